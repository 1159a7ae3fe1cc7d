//! `bubbles animate` end to end: resume after a kill and frame ranges give the frames of
//! one uninterrupted run byte for byte; APNG holds those frames exactly; the GIF preview
//! stays close in CIEDE2000; bad arguments exit with 2.

use std::path::Path;
use std::process::{Command, Output};

/// A small, fast animation: the two-bubble collision at 48 × 36, one sample per pixel
/// (at 20 fps unless a test says otherwise).
const SMALL: [&str; 8] = [
    "bubble-collision",
    "--width",
    "48",
    "--height",
    "36",
    "--samples",
    "1",
    "--cube-map-size=16",
];

fn animate(extra: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .arg("animate")
        .args(SMALL)
        .args(extra)
        .args(if extra.contains(&"--fps") {
            &[][..]
        } else {
            &["--fps", "20"][..]
        })
        .current_dir(dir)
        .output()
        .expect("bubbles runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn frame_bytes(dir: &Path, k: u64) -> Vec<u8> {
    std::fs::read(dir.join(format!("frame_{k:05}.png"))).unwrap()
}

fn pixels(png_file: &Path) -> Vec<u8> {
    image::open(png_file)
        .expect("frame decodes")
        .to_rgb8()
        .into_raw()
}

#[test]
fn resume_after_a_kill_and_frame_ranges_give_the_uninterrupted_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let (full, killed, part) = ("full", "killed", "part");
    let out = animate(&["--seconds", "0.5", "--out", full], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let count = 10;
    assert!(tmp.path().join(full).join("frame_00009.png").is_file());
    assert!(!tmp.path().join(full).join("frame_00010.png").exists());

    // Kill a run of a longer animation once its first frames are on disk.
    let mut child = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .arg("animate")
        .args(SMALL)
        .args(["--fps", "20", "--seconds", "3", "--out", killed])
        .current_dir(tmp.path())
        .spawn()
        .unwrap();
    let first = tmp.path().join(killed).join("frame_00001.png");
    while !first.exists() {
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done = (0..60)
        .filter(|k| {
            tmp.path()
                .join(killed)
                .join(format!("frame_{k:05}.png"))
                .is_file()
        })
        .count();
    assert!(done < 60, "the run finished before it was killed");
    // Every frame left behind is whole.
    for k in 0..done as u64 {
        pixels(&tmp.path().join(killed).join(format!("frame_{k:05}.png")));
    }
    let out = animate(
        &["--seconds", "0.5", "--out", killed, "--resume"],
        tmp.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    for k in 0..count {
        assert!(
            frame_bytes(&tmp.path().join(killed), k) == frame_bytes(&tmp.path().join(full), k),
            "resumed frame {k} differs"
        );
    }

    let out = animate(
        &["--seconds", "0.5", "--out", part, "--frames", "6..8"],
        tmp.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    for k in 6..8 {
        assert!(
            frame_bytes(&tmp.path().join(part), k) == frame_bytes(&tmp.path().join(full), k),
            "frame {k} of --frames 6..8 differs"
        );
    }
    assert!(!tmp.path().join(part).join("frame_00005.png").exists());
    assert!(!tmp.path().join(part).join("frame_00008.png").exists());

    // The APNG holds exactly the frames.
    let out = animate(&["--seconds", "0.5", "--out", "a.apng"], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(tmp.path().join("a.apng")).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let control = reader.info().animation_control().expect("an APNG");
    assert_eq!(control.num_frames, count as u32);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for k in 0..count {
        let info = reader.next_frame(&mut buf).unwrap();
        assert!(
            buf[..info.buffer_size()]
                == pixels(&tmp.path().join(full).join(format!("frame_{k:05}.png")))[..],
            "APNG frame {k} differs from frame_{k:05}.png"
        );
    }

    // Frames of other settings never go into the directory, resumed or not.
    for resume in [&["--resume"][..], &[]] {
        let args = [
            &["--seconds", "0.5", "--out", full, "--fps", "10"][..],
            resume,
        ]
        .concat();
        let out = animate(&args, tmp.path());
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains("animation.txt"), "{}", stderr(&out));
    }
}

#[test]
fn gif_preview_is_close_to_the_exact_frames_in_ciede2000() {
    let tmp = tempfile::tempdir().unwrap();
    let out = animate(&["--seconds", "0.2", "--out", "f"], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let out = animate(&["--seconds", "0.2", "--out", "p.gif"], tmp.path());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("mean CIEDE2000"), "{}", stderr(&out));
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let file = std::fs::File::open(tmp.path().join("p.gif")).unwrap();
    let mut decoder = options.read_info(file).unwrap();
    let (mut sum, mut n, mut k) = (0.0, 0usize, 0u64);
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        let exact = pixels(&tmp.path().join("f").join(format!("frame_{k:05}.png")));
        for (e, g) in exact.chunks_exact(3).zip(frame.buffer.chunks_exact(4)) {
            sum += thinfilm::ciede2000(lab(e), lab(&g[..3]));
            n += 1;
        }
        k += 1;
    }
    assert_eq!(k, 4, "GIF frames");
    let mean = sum / n as f64;
    assert!(
        mean < 3.0,
        "mean ΔE00 {mean:.2} between the GIF and the PNG frames"
    );
}

fn lab(rgb: &[u8]) -> thinfilm::Lab {
    use thinfilm::colorspace::{XYZ_FROM_SRGB, apply, srgb_decode};
    let linear = [0, 1, 2].map(|c| srgb_decode(f64::from(rgb[c]) / 255.0));
    thinfilm::lab_from_xyz(
        apply(&XYZ_FROM_SRGB, linear),
        apply(&XYZ_FROM_SRGB, [1.0; 3]),
    )
}

#[test]
fn bad_arguments_exit_2_with_a_message_naming_them() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("file"), "not a directory").unwrap();
    for (args, expect) in [
        (
            &["--seconds", "1", "--fps", "0", "--out", "d"][..],
            "--fps 0",
        ),
        (&["--seconds", "-1", "--out", "d"][..], "--seconds -1"),
        (
            &["--seconds", "1", "--out", "file/frames"][..],
            "file/frames",
        ),
        (
            &["--seconds", "1", "--out", "d", "--frames", "10..30"][..],
            "--frames 10..30",
        ),
        (
            &["--seconds", "1", "--out", "x.gif", "--resume"][..],
            "--resume",
        ),
        (&["--seconds", "1", "--out", "x.mp4"][..], ".mp4"),
        (&["--seconds", "1e6", "--out", "d"][..], "--seconds 1000000"),
    ] {
        let out = animate(args, tmp.path());
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(expect), "{args:?}: {}", stderr(&out));
    }
    assert!(
        !tmp.path().join("d").exists(),
        "a rejected run created its directory"
    );
}

#[test]
fn demo_with_a_white_lamp_renders() {
    let tmp = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args([
            "render",
            "demo-white",
            "--out",
            "w.png",
            "--width",
            "40",
            "--height",
            "30",
        ])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn demo_with_its_sodium_lamp_renders() {
    let tmp = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args([
            "render", "demo", "--out", "d.png", "--width", "40", "--height", "30",
        ])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
}
