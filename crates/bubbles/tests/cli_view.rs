//! `bubbles view`: without a display it exits 2; under Xvfb, driven by real X input
//! events (xdotool), it draws the scene, a drag changes the view, F shows the overlay, S
//! saves a screenshot and Escape exits 0, on
//! the CPU presenter and, built with `--features wgpu`, on the wgpu surface and through its
//! CPU fallback.
#![cfg(feature = "view")]

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

fn bubbles() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bubbles"))
}

#[test]
fn without_a_display_view_exits_2_naming_the_variables() {
    let err = view_without_a_display_exits_2(&[]);
    assert!(
        err.contains("DISPLAY") && err.contains("WAYLAND_DISPLAY"),
        "{err}"
    );
}

/// Kills the child (Xvfb or the viewer) when the test ends, however it ends.
struct Reap(Child);

impl Drop for Reap {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn run(display: &str, program: &str, args: &[&str]) -> String {
    let out = Command::new(program)
        .args(args)
        .env("DISPLAY", display)
        .output()
        .unwrap_or_else(|e| panic!("{program}: {e}"));
    assert!(out.status.success(), "{program} {args:?}: {out:?}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// An X screenshot of the root window, parsed from XWD: (width, height, RGB bytes).
fn screenshot(display: &str, dir: &Path, name: &str) -> (usize, usize, Vec<u8>) {
    let path = dir.join(name);
    run(
        display,
        "xwd",
        &["-root", "-silent", "-out", path.to_str().unwrap()],
    );
    parse_xwd(&std::fs::read(&path).unwrap())
}

/// XWD: a header of big-endian u32 fields, a colour map, then the pixels (ZPixmap,
/// 32 bits per pixel for a 24-bit Xvfb screen).
fn parse_xwd(bytes: &[u8]) -> (usize, usize, Vec<u8>) {
    let field = |i: usize| u32::from_be_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap()) as usize;
    let (header, format, width, height) = (field(0), field(2), field(4), field(5));
    let (byte_order, bpp, line, ncolors) = (field(7), field(11), field(12), field(19));
    let masks = [field(14), field(15), field(16)];
    assert_eq!(
        (format, bpp),
        (2, 32),
        "expected a ZPixmap with 32 bits per pixel"
    );
    let data = &bytes[header + 12 * ncolors..];
    let mut rgb = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            let p: [u8; 4] = data[y * line + 4 * x..y * line + 4 * x + 4]
                .try_into()
                .unwrap();
            let v = if byte_order == 0 {
                u32::from_le_bytes(p)
            } else {
                u32::from_be_bytes(p)
            } as usize;
            rgb.extend(masks.map(|m| ((v & m) >> m.trailing_zeros()) as u8));
        }
    }
    (width, height, rgb)
}

fn geometry(display: &str, window: &str) -> (usize, usize, usize, usize) {
    let text = run(
        display,
        "xdotool",
        &["getwindowgeometry", "--shell", window],
    );
    let get = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{key}=")))
            .and_then(|v| v.trim().parse::<usize>().ok())
            .unwrap_or_else(|| panic!("no {key} in {text}"))
    };
    (get("X"), get("Y"), get("WIDTH"), get("HEIGHT"))
}

/// The window's pixels out of a root screenshot.
fn crop(shot: &(usize, usize, Vec<u8>), g: (usize, usize, usize, usize)) -> Vec<[u8; 3]> {
    let (w, _, rgb) = shot;
    let mut out = Vec::new();
    for y in g.1..g.1 + g.3 {
        for x in g.0..g.0 + g.2 {
            let i = 3 * (y * w + x);
            out.push([rgb[i], rgb[i + 1], rgb[i + 2]]);
        }
    }
    out
}

#[test]
fn view_under_xvfb_draws_the_scene_turns_on_a_drag_and_quits_on_escape() {
    drive_viewer(&[], &[]);
}

/// The same drive with `--backend wgpu`: the GPU draws into the window's wgpu surface
/// (lavapipe in CI, through Mesa's X11 WSI on Xvfb), and says so on stderr.
#[cfg(feature = "wgpu")]
#[test]
fn wgpu_view_under_xvfb_draws_the_scene_turns_on_a_drag_and_quits_on_escape() {
    let Some(err) = drive_viewer(&["--backend", "wgpu"], &[]) else {
        return;
    };
    assert!(err.contains("drawing with wgpu on"), "{err}");
    assert!(!err.contains("drawing on the CPU instead"), "{err}");
}

/// With no Vulkan driver to be found, `--backend wgpu` falls back to the CPU presenter,
/// says so once on stderr, and the window works as ever.
#[cfg(feature = "wgpu")]
#[test]
fn wgpu_view_without_a_driver_falls_back_to_the_cpu_and_says_so() {
    let env = [("VK_DRIVER_FILES", "/nonexistent/no_icd.json")];
    let Some(err) = drive_viewer(&["--backend", "wgpu"], &env) else {
        return;
    };
    assert_eq!(
        err.matches("drawing on the CPU instead").count(),
        1,
        "{err}"
    );
}

#[cfg(not(feature = "wgpu"))]
#[test]
fn without_the_wgpu_feature_backend_wgpu_exits_2_saying_how_to_build_it() {
    let err = view_without_a_display_exits_2(&["--backend", "wgpu"]);
    assert!(err.contains("--features wgpu"), "{err}");
}

/// `bubbles view paper` with `args` and no display variables: it must exit 2; returns
/// its stderr.
fn view_without_a_display_exits_2(args: &[&str]) -> String {
    let out = bubbles()
        .args(["view", "paper"])
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh Xvfb on a display it picks itself (`-displayfd`: the first free number, its
/// lock and socket checked, written back once it listens), and that display. A number
/// chosen here from the process id met stale locks and sockets that earlier runs had
/// left on a long-lived machine, and the viewer could not open the display.
fn start_xvfb() -> (Reap, String) {
    let mut xvfb = Reap(
        Command::new("Xvfb")
            .args(["-displayfd", "1", "-screen", "0", "640x480x24"])
            .args(["-nolisten", "tcp"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let mut number = String::new();
    let stdout = xvfb.0.stdout.take().expect("Xvfb's stdout");
    BufReader::new(stdout).read_line(&mut number).unwrap();
    let number = number.trim();
    assert!(!number.is_empty(), "Xvfb wrote no display number");
    (xvfb, format!(":{number}"))
}

/// Runs `bubbles view paper` with `args` and `env` under a fresh Xvfb, drives it with real
/// X input (a drag, then the keys F, S and Escape), checks the window shows the scene,
/// turns on the drag, shows the overlay on F, saves a screenshot on S and exits 0 on Escape, and returns the viewer's stderr; `None` where the tools are missing
/// outside CI (in CI, with `CI` set, that fails instead).
fn drive_viewer(args: &[&str], env: &[(&str, &str)]) -> Option<String> {
    let tools = ["Xvfb", "xdotool", "xwd"];
    let missing: Vec<_> = tools.iter().filter(|t| !have(t)).collect();
    if !missing.is_empty() {
        // CI installs them (.ci/run); there a missing tool is a failure, not a skip.
        assert!(
            std::env::var("CI").is_err(),
            "CI must install {missing:?} (apt-get install xvfb xdotool x11-apps)"
        );
        eprintln!("skipped: {missing:?} not installed");
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    let (_xvfb, display) = start_xvfb();
    let deadline = Instant::now() + Duration::from_secs(20);
    while !run_ok(&display, "xdotool", &["getmouselocation"]) {
        assert!(Instant::now() < deadline, "Xvfb {display} did not start");
        sleep(Duration::from_millis(100));
    }
    let stderr_path = dir.path().join("stderr.txt");
    let mut viewer = Reap(
        bubbles()
            .args([
                "view",
                "paper",
                "--width",
                "320",
                "--height",
                "240",
                "--samples",
                "1",
            ])
            .args(["--reflection", "static", "--fixed-scale"])
            .args(args)
            .envs(env.iter().copied())
            .env("DISPLAY", &display)
            .env_remove("WAYLAND_DISPLAY")
            .current_dir(dir.path())
            .stderr(std::fs::File::create(&stderr_path).unwrap())
            .spawn()
            .unwrap(),
    );
    let deadline = Instant::now() + Duration::from_secs(120);
    let window = loop {
        let out = Command::new("xdotool")
            .args(["search", "--name", "bubbles view"])
            .env("DISPLAY", &display)
            .output()
            .unwrap();
        if let Some(id) = String::from_utf8_lossy(&out.stdout).lines().next() {
            break id.to_string();
        }
        assert!(
            viewer.0.try_wait().unwrap().is_none(),
            "the viewer exited early: {}",
            std::fs::read_to_string(&stderr_path).unwrap_or_default()
        );
        assert!(Instant::now() < deadline, "no window appeared");
        sleep(Duration::from_millis(200));
    };
    // The first frames may take a while (a GPU driver compiles its pipelines): wait, with
    // a generous deadline, for a window full of the scene.
    let g = geometry(&display, &window);
    let before = wait_for(&display, dir.path(), g, "before", |shot| {
        let mut colours = shot.to_vec();
        colours.sort_unstable();
        colours.dedup();
        let lit = shot.iter().filter(|p| p.iter().any(|&c| c > 40)).count();
        let ok = colours.len() > 100 && lit * 10 > shot.len() * 9;
        let why = format!(
            "a drawn scene has many colours and fills the window (sky, ground): {} colours, \
             {lit} of {} lit",
            colours.len(),
            shot.len()
        );
        (ok, why)
    });

    let (cx, cy) = (g.0 + g.2 / 2, g.1 + g.3 / 2);
    run(
        &display,
        "xdotool",
        &["mousemove", &cx.to_string(), &cy.to_string()],
    );
    run(&display, "xdotool", &["mousedown", "1"]);
    for step in 1..=10 {
        sleep(Duration::from_millis(50));
        let x = (cx + 12 * step).to_string();
        run(&display, "xdotool", &["mousemove", &x, &cy.to_string()]);
    }
    run(&display, "xdotool", &["mouseup", "1"]);
    wait_for(&display, dir.path(), g, "after", |after| {
        let diff: u64 = before
            .iter()
            .zip(after)
            .map(|(a, b)| (0..3).map(|i| u64::from(a[i].abs_diff(b[i]))).sum::<u64>())
            .sum();
        let mean = diff as f64 / (3 * before.len()) as f64;
        let why = format!("a 120-pixel drag must turn the view: mean change {mean:.2} of 255");
        (mean > 4.0, why)
    });

    run(&display, "xdotool", &["windowfocus", "--sync", &window]);
    // F: the overlay's white glyphs appear in the top-left corner.
    let white = |shot: &[[u8; 3]]| {
        (0..60)
            .flat_map(|y| (0..200).map(move |x| (x, y)))
            .filter(|&(x, y)| shot[y * g.2 + x] == [255; 3])
            .count()
    };
    let plain = white(&before);
    run(&display, "xdotool", &["key", "f"]);
    wait_for(&display, dir.path(), g, "overlay", |shot| {
        let lit = white(shot);
        let why = format!("F must show the overlay: {lit} white pixels, {plain} before");
        (lit > plain + 200, why)
    });
    // S: a screenshot of the frame at the window's size.
    run(&display, "xdotool", &["key", "s"]);
    let saved = dir.path().join("bubbles-view-0001.png");
    let deadline = Instant::now() + Duration::from_secs(60);
    while png_size(&saved) != Some((320, 240)) {
        assert!(
            Instant::now() < deadline,
            "S must save a 320x240 {}: {:?}",
            saved.display(),
            png_size(&saved)
        );
        sleep(Duration::from_millis(200));
    }
    run(&display, "xdotool", &["key", "Escape"]);
    let deadline = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(status) = viewer.0.try_wait().unwrap() {
            break status;
        }
        assert!(Instant::now() < deadline, "Escape did not close the viewer");
        sleep(Duration::from_millis(100));
    };
    let err = std::fs::read_to_string(&stderr_path).unwrap();
    assert_eq!(status.code(), Some(0), "Escape must exit 0: {err}");
    Some(err)
}

/// Width and height from a PNG's header, if `path` holds one (complete or not).
fn png_size(path: &Path) -> Option<(u32, u32)> {
    let bytes = std::fs::read(path).ok()?;
    let field = |i: usize| Some(u32::from_be_bytes(bytes.get(i..i + 4)?.try_into().ok()?));
    (bytes.starts_with(b"\x89PNG") && bytes.len() > 100).then_some((field(16)?, field(20)?))
}

/// Screenshots the window at `g` every half second until `check` passes, and returns
/// that screenshot; fails with `check`'s explanation after a minute.
fn wait_for(
    display: &str,
    dir: &Path,
    g: (usize, usize, usize, usize),
    name: &str,
    check: impl Fn(&[[u8; 3]]) -> (bool, String),
) -> Vec<[u8; 3]> {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        sleep(Duration::from_millis(500));
        let shot = crop(&screenshot(display, dir, &format!("{name}.xwd")), g);
        let (ok, why) = check(&shot);
        if ok {
            return shot;
        }
        assert!(Instant::now() < deadline, "{why}");
    }
}

fn run_ok(display: &str, program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .env("DISPLAY", display)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}
