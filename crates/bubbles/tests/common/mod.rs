//! Helpers shared by the CLI tests: run the built `bubbles` binary and read its output.
// Each test file is its own crate and uses only some of these.
#![allow(dead_code)]

pub mod hostile;

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};

/// Runs `bubbles ARGS` in `dir` and waits for it.
pub fn bubbles(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("bubbles runs")
}

/// Runs `bubbles ARGS` with `stdin` piped in and waits for it.
pub fn bubbles_piped(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn bubbles");
    // The command may reject its options and exit before reading stdin; the broken
    // pipe that then ends this write is expected, and the exit status tells the story.
    let _ = child.stdin.take().unwrap().write_all(stdin.as_bytes());
    child.wait_with_output().unwrap()
}

/// The process's standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The number under `key` in `bubbles compare --json` output.
pub fn json_field(json: &str, key: &str) -> f64 {
    let start = json.find(&format!("\"{key}\": ")).expect(key) + key.len() + 4;
    let rest = &json[start..];
    let end = rest.find([',', '}']).unwrap();
    rest[..end].trim().parse().unwrap()
}

/// Runs `bubbles bake ARGS` in the working directory and waits for it.
pub fn bake(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bubbles"))
        .arg("bake")
        .args(args)
        .output()
        .expect("bubbles runs")
}

/// The names of the files in `dir`, sorted; none when it does not exist.
pub fn files_in(dir: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut names: Vec<_> = entries
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
