//! The layout's one-way flow, enforced: no cycles between the top-level modules of `src/`, the
//! two backends never name each other, and the experiments name no backend (only `job` picks
//! one).
//!
//! Every `crate::<path>` in `src/**/*.rs` counts, `use crate::{a, b::{c, d}}` groups included,
//! comments and doc links too (a doc link is a dependency a reader follows). A file belongs to
//! the top-level module of its first path component (`src/backend/gpu/engine/mod.rs` →
//! `backend`); `main.rs` and `lib.rs` only declare and call modules.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file below `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The paths a `use` tree names, from its start (after `crate::`): `a::b`, or `{a, b::{c, d}}`
/// → `a`, `b::c`, `b::d`. Returns the paths and how many bytes the tree took.
fn tree_paths(text: &str) -> (Vec<Vec<String>>, usize) {
    let mut at = 0;
    let mut prefix = Vec::new();
    loop {
        let rest = &text[at..];
        let ident: String = rest.chars().take_while(|&c| is_ident(c)).collect();
        if !ident.is_empty() {
            at += ident.len();
            prefix.push(ident);
            if text[at..].starts_with("::") {
                at += 2;
                continue;
            }
            return (vec![prefix], at);
        }
        if rest.starts_with('{') {
            at += 1;
            let mut paths = Vec::new();
            loop {
                let skipped = text[at..].len() - text[at..].trim_start().len();
                at += skipped;
                if text[at..].starts_with('}') {
                    return (paths, at + 1);
                }
                if text[at..].starts_with(',') {
                    at += 1;
                    continue;
                }
                let (inner, used) = tree_paths(&text[at..]);
                if used == 0 {
                    // `self`, `*` or something this scanner does not follow: skip a character.
                    at += text[at..].chars().next().map_or(1, char::len_utf8);
                    continue;
                }
                for p in inner {
                    // `self` in a group names the group's own prefix.
                    let p = p.into_iter().filter(|part| part != "self");
                    paths.push(prefix.iter().cloned().chain(p).collect());
                }
                at += used;
            }
        }
        return (
            if prefix.is_empty() {
                vec![]
            } else {
                vec![prefix]
            },
            at,
        );
    }
}

/// Every path named after `crate::` in `text`.
fn crate_paths(text: &str) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    let mut from = 0;
    while let Some(found) = text[from..].find("crate::") {
        let start = from + found;
        let preceded = text[..start].chars().next_back().is_some_and(is_ident);
        from = start + "crate::".len();
        if preceded {
            continue; // `dustdem_crate::` and the like
        }
        let (found, used) = tree_paths(&text[from..]);
        paths.extend(found);
        from += used.max(1).min(text.len() - from);
    }
    paths
}

/// The module path of a file below `src/` (`backend/gpu/engine/mod.rs` → backend, gpu,
/// engine).
fn module_of(relative: &Path) -> Vec<String> {
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap();
    let stem = last.strip_suffix(".rs").unwrap().to_string();
    if stem != "mod" {
        parts.push(stem);
    }
    parts
}

struct Reference {
    file: String,
    from: Vec<String>,
    to: Vec<String>,
}

fn references() -> Vec<Reference> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut all = Vec::new();
    for file in rust_files(&src) {
        let relative = file.strip_prefix(&src).unwrap();
        let from = module_of(relative);
        if from.is_empty() || from == ["main"] || from == ["lib"] {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for to in crate_paths(&text) {
            all.push(Reference {
                file: relative.display().to_string(),
                from: from.clone(),
                to,
            });
        }
    }
    all
}

/// Edges between top-level modules, each with one file that makes it.
fn top_level_graph(refs: &[Reference]) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut graph: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for r in refs {
        let (from, to) = (&r.from[0], &r.to[0]);
        graph.entry(from.clone()).or_default();
        if from != to {
            graph
                .entry(from.clone())
                .or_default()
                .entry(to.clone())
                .or_insert_with(|| r.file.clone());
        }
    }
    graph
}

/// A cycle through `start`, as the modules in order (`start` first), if there is one.
fn cycle_through(
    graph: &BTreeMap<String, BTreeMap<String, String>>,
    start: &str,
) -> Option<Vec<String>> {
    fn walk(
        graph: &BTreeMap<String, BTreeMap<String, String>>,
        start: &str,
        at: &str,
        path: &mut Vec<String>,
        seen: &mut BTreeSet<String>,
    ) -> bool {
        for next in graph.get(at).into_iter().flat_map(|e| e.keys()) {
            if next == start {
                return true;
            }
            if seen.insert(next.clone()) {
                path.push(next.clone());
                if walk(graph, start, next, path, seen) {
                    return true;
                }
                path.pop();
            }
        }
        false
    }
    let mut path = vec![start.to_string()];
    let mut seen = BTreeSet::new();
    walk(graph, start, start, &mut path, &mut seen).then_some(path)
}

fn starts_with(path: &[String], prefix: &[&str]) -> bool {
    path.len() >= prefix.len() && path.iter().zip(prefix).all(|(a, b)| a == b)
}

#[test]
fn top_level_modules_have_no_cycles() {
    let refs = references();
    let graph = top_level_graph(&refs);
    // The scan sees the layout: the job picks a backend, the experiments use the state.
    assert!(graph["job"].contains_key("backend"), "{graph:?}");
    assert!(graph["experiment"].contains_key("engine"), "{graph:?}");
    let mut cycles = BTreeSet::new();
    for module in graph.keys() {
        if let Some(mut cycle) = cycle_through(&graph, module) {
            // One report per cycle, whichever module it was found from.
            let first = cycle.iter().enumerate().min_by_key(|(_, m)| *m).unwrap().0;
            cycle.rotate_left(first);
            cycles.insert(cycle);
        }
    }
    let described: Vec<String> = cycles
        .iter()
        .map(|cycle| {
            let mut steps = Vec::new();
            for (k, from) in cycle.iter().enumerate() {
                let to = &cycle[(k + 1) % cycle.len()];
                steps.push(format!("{from} → {to} ({})", graph[from][to]));
            }
            steps.join(", ")
        })
        .collect();
    assert!(
        described.is_empty(),
        "cycles between top-level modules:\n  {}",
        described.join("\n  ")
    );
}

#[test]
fn the_backends_are_leaves_and_the_experiments_name_none() {
    let refs = references();
    let mut wrong = Vec::new();
    for r in &refs {
        let pairs: [(&[&str], &[&str]); 3] = [
            (&["backend", "cpu"], &["backend", "gpu"]),
            (&["backend", "gpu"], &["backend", "cpu"]),
            (&["experiment"], &["backend"]),
        ];
        for (from, to) in pairs {
            if starts_with(&r.from, from) && starts_with(&r.to, to) {
                wrong.push(format!("{}: crate::{}", r.file, r.to.join("::")));
            }
        }
    }
    // Relative paths between the backends (`super::gpu` from backend/cpu/mod.rs).
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    for (dir, other) in [("cpu", "gpu"), ("gpu", "cpu")] {
        let file = src.join("backend").join(dir).join("mod.rs");
        let text = std::fs::read_to_string(&file).unwrap();
        if text.contains(&format!("super::{other}")) {
            wrong.push(format!("backend/{dir}/mod.rs: super::{other}"));
        }
    }
    assert!(
        wrong.is_empty(),
        "backend::cpu and backend::gpu must not name each other, nor experiment a backend:\n  {}",
        wrong.join("\n  ")
    );
    // The check can fail: the job names both backends.
    for backend in ["cpu", "gpu"] {
        assert!(
            refs.iter()
                .any(|r| r.from[0] == "job" && starts_with(&r.to, &["backend", backend])),
            "the scan found no reference from job to backend::{backend}"
        );
    }
}

#[test]
fn use_groups_and_paths_are_read() {
    let text = "use crate::{a, b::{c, d::e}, f::g};\nlet x = crate::h::i(1);\n\
                // see [`crate::j`]\nnot_crate::k; use crate::l::{self, m};";
    let found: Vec<String> = crate_paths(text).iter().map(|p| p.join("::")).collect();
    assert_eq!(
        found,
        ["a", "b::c", "b::d::e", "f::g", "h::i", "j", "l", "l::m"],
        "{found:?}"
    );
    assert_eq!(
        module_of(Path::new("backend/gpu/engine/mod.rs")),
        ["backend", "gpu", "engine"]
    );
    assert_eq!(module_of(Path::new("job/backend.rs")), ["job", "backend"]);
}

#[test]
fn a_cycle_is_found_and_named() {
    let mut graph: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for (a, b) in [("x", "y"), ("y", "z"), ("z", "x"), ("z", "w")] {
        graph
            .entry(a.into())
            .or_default()
            .insert(b.into(), "f.rs".into());
    }
    assert_eq!(cycle_through(&graph, "x").unwrap(), ["x", "y", "z"]);
    assert_eq!(cycle_through(&graph, "w"), None);
}
