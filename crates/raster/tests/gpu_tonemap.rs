//! The wgpu backend's tone-map pass against the CPU's `Frame::to_srgb8`, the specification.
//!
//! Runs with `cargo test -p raster --features wgpu --test gpu_tonemap`. Without an adapter it
//! skips with a message, except under `CI=true`, where a missing adapter fails.
#![cfg(feature = "wgpu")]

use raster::gpu::{Gpu, GpuOptions};
use raster::{Frame, ToneMap};

/// The device, or `None` (skip) outside CI when no adapter exists.
fn gpu() -> Option<Gpu> {
    match Gpu::new(GpuOptions::default()) {
        Ok(gpu) => {
            eprintln!("adapter: {}", gpu.adapter_name());
            Some(gpu)
        }
        Err(e) if std::env::var_os("CI").is_none() => {
            eprintln!("skipped: {e}");
            None
        }
        Err(e) => panic!("CI must run the wgpu tests: {e}"),
    }
}

/// A deterministic HDR frame spanning black, mid-tones, highlights far above 1 and
/// negative (out-of-gamut) channels, with an odd width so rows need padding on read-back.
fn test_frame(width: usize, height: usize) -> Frame {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let rgb = (0..width * height)
        .map(|_| [0; 3].map(|_| (next() * 14.0 - 10.0).exp2() - 0.002))
        .collect();
    Frame::try_from_rgb(width, height, rgb).expect("size matches")
}

#[test]
fn gpu_tone_map_matches_the_cpu_backend_within_one_code_value() {
    let Some(gpu) = gpu() else { return };
    let frame = test_frame(67, 31);
    for tonemap in [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::AcesFitted] {
        for exposure_ev in [-1.5, 0.0, 2.0] {
            let cpu = frame.to_srgb8(exposure_ev, tonemap);
            let gpu_bytes = gpu.tone_map_srgb8(&frame, exposure_ev, tonemap).unwrap();
            assert_eq!(gpu_bytes.len(), cpu.len(), "{tonemap:?}");
            let diffs: Vec<(usize, u8, u8)> = cpu
                .iter()
                .zip(&gpu_bytes)
                .enumerate()
                .filter(|(_, (a, b))| a != b)
                .map(|(i, (a, b))| (i, *a, *b))
                .collect();
            let worst = diffs.iter().map(|d| d.1.abs_diff(d.2)).max().unwrap_or(0);
            assert!(
                worst <= 1 && diffs.len() * 100 <= cpu.len(),
                "{tonemap:?} at {exposure_ev} EV: {} of {} bytes differ, worst by {worst}: {:?}",
                diffs.len(),
                cpu.len(),
                &diffs[..diffs.len().min(8)]
            );
        }
    }
}

#[test]
fn gpu_tone_map_refuses_images_beyond_the_texture_limit() {
    let Some(gpu) = gpu() else { return };
    let frame = Frame::try_from_rgb(70_000, 1, vec![[0.5; 3]; 70_000]).unwrap();
    let err = gpu
        .tone_map_srgb8(&frame, 0.0, ToneMap::Clamp)
        .unwrap_err()
        .to_string();
    assert!(err.contains("70000x1"), "{err}");
}
