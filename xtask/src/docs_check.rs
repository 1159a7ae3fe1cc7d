//! `cargo xtask docs-check`: every figure block in docs/ names the command that
//! reproduces it.
//!
//! The Markdown files are cut into blocks at blank lines (a fenced code block is one
//! block). A *figure block* embeds an image (`![`) or says "measured". It names its
//! command when it, or the block just before or after it, holds a command in backticks
//! or in a fenced block: text starting with `cargo `, `bubbles `, `BLESS=`,
//! `CARGO_TARGET_DIR=`, `python3 `, `perf ` or `valgrind `.

use std::path::{Path, PathBuf};

/// How a reproducing command starts.
const COMMAND_STARTS: [&str; 7] = [
    "cargo ",
    "bubbles ",
    "BLESS=",
    "CARGO_TARGET_DIR=",
    "python3 ",
    "perf ",
    "valgrind ",
];

/// A run of non-blank lines, or one fenced code block.
struct Block {
    first_line: usize,
    text: String,
    fenced: bool,
}

/// Checks every `docs/*.md`; prints each figure block without a command and returns
/// whether there were none.
pub fn run() -> bool {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs");
    let mut files: Vec<PathBuf> = match std::fs::read_dir(&docs) {
        Ok(entries) => entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "md"))
            .collect(),
        Err(err) => {
            eprintln!("docs-check: cannot read {}: {err}", docs.display());
            return false;
        }
    };
    files.sort();
    let mut missing = 0;
    for path in &files {
        let Ok(text) = std::fs::read_to_string(path) else {
            eprintln!("docs-check: cannot read {}", path.display());
            return false;
        };
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        for (line, excerpt) in figures_without_command(&text) {
            eprintln!("docs/{name}:{line}: figure block names no command: {excerpt}");
            missing += 1;
        }
    }
    if missing == 0 {
        eprintln!(
            "docs-check: every figure block in {} files names its command",
            files.len()
        );
    }
    missing == 0
}

/// (line, excerpt) of each figure block in `markdown` with no command in reach.
fn figures_without_command(markdown: &str) -> Vec<(usize, String)> {
    let blocks = blocks(markdown);
    let mut out = Vec::new();
    for (k, block) in blocks.iter().enumerate() {
        if block.fenced || !is_figure(&block.text) {
            continue;
        }
        let neighbours = [k.checked_sub(1), Some(k), Some(k + 1)];
        let named = neighbours
            .iter()
            .flatten()
            .filter_map(|&i| blocks.get(i))
            .any(has_command);
        if !named {
            let excerpt: String = block.text.chars().take(90).collect();
            out.push((block.first_line, excerpt.replace('\n', " ")));
        }
    }
    out
}

fn is_figure(text: &str) -> bool {
    text.contains("![") || text.to_lowercase().contains("measured")
}

fn has_command(block: &Block) -> bool {
    let starts = |s: &str| COMMAND_STARTS.iter().any(|c| s.trim_start().starts_with(c));
    if block.fenced {
        return block.text.lines().any(starts);
    }
    // Code spans: the text between pairs of backticks.
    block.text.split('`').skip(1).step_by(2).any(starts)
}

fn blocks(markdown: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut current: Option<Block> = None;
    let mut in_fence = false;
    for (i, line) in markdown.lines().enumerate() {
        let fence = line.trim_start().starts_with("```");
        if in_fence {
            if let Some(b) = current.as_mut() {
                b.text.push_str(line);
                b.text.push('\n');
            }
            if fence {
                in_fence = false;
                blocks.extend(current.take());
            }
            continue;
        }
        if fence {
            blocks.extend(current.take());
            in_fence = true;
            current = Some(Block {
                first_line: i + 1,
                text: String::new(),
                fenced: true,
            });
            continue;
        }
        if line.trim().is_empty() {
            blocks.extend(current.take());
            continue;
        }
        let block = current.get_or_insert_with(|| Block {
            first_line: i + 1,
            text: String::new(),
            fenced: false,
        });
        block.text.push_str(line);
        block.text.push('\n');
    }
    blocks.extend(current);
    blocks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_measured_paragraph_needs_a_command_nearby() {
        let bare = "Intro.\n\nMeasured: 3 ms per frame.\n\nOutro.\n";
        assert_eq!(figures_without_command(bare).len(), 1);
        let named = "Measured: 3 ms per frame (`cargo bench -p raster`).\n";
        assert!(figures_without_command(named).is_empty());
        let below = "Measured: 3 ms.\n\n```\ncargo bench -p raster\n```\n";
        assert!(figures_without_command(below).is_empty());
    }

    #[test]
    fn an_image_needs_a_command_and_code_fences_are_not_figures() {
        let image = "![chart](figures/chart.png)\n";
        assert_eq!(figures_without_command(image)[0].0, 1);
        let fenced = "```\nmeasured ![x](y)\n```\n";
        assert!(figures_without_command(fenced).is_empty());
        let far = "![chart](figures/chart.png)\n\nA.\n\nB `cargo xtask figures`.\n";
        assert_eq!(figures_without_command(far).len(), 1);
    }
}
