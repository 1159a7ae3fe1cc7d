//! The frame on its way to the window: tone-mapped into 0RGB words and scaled to the
//! window's size, both without allocating once the buffers have grown.

/// Tone-maps linear radiance into 0RGB words, reusing `out`'s allocation.
///
/// In parallel: one `powf` per channel made this the costliest step of a 1280×720 frame
/// (more than the render) when it ran on one thread. Each pixel is independent, so the
/// result does not depend on the thread count.
pub(super) fn tone_map_into(
    out: &mut Vec<u32>,
    rgb: &[[f32; 3]],
    exposure_ev: f32,
    tonemap: raster::ToneMap,
) {
    use rayon::prelude::*;
    let scale = exposure_ev.exp2();
    out.resize(rgb.len(), 0);
    out.par_iter_mut()
        .zip(rgb.par_iter())
        .for_each(|(word, px)| {
            let [r, g, b] = raster::tone_map(px.map(|c| c * scale), tonemap)
                .map(|c| (raster::linear_to_srgb(c) * 255.0 + 0.5) as u32);
            *word = (r << 16) | (g << 8) | b;
        });
}

/// Nearest-neighbour upscale of an `iw`×`ih` image into a `w`×`h` one.
pub(super) fn upscale(src: &[u32], iw: usize, ih: usize, dst: &mut [u32], w: usize, h: usize) {
    for (y, row) in dst.chunks_exact_mut(w).take(h).enumerate() {
        let sy = (y * ih / h).min(ih - 1);
        let src_row = &src[sy * iw..(sy + 1) * iw];
        for (x, px) in row.iter_mut().enumerate() {
            *px = src_row[(x * iw / w).min(iw - 1)];
        }
    }
}
