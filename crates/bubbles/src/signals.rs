//! Ctrl-C (SIGINT) and SIGTERM during `render`, `animate` and `thickness`: the handler only records
//! the signal; the work stops at its next safe point (between solver steps, before a
//! file is written, between frames), every temporary is removed as the error unwinds,
//! and the process exits 128 + the signal's number (130, 143) with one line on stderr.
//! The work between safe points (one frame's rendering) is not cut short; a second
//! signal ends the process at once.

use crate::error::CliError;
use std::sync::atomic::{AtomicI32, Ordering};

/// The signal received, 0 while none.
static RECEIVED: AtomicI32 = AtomicI32::new(0);

/// Records the signal; only an atomic store, so it is async-signal-safe.
#[cfg(unix)]
extern "C" fn record(signal: libc::c_int) {
    RECEIVED.store(signal, Ordering::SeqCst);
}

/// Installs the handler for SIGINT and SIGTERM (on Unix; elsewhere the default stays).
pub fn install() {
    #[cfg(unix)]
    for signal in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: `record` is async-signal-safe (one atomic store), and `action` is a
        // zero-initialised `sigaction` with an empty mask, as `sigaction(2)` expects.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = record as extern "C" fn(libc::c_int) as libc::sighandler_t;
            libc::sigemptyset(&mut action.sa_mask);
            // The handler runs once: a second Ctrl-C ends the process at once, for a
            // user who will not wait for the frame in progress.
            action.sa_flags = libc::SA_RESETHAND;
            libc::sigaction(signal, &action, std::ptr::null_mut());
        }
    }
}

/// Whether SIGINT or SIGTERM has arrived since [`install`].
pub fn interrupted() -> bool {
    RECEIVED.load(Ordering::SeqCst) != 0
}

/// A safe point: the error to stop with once a signal has arrived.
pub fn check() -> Result<(), CliError> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => Ok(()),
        signal => Err(CliError::interrupted(signal)),
    }
}
