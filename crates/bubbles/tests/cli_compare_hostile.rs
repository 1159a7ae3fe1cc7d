//! `bubbles compare` against hostile inputs (issue 28): images past the pixel limit,
//! refused from their header before decoding; translucent pixels; animated PNGs; and a
//! heat map that names one of the inputs. Each exits 2 naming the file and the value,
//! and leaves the inputs untouched.

use std::io::Write as _;
use std::path::Path;
use std::process::Output;
use std::time::{Duration, Instant};

mod common;
use common::{bubbles, json_field};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Asserts exit code 2, nothing on stdout, and a message containing every needle.
#[track_caller]
fn assert_refused(out: &Output, needles: &[&str]) {
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(out.stdout.is_empty(), "stdout: {}", text(&out.stdout));
    for needle in needles {
        assert!(stderr.contains(needle), "{needle:?} missing from: {stderr}");
    }
}

/// A PNG of `width × height`, colour type `color`, every pixel `pixel`, written a row at
/// a time so a large one never exists in memory.
fn write_uniform_png(
    path: &Path,
    (width, height): (u32, u32),
    color: png::ColorType,
    pixel: &[u8],
) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fastest);
    let mut writer = encoder.write_header().unwrap();
    let mut stream = writer.stream_writer().unwrap();
    let row: Vec<u8> = pixel.repeat(width as usize);
    for _ in 0..height {
        stream.write_all(&row).unwrap();
    }
    stream.finish().unwrap();
}

/// A PNG whose header claims `width × height` but whose one IDAT chunk is an empty zlib
/// stream: anything that decodes it fails (or first allocates the claimed size), so a
/// refusal naming the size proves the header was read first.
fn write_header_only_png(path: &Path, width: u32, height: u32) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    const EMPTY_ZLIB: [u8; 8] = [0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01];
    writer.write_chunk(png::chunk::IDAT, &EMPTY_ZLIB).unwrap();
    // Dropping the writer adds IEND.
}

#[test]
fn an_image_one_column_past_the_pixel_limit_is_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    // 8193 × 8192 = 67 117 056 pixels, 8192 more than the 67 108 864 limit.
    write_uniform_png(
        &dir.path().join("big.png"),
        (8193, 8192),
        png::ColorType::Rgb,
        &[0, 0, 0],
    );
    write_uniform_png(
        &dir.path().join("small.png"),
        (4, 4),
        png::ColorType::Rgb,
        &[0, 0, 0],
    );
    for args in [["big.png", "small.png"], ["small.png", "big.png"]] {
        let start = Instant::now();
        let out = bubbles(&["compare", args[0], args[1]], dir.path());
        let took = start.elapsed();
        assert_refused(
            &out,
            &[
                "big.png",
                "8193x8192",
                "67117056",
                "above the limit of 67108864",
            ],
        );
        // Decoding it took 15 to 18 s and 1.45 GB; the header alone is instant.
        assert!(
            took < Duration::from_secs(5),
            "took {took:?}: was it decoded?"
        );
    }
}

#[test]
fn a_header_claiming_60000_by_60000_is_refused_with_the_limit_message() {
    let dir = tempfile::tempdir().unwrap();
    write_header_only_png(&dir.path().join("claims.png"), 60000, 60000);
    write_uniform_png(
        &dir.path().join("small.png"),
        (4, 4),
        png::ColorType::Rgb,
        &[0, 0, 0],
    );
    let out = bubbles(&["compare", "small.png", "claims.png"], dir.path());
    assert_refused(
        &out,
        &[
            "claims.png",
            "60000x60000",
            "3600000000",
            "above the limit of 67108864",
        ],
    );
    assert!(
        !text(&out.stderr).contains("Memory limit exceeded"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn a_half_transparent_image_is_refused_naming_the_pixel_and_its_alpha() {
    let dir = tempfile::tempdir().unwrap();
    write_uniform_png(
        &dir.path().join("rgb.png"),
        (6, 4),
        png::ColorType::Rgb,
        &[200, 40, 90],
    );
    write_uniform_png(
        &dir.path().join("half.png"),
        (6, 4),
        png::ColorType::Rgba,
        &[200, 40, 90, 128],
    );
    // (ΔE 0 before: the alpha was dropped.)
    let out = bubbles(&["compare", "rgb.png", "half.png"], dir.path());
    assert_refused(
        &out,
        &["half.png", "not opaque", "(0, 0)", "alpha 128 of 255"],
    );

    // One translucent pixel in an otherwise opaque image is found where it is.
    let mut img = image::RgbaImage::from_pixel(6, 4, image::Rgba([200, 40, 90, 255]));
    img.put_pixel(5, 2, image::Rgba([200, 40, 90, 254]));
    img.save(dir.path().join("one.png")).unwrap();
    let out = bubbles(&["compare", "one.png", "rgb.png"], dir.path());
    assert_refused(&out, &["one.png", "(5, 2)", "alpha 254 of 255"]);

    // A fully opaque RGBA image is compared, channel by channel, like its RGB twin.
    write_uniform_png(
        &dir.path().join("opaque.png"),
        (6, 4),
        png::ColorType::Rgba,
        &[200, 40, 90, 255],
    );
    let out = bubbles(&["compare", "rgb.png", "opaque.png", "--json"], dir.path());
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert_eq!(json_field(&text(&out.stdout), "max"), 0.0);
}

#[test]
fn an_animated_png_is_refused_naming_its_frame_count() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("anim.png");
    {
        let file = std::fs::File::create(&path).unwrap();
        let mut encoder = png::Encoder::new(file, 4, 3);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_animated(2, 0).unwrap();
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(&[10; 4 * 3 * 3]).unwrap();
        writer.write_image_data(&[250; 4 * 3 * 3]).unwrap();
        writer.finish().unwrap();
    }
    write_uniform_png(
        &dir.path().join("still.png"),
        (4, 3),
        png::ColorType::Rgb,
        &[10, 10, 10],
    );
    // Before, only the first frame was read: ΔE 0 against `still.png`.
    let out = bubbles(&["compare", "still.png", "anim.png"], dir.path());
    assert_refused(&out, &["anim.png", "animated PNG of 2 frames"]);
}

#[test]
fn a_heat_map_that_names_an_input_is_refused_however_it_is_spelled() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    write_uniform_png(
        &sub.join("a.png"),
        (4, 3),
        png::ColorType::Rgb,
        &[10, 20, 30],
    );
    write_uniform_png(
        &dir.path().join("b.png"),
        (4, 3),
        png::ColorType::Rgb,
        &[12, 20, 30],
    );
    let a_before = std::fs::read(sub.join("a.png")).unwrap();
    let b_before = std::fs::read(dir.path().join("b.png")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(sub.join("a.png"), dir.path().join("link.png")).unwrap();
    std::fs::hard_link(dir.path().join("b.png"), dir.path().join("hard.png")).unwrap();
    let mut spellings = vec![
        "sub/a.png",
        "./sub/a.png",
        "sub/../sub/a.png",
        "sub//a.png",
        "b.png",
        "./b.png",
        "hard.png",
    ];
    if cfg!(unix) {
        spellings.push("link.png");
    }
    for heatmap in spellings {
        let out = bubbles(
            &["compare", "sub/a.png", "b.png", "--heatmap", heatmap],
            dir.path(),
        );
        assert_refused(&out, &["--heatmap", heatmap, "would overwrite"]);
    }
    assert_eq!(std::fs::read(sub.join("a.png")).unwrap(), a_before);
    assert_eq!(std::fs::read(dir.path().join("b.png")).unwrap(), b_before);

    // A heat map elsewhere is written as before.
    let out = bubbles(
        &["compare", "sub/a.png", "b.png", "--heatmap", "sub/heat.png"],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(sub.join("heat.png").is_file());
}

#[test]
fn an_image_that_is_not_a_png_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    // An HDR EXR was clamped to 8 bits and compared as if it were sRGB.
    image::Rgb32FImage::from_pixel(4, 3, image::Rgb([0.5, 2.0, 0.1]))
        .save(dir.path().join("hdr.exr"))
        .unwrap();
    write_uniform_png(
        &dir.path().join("a.png"),
        (4, 3),
        png::ColorType::Rgb,
        &[10, 10, 10],
    );
    let out = bubbles(&["compare", "a.png", "hdr.exr"], dir.path());
    assert_refused(&out, &["hdr.exr", "compare reads PNG images"]);
}
