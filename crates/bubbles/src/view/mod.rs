//! `bubbles view`: a live window (feature `view`) on the CPU renderer, or with
//! `--backend wgpu` on the GPU, presented through a wgpu surface.

mod controls;
mod font;
#[cfg(feature = "wgpu")]
mod gpu;
mod keys;
mod pixels;
mod present;
mod scale;
mod window;

use crate::error::{CliError, CliResult};
use crate::frame::{Backend, Options};

/// The controls, printed by `bubbles view --help` and drawn by H in the window.
pub const CONTROLS: &str = "\
Controls:
  drag             orbit the camera about its target
  wheel            zoom
  right/shift-drag pan
  W                wind on/off
  arrow keys       turn the wind
  + / -            wind strength
  space            blow a bubble towards the target
  click a bubble   poke it
  1 / 2 / 3        reflections: cube maps / environment / sphere map
  M                anti-aliasing samples (1, 4, 16)
  P                pause; period: one step while paused
  R                reset the scene
  F                overlay: fps, frame-time breakdown, bubbles, events
  S                save a screenshot (bubbles-view-NNNN.png)
  H                this help
  escape           quit";

/// Arguments of `bubbles view`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A scene file (.toml) or a built-in scene: `paper` (default) or `white-furnace`.
    pub scene: Option<String>,
    /// Frame rate to hold by lowering the internal resolution.
    #[arg(long, default_value_t = 60.0)]
    pub target_fps: f32,
    /// Always render at the window's full resolution (no adaptive scaling).
    #[arg(long)]
    pub fixed_scale: bool,
    /// Quit after this many seconds, printing the frames drawn and the mean fps on stderr
    /// (to measure the viewer).
    #[arg(long, value_name = "SECONDS")]
    pub quit_after_s: Option<f64>,
    #[command(flatten)]
    pub options: Options,
}

/// Runs `bubbles view`.
pub fn run(args: Args) -> CliResult {
    check_backend(args.options.backend)?;
    check_display(|name| std::env::var_os(name))?;
    if !(args.target_fps.is_finite() && args.target_fps > 0.0) {
        return Err(CliError::input(format!(
            "--target-fps {}: must be a finite number > 0",
            crate::scene::values::plain(f64::from(args.target_fps))
        )));
    }
    if let Some(s) = args.quit_after_s.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(CliError::input(format!(
            "--quit-after-s {}: must be a finite number of seconds > 0",
            crate::scene::values::plain(s)
        )));
    }
    window::run(args)
}

/// `--backend wgpu` in a build without the wgpu backend: the same error (exit 2) as
/// `bubbles render --backend wgpu`, before any window-system call.
fn check_backend(backend: Backend) -> CliResult {
    #[cfg(not(feature = "wgpu"))]
    if backend == Backend::Wgpu {
        return Err(crate::frame::gpu::unavailable());
    }
    let _ = backend;
    Ok(())
}

/// Fails with exit code 2 before any window-system call when there is no display to open.
fn check_display(var: impl Fn(&str) -> Option<std::ffi::OsString>) -> CliResult {
    let set = |name| var(name).is_some_and(|v| !v.is_empty());
    if set("DISPLAY") || set("WAYLAND_DISPLAY") {
        Ok(())
    } else {
        Err(CliError::input(
            "bubbles view needs a display: neither DISPLAY nor WAYLAND_DISPLAY is set \
             (run it in a desktop session, or under xvfb-run; `bubbles render` needs none)",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_display_is_an_input_error_naming_both_variables() {
        let err = check_display(|_| None).expect_err("no display");
        assert_eq!(err.exit_code(), 2);
        let msg = err.to_string();
        assert!(
            msg.contains("DISPLAY") && msg.contains("WAYLAND_DISPLAY"),
            "{msg}"
        );
        assert!(
            check_display(|n| (n == "DISPLAY").then(|| "".into())).is_err(),
            "empty counts as unset"
        );
        assert!(check_display(|n| (n == "WAYLAND_DISPLAY").then(|| "wayland-0".into())).is_ok());
    }
}
