//! [`Bytes`]: little-endian bytes for a GPU buffer, as `scene_data` and `water_data` pack
//! them. Pure CPU code.

// Without the `wgpu` feature only the naga layout test uses this module.
#![cfg_attr(not(feature = "wgpu"), allow(dead_code))]

/// Little-endian bytes for a GPU buffer.
#[derive(Debug, Default)]
pub(super) struct Bytes(pub Vec<u8>);

impl Bytes {
    pub(super) fn f32(&mut self, x: f32) -> &mut Self {
        self.0.extend_from_slice(&x.to_le_bytes());
        self
    }

    pub(super) fn u32(&mut self, x: u32) -> &mut Self {
        self.0.extend_from_slice(&x.to_le_bytes());
        self
    }

    pub(super) fn vec4(&mut self, xyz: [f32; 3], w: f32) -> &mut Self {
        for x in xyz {
            self.f32(x);
        }
        self.f32(w)
    }
}
