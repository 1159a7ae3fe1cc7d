//! The layout's invariants (docs/ARCHITECTURE.md), read from the sources: the GPU module
//! never imports the CPU renderer's modules, no two of the renderer's modules import each
//! other in a circle, the scene crate holds no pixel loop, thread pool or GPU code, and
//! the reference tracer never sees the rasterizer.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out.sort();
    out
}

/// The module path of a source file (`passes/opaque.rs` → `passes::opaque`, `lib.rs` → ``).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .filter(|p| p != "lib" && p != "mod")
        .collect();
    parts.join("::")
}

/// A file's code without its unit-test module (tests may reach anywhere).
fn code_of(file: &Path) -> String {
    let text = fs::read_to_string(file).unwrap();
    match text.find("#[cfg(test)]\nmod tests") {
        Some(k) => text[..k].to_string(),
        None => text,
    }
}

/// The paths after `prefix` in `code` (`crate::passes::opaque::X` → `passes::opaque::X`).
fn paths_after<'a>(code: &'a str, prefix: &str) -> Vec<&'a str> {
    code.match_indices(prefix)
        .map(|(k, _)| {
            let rest = &code[k + prefix.len()..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            rest[..end].trim_end_matches(':')
        })
        .collect()
}

/// Item name → the module `lib.rs` re-exports it from (`pub use camera::{Camera, X};`).
fn reexports(src: &Path) -> BTreeMap<String, String> {
    let lib = code_of(&src.join("lib.rs"));
    let mut out = BTreeMap::new();
    for stmt in lib.split(';') {
        let Some(rest) = stmt.trim().strip_prefix("pub use ") else {
            continue;
        };
        let Some((module, items)) = rest.split_once("::") else {
            continue;
        };
        for item in items.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')) {
            if !item.is_empty() {
                out.insert(item.to_string(), module.to_string());
            }
        }
    }
    out
}

/// The items of every `crate::{A, B}` group in `code`.
fn grouped_items(code: &str) -> Vec<&str> {
    code.match_indices("crate::{")
        .flat_map(|(k, m)| {
            let rest = &code[k + m.len()..];
            rest[..rest.find('}').unwrap_or(0)]
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .filter(|s| !s.is_empty())
        })
        .collect()
}

/// Module → the other modules of the crate it imports (`crate::` and `super::` paths
/// resolved to the longest module they name, root re-exports to the module they come
/// from). Doc comments are skipped.
fn import_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files = rust_files(src);
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(src, f)).collect();
    let reexported = reexports(src);
    let resolve = |path: &str| -> Option<String> {
        let parts: Vec<&str> = path.split("::").collect();
        (1..=parts.len())
            .rev()
            .map(|n| parts[..n].join("::"))
            .find(|m| modules.contains(m))
    };
    let mut graph = BTreeMap::new();
    for file in &files {
        let module = module_of(src, file);
        let code: String = code_of(file)
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let parent = module.rsplit_once("::").map_or("", |(p, _)| p).to_string();
        let mut deps = BTreeSet::new();
        for path in paths_after(&code, "crate::") {
            deps.extend(resolve(path));
            deps.extend(
                reexported
                    .get(path.split("::").next().unwrap_or(""))
                    .cloned(),
            );
        }
        for item in grouped_items(&code) {
            deps.extend(resolve(item));
            deps.extend(reexported.get(item).cloned());
        }
        for path in paths_after(&code, "super::") {
            let full = if parent.is_empty() {
                path.to_string()
            } else {
                format!("{parent}::{path}")
            };
            deps.insert(resolve(&full).unwrap_or_else(|| parent.clone()));
        }
        deps.remove(&module);
        deps.remove("");
        graph.insert(module, deps);
    }
    graph
}

/// One import circle of `graph`, if any, as the modules along it.
fn find_circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        m: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        stack: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(k) = stack.iter().position(|s| s == m) {
            let mut circle = stack[k..].to_vec();
            circle.push(m.to_string());
            return Some(circle);
        }
        if done.contains(m) {
            return None;
        }
        stack.push(m.to_string());
        for d in graph.get(m).into_iter().flatten() {
            if let Some(c) = visit(d, graph, stack, done) {
                return Some(c);
            }
        }
        stack.pop();
        done.insert(m.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|m| visit(m, graph, &mut Vec::new(), &mut done))
}

fn crate_dir(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(name)
}

#[test]
fn the_renderers_modules_import_each_other_in_no_circle() {
    let graph = import_graph(&crate_dir("raster").join("src"));
    assert!(graph.contains_key("passes::opaque"), "{graph:?}");
    assert!(
        graph["passes::water"].contains("passes::opaque"),
        "the graph misses a known import: {graph:?}"
    );
    if let Some(circle) = find_circle(&graph) {
        panic!("import circle: {}", circle.join(" → "));
    }
}

#[test]
fn the_scene_crates_modules_import_each_other_in_no_circle() {
    let graph = import_graph(&crate_dir("render-scene").join("src"));
    assert!(
        graph["scene"].contains("water") && graph["water"].contains("material"),
        "the graph misses a known import: {graph:?}"
    );
    if let Some(circle) = find_circle(&graph) {
        panic!("import circle: {}", circle.join(" → "));
    }
}

#[test]
fn the_circle_finder_finds_a_circle() {
    let mut graph = BTreeMap::new();
    graph.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    graph.insert("b".to_string(), BTreeSet::from(["c".to_string()]));
    graph.insert("c".to_string(), BTreeSet::from(["a".to_string()]));
    assert_eq!(find_circle(&graph).unwrap(), ["a", "b", "c", "a"]);
    graph.get_mut("c").unwrap().clear();
    assert_eq!(find_circle(&graph), None);
}

#[test]
fn the_gpu_module_never_imports_the_cpu_renderer() {
    let graph = import_graph(&crate_dir("raster").join("src"));
    for (module, deps) in graph.iter().filter(|(m, _)| m.starts_with("gpu")) {
        for d in deps {
            assert!(
                d.starts_with("gpu"),
                "{module} imports the CPU renderer's {d}: move what both need into render_scene"
            );
        }
    }
}

#[test]
fn the_scene_crate_holds_no_pixel_loop_thread_pool_or_gpu_code() {
    let dir = crate_dir("render-scene");
    let manifest = fs::read_to_string(dir.join("Cargo.toml")).unwrap();
    for dep in ["rayon", "wgpu", "raster"] {
        assert!(
            !manifest.lines().any(|l| l.trim_start().starts_with(dep)),
            "render-scene depends on {dep}"
        );
    }
    for file in rust_files(&dir.join("src")) {
        let code = code_of(&file);
        for word in ["par_iter", "par_chunks", "rayon", "wgpu::"] {
            assert!(!code.contains(word), "{} uses {word}", file.display());
        }
    }
}

#[test]
fn the_reference_tracer_never_sees_the_rasterizer() {
    let dir = crate_dir("reference-tracer");
    let manifest = fs::read_to_string(dir.join("Cargo.toml")).unwrap();
    assert!(
        !manifest
            .lines()
            .any(|l| l.trim_start().starts_with("raster")),
        "reference-tracer depends on raster"
    );
    for file in rust_files(&dir.join("src")) {
        assert!(
            !code_of(&file).contains("raster::"),
            "{} names raster",
            file.display()
        );
    }
}
