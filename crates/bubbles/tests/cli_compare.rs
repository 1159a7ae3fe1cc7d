//! `bubbles compare` end to end, and `render --backend reference` on the furnace.

use std::path::Path;

mod common;
use common::{bubbles, json_field};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn write_png(dir: &Path, name: &str, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb(f(x, y)));
    img.save(dir.join(name)).unwrap();
}

#[test]
fn identical_images_give_zero_and_one_changed_pixel_gives_its_delta_e() {
    let dir = tempfile::tempdir().unwrap();
    let base = |x: u32, y: u32| [(x * 20) as u8, (y * 30) as u8, 128];
    write_png(dir.path(), "a.png", 8, 6, base);
    write_png(dir.path(), "b.png", 8, 6, |x, y| {
        if (x, y) == (3, 2) {
            [10, 200, 30]
        } else {
            base(x, y)
        }
    });
    let same = bubbles(&["compare", "a.png", "a.png", "--json"], dir.path());
    assert!(same.status.success(), "{}", text(&same.stderr));
    let json = text(&same.stdout);
    assert_eq!(json_field(&json, "max"), 0.0, "{json}");
    assert_eq!(json_field(&json, "mean"), 0.0, "{json}");

    let out = bubbles(
        &[
            "compare",
            "a.png",
            "b.png",
            "--json",
            "--heatmap",
            "heat.png",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json = text(&out.stdout);
    // ΔE2000 of the changed pixel, through thinfilm's CIELAB, computed here independently.
    use thinfilm::colorspace::{XYZ_FROM_SRGB, apply, srgb_decode};
    let lab = |p: [u8; 3]| {
        let lin = p.map(|c| srgb_decode(f64::from(c) / 255.0));
        thinfilm::lab_from_xyz(apply(&XYZ_FROM_SRGB, lin), apply(&XYZ_FROM_SRGB, [1.0; 3]))
    };
    let want = thinfilm::ciede2000(lab(base(3, 2)), lab([10, 200, 30]));
    let max = json_field(&json, "max");
    assert!((max - want).abs() < 1e-9, "max {max} vs {want}");
    let heat = image::open(dir.path().join("heat.png")).unwrap().to_rgb8();
    assert!(
        heat.width() > 8 && heat.height() >= 6,
        "{:?}",
        heat.dimensions()
    );
    assert_ne!(
        heat.get_pixel(3, 2),
        heat.get_pixel(0, 0),
        "the changed pixel shows"
    );
}

#[test]
fn different_sizes_and_unreadable_files_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    write_png(dir.path(), "a.png", 8, 6, |_, _| [1, 2, 3]);
    write_png(dir.path(), "b.png", 6, 8, |_, _| [1, 2, 3]);
    std::fs::write(dir.path().join("junk.png"), b"not a png").unwrap();
    for (b, needle) in [
        ("b.png", "same size"),
        ("junk.png", "junk.png"),
        ("none.png", "none.png"),
    ] {
        let out = bubbles(&["compare", "a.png", b], dir.path());
        assert_eq!(out.status.code(), Some(2), "{b}: {}", text(&out.stderr));
        assert!(
            text(&out.stderr).contains(needle),
            "{b}: {}",
            text(&out.stderr)
        );
    }
}

#[test]
fn reference_backend_renders_the_furnace_invisible() {
    let dir = tempfile::tempdir().unwrap();
    let out = bubbles(
        &[
            "render",
            "white-furnace",
            "--backend",
            "reference",
            "--out",
            "ref.png",
            "--width",
            "24",
            "--height",
            "24",
            "--ref-samples",
            "1",
            "--ref-step-nm",
            "25",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let img = image::open(dir.path().join("ref.png")).unwrap().to_rgb8();
    let darkest = img.pixels().flat_map(|p| p.0).min().unwrap();
    assert!(darkest >= 254, "darkest channel {darkest}/255");
}
