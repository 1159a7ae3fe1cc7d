//! The CPU renderer's passes over one strip of rows: the opaque scene ([`opaque`], with its
//! span kernels [`ground_span`] and [`sky_span`]), the bubble blend ([`bubble`]) and the
//! water's reflection cube map ([`water`]).
//!
//! The arrows run one way: `water` drives `opaque` and `bubble`; `opaque` calls the span
//! kernels; the kernels read only the scene crate and [`SPAN`].

pub(crate) mod bubble;
pub(crate) mod ground_span;
pub(crate) mod opaque;
pub(crate) mod sky_span;
pub(crate) mod water;

/// Pixels per span-kernel call: the opaque pass walks a row in chunks of this width.
pub(crate) const SPAN: usize = 64;
