//! Output paths, checked before the work that fills them: a file the user names must be
//! creatable where it is named, so a render never fails after minutes of work, and an
//! unwritable output is bad input (exit code 2) in every command.

use crate::error::{CliError, CliResult};
use std::path::Path;

/// The directory a file at `path` is created in (`.` for a bare name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Refuses, by `flag` and path, a file output that cannot be created: an existing
/// directory, a missing parent directory, or one where no file can be made (tried by
/// creating and removing a temporary file beside the target, as the writers do).
pub fn check_file(flag: &str, path: &Path) -> CliResult {
    let refuse = |why: String| CliError::input(format!("{flag} {}: {why}", path.display()));
    if path.is_dir() {
        return Err(refuse("is a directory, not a file".into()));
    }
    let parent = parent_dir(path);
    if !parent.is_dir() {
        return Err(refuse(format!(
            "directory {} does not exist",
            parent.display()
        )));
    }
    check_creatable(parent).map_err(refuse)
}

/// Refuses, by `flag` and path, a directory output that is a file or in which no file
/// can be created; a directory not there yet is checked at its nearest existing parent.
pub fn check_dir(flag: &str, dir: &Path) -> CliResult {
    let refuse = |why: String| CliError::input(format!("{flag} {}: {why}", dir.display()));
    if dir.exists() && !dir.is_dir() {
        return Err(refuse("is not a directory".into()));
    }
    let existing = dir
        .ancestors()
        .find(|a| a.is_dir())
        .unwrap_or(Path::new("."));
    check_creatable(existing).map_err(refuse)
}

/// Whether a file can be created in `dir`: creates and removes a private temporary.
fn check_creatable(dir: &Path) -> Result<(), String> {
    tempfile::Builder::new()
        .prefix(".bubbles-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| {
            format!(
                "cannot create a file in {}: {}",
                dir.display(),
                os_reason(&e)
            )
        })
}

/// The operating system's reason for `e`, without the ` at path "…"` naming the probe's
/// random temporary that `tempfile` appends.
fn os_reason(e: &std::io::Error) -> String {
    let text = e.to_string();
    match text.split_once(" at path \"") {
        Some((reason, _)) => reason.to_string(),
        None => text,
    }
}

/// Refuses, by `flag`, an output `out` that names one of the `inputs`, however spelled
/// (`./a.png`, `dir/../a.png`, a symbolic or hard link): `what` would replace it.
pub fn refuse_overwriting(flag: &str, out: &Path, inputs: &[&Path], what: &str) -> CliResult {
    // A path that does not exist yet cannot be an input that does.
    let Ok(out_meta) = std::fs::metadata(out) else {
        return Ok(());
    };
    let out_real = std::fs::canonicalize(out).ok();
    for input in inputs.iter().copied() {
        let same_path = out_real.is_some() && std::fs::canonicalize(input).ok() == out_real;
        let same_file = std::fs::metadata(input).is_ok_and(|m| same_inode(&m, &out_meta));
        if same_path || same_file {
            return Err(CliError::input(format!(
                "{flag} {} is the input {}: {what} would overwrite it; write it elsewhere",
                out.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

/// Whether two metadata describe the same file (device and inode; never on non-Unix).
fn same_inode(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        a.dev() == b.dev() && a.ino() == b.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (a, b);
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_no_file_and_a_file_no_directory() {
        let dir = tempfile::tempdir().unwrap();
        let err = check_file("--out", dir.path()).unwrap_err();
        assert_eq!(err.exit_code(), 2);
        assert!(err.to_string().contains("is a directory"), "{err}");
        let file = dir.path().join("a.png");
        std::fs::write(&file, b"x").unwrap();
        assert!(check_file("--out", &file).is_ok());
        assert!(check_dir("--out", &file).is_err());
        assert!(check_dir("--out", &dir.path().join("new/deeper")).is_ok());
        assert!(check_file("--out", &dir.path().join("no/such.png")).is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "the probe leaves no temporary behind");
    }
}
