//! `bubbles view`: without a display it exits 2; under Xvfb, driven by real X input
//! events (xdotool), it draws the scene, a drag changes the view and Escape exits 0.
#![cfg(feature = "view")]

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

fn bubbles() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bubbles"))
}

#[test]
fn without_a_display_view_exits_2_naming_the_variables() {
    let out = bubbles()
        .args(["view", "paper"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
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
    let tools = ["Xvfb", "xdotool", "xwd"];
    let missing: Vec<_> = tools.iter().filter(|t| !have(t)).collect();
    if !missing.is_empty() {
        // CI installs them (.ci/run); there a missing tool is a failure, not a skip.
        assert!(
            std::env::var("CI").is_err(),
            "CI must install {missing:?} (apt-get install xvfb xdotool x11-apps)"
        );
        eprintln!("skipped: {missing:?} not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let display = format!(":{}", 100 + std::process::id() % 800);
    let _xvfb = Reap(
        Command::new("Xvfb")
            .args([
                display.as_str(),
                "-screen",
                "0",
                "640x480x24",
                "-nolisten",
                "tcp",
            ])
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let deadline = Instant::now() + Duration::from_secs(20);
    while !run_ok(&display, "xdotool", &["getmouselocation"]) {
        assert!(Instant::now() < deadline, "Xvfb {display} did not start");
        sleep(Duration::from_millis(100));
    }
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
            .env("DISPLAY", &display)
            .env_remove("WAYLAND_DISPLAY")
            .current_dir(dir.path())
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
            "the viewer exited early"
        );
        assert!(Instant::now() < deadline, "no window appeared");
        sleep(Duration::from_millis(200));
    };
    sleep(Duration::from_secs(3));
    let g = geometry(&display, &window);
    let before = crop(&screenshot(&display, dir.path(), "before.xwd"), g);
    let mut colours: Vec<[u8; 3]> = before.clone();
    colours.sort_unstable();
    colours.dedup();
    let lit = before.iter().filter(|p| p.iter().any(|&c| c > 40)).count();
    assert!(
        colours.len() > 100,
        "a drawn scene has many colours, got {}",
        colours.len()
    );
    assert!(
        lit * 10 > before.len() * 9,
        "the scene (sky, ground) fills the window: {lit} of {} lit",
        before.len()
    );

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
    sleep(Duration::from_secs(3));
    let after = crop(&screenshot(&display, dir.path(), "after.xwd"), g);
    let diff: u64 = before
        .iter()
        .zip(&after)
        .map(|(a, b)| (0..3).map(|i| u64::from(a[i].abs_diff(b[i]))).sum::<u64>())
        .sum();
    let mean = diff as f64 / (3 * before.len()) as f64;
    assert!(
        mean > 4.0,
        "a 120-pixel drag must turn the view: mean change {mean:.2} of 255"
    );

    run(&display, "xdotool", &["windowfocus", "--sync", &window]);
    run(&display, "xdotool", &["key", "Escape"]);
    let deadline = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(status) = viewer.0.try_wait().unwrap() {
            break status;
        }
        assert!(Instant::now() < deadline, "Escape did not close the viewer");
        sleep(Duration::from_millis(100));
    };
    assert_eq!(status.code(), Some(0), "Escape must exit 0");
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
