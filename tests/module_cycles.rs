//! The layout's one-way flow, enforced: no cycles between the top-level modules of `src/`, the
//! two backends never name each other, and the experiments name no backend (only `job` picks
//! one). Within the backends the same holds one level down: no cycles between the modules of
//! `src/backend`, of `src/backend/cpu` (the CPU engine's layers, DESIGN.md, "CPU engine
//! layers") and of each folder below it.
//!
//! Every `crate::<path>` in `src/**/*.rs` counts, `use crate::{a, b::{c, d}}` groups included,
//! comments and doc links too (a doc link is a dependency a reader follows). A file belongs to
//! the top-level module of its first path component (`src/backend/gpu/engine/mod.rs` →
//! `backend`); `main.rs` and `lib.rs` only declare and call modules. Below the top level,
//! `super::` and `self::` paths count as well, and in a file with child modules the paths that
//! start with a child's name.

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
    paths_after(text, "crate::", is_ident)
        .into_iter()
        .map(|(_, p)| p)
        .collect()
}

/// Every path named after `start` (`crate::`, `super::`, `lanes::`, ...) where the character
/// before it is not one that `joined` accepts (part of a longer name or path), with where it
/// starts.
fn paths_after(text: &str, start: &str, joined: fn(char) -> bool) -> Vec<(usize, Vec<String>)> {
    let mut paths = Vec::new();
    let mut from = 0;
    while let Some(found) = text[from..].find(start) {
        let at = from + found;
        let preceded = text[..at].chars().next_back().is_some_and(joined);
        from = at + start.len();
        if preceded {
            continue; // `dustdem_crate::` and the like
        }
        let (found, used) = tree_paths(&text[from..]);
        paths.extend(found.into_iter().map(|p| (at, p)));
        from += used.max(1).min(text.len() - from);
    }
    paths
}

/// The inline modules (`mod name { ... }`) of `text`: each one's name and the bytes its body
/// spans. Braces in comments, strings and character literals are skipped.
fn inline_modules(text: &str) -> Vec<(String, std::ops::Range<usize>)> {
    let bytes = text.as_bytes();
    let mut open: Vec<Option<(String, usize)>> = Vec::new();
    let mut found = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let rest = &text[at..];
        if rest.starts_with("//") {
            at += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            at += rest.find("*/").map_or(rest.len(), |e| e + 2);
        } else if rest.starts_with('"') {
            at += 1;
            while at < bytes.len() && bytes[at] != b'"' {
                at += if bytes[at] == b'\\' { 2 } else { 1 };
            }
            at += 1;
        } else if rest.starts_with("'{'") || rest.starts_with("'}'") {
            at += 3;
        } else if rest.starts_with('{') {
            // `mod name {`: the words before the brace.
            let before: Vec<&str> = text[..at].split_whitespace().rev().take(2).collect();
            let name = match before.as_slice() {
                [name, "mod"] if name.chars().all(is_ident) => Some((name.to_string(), at + 1)),
                _ => None,
            };
            open.push(name);
            at += 1;
        } else if rest.starts_with('}') {
            if let Some(Some((name, start))) = open.pop() {
                found.push((name, start..at));
            }
            at += 1;
        } else {
            at += rest.chars().next().map_or(1, char::len_utf8);
        }
    }
    found
}

/// Part of a name or of a path before it (`super::super::`, `a::super`).
fn in_path(c: char) -> bool {
    is_ident(c) || c == ':'
}

/// The names of the modules a file declares as files or folders of its own: those in its
/// folder for a `mod.rs`, in the folder of its name otherwise.
fn children_of(file: &Path) -> Vec<String> {
    let dir = match file.file_name().is_some_and(|n| n == "mod.rs") {
        true => file.parent().unwrap().to_path_buf(),
        false => file.with_extension(""),
    };
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return vec![];
    };
    let mut names: Vec<String> = entries
        .map(|e| e.unwrap().path())
        .filter_map(|p| match p.is_dir() {
            true => Some(p.file_name()?.to_string_lossy().into_owned()),
            false => (p.extension()? == "rs" && p.file_stem()? != "mod")
                .then(|| p.file_stem().unwrap().to_string_lossy().into_owned()),
        })
        .collect();
    names.sort();
    names
}

/// Every module path a file at module `from` names, from the crate root: `crate::` paths,
/// `super::` and `self::` ones resolved from `from` (and the inline modules they are in), and
/// those outside inline modules that start with the name of one of `children` (the file's own
/// child modules).
fn resolved_paths(text: &str, from: &[String], children: &[String]) -> Vec<Vec<String>> {
    let inline = inline_modules(text);
    // The module of the text at `at`: the file's, then each inline module around it.
    let module_at = |at: usize| -> Vec<String> {
        let mut around: Vec<&(String, std::ops::Range<usize>)> =
            inline.iter().filter(|(_, r)| r.contains(&at)).collect();
        around.sort_by_key(|(_, r)| r.start);
        from.iter()
            .cloned()
            .chain(around.iter().map(|(n, _)| n.clone()))
            .collect()
    };
    let mut all = crate_paths(text);
    for (at, path) in paths_after(text, "super::", in_path) {
        let module = module_at(at);
        let ups = 1 + path.iter().take_while(|p| *p == "super").count();
        let base = &module[..module.len().saturating_sub(ups)];
        let rest = path.iter().skip(ups - 1);
        all.push(base.iter().chain(rest).cloned().collect());
    }
    for (at, path) in paths_after(text, "self::", in_path) {
        all.push(module_at(at).into_iter().chain(path).collect());
    }
    for child in children {
        for (at, path) in paths_after(text, &format!("{child}::"), in_path) {
            if module_at(at).len() == from.len() {
                let child = std::iter::once(child);
                all.push(from.iter().chain(child).chain(&path).cloned().collect());
            }
        }
    }
    all
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

/// Every reference of every file below `src/`, resolved to module paths from the crate root
/// ([`resolved_paths`]), with the file's own module path.
fn resolved_references() -> Vec<Reference> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut all = Vec::new();
    for file in rust_files(&src) {
        let relative = file.strip_prefix(&src).unwrap();
        let from = module_of(relative);
        let text = std::fs::read_to_string(&file).unwrap();
        for to in resolved_paths(&text, &from, &children_of(&file)) {
            all.push(Reference {
                file: relative.display().to_string(),
                from: from.clone(),
                to,
            });
        }
    }
    all
}

/// Edges between the modules directly below `parent` (each file or folder there is one node;
/// the parent's own file, `mod.rs`, is another, holding what names the parent itself), each
/// with one file that makes it. Every child is a node, with or without edges.
fn child_graph(refs: &[Reference], parent: &[&str]) -> BTreeMap<String, BTreeMap<String, String>> {
    let dir = parent
        .iter()
        .fold(Path::new(env!("CARGO_MANIFEST_DIR")).join("src"), |d, p| {
            d.join(p)
        });
    let own = match dir.join("mod.rs").exists() {
        true => "mod.rs".to_string(),
        false => format!("{}.rs", parent.last().unwrap()),
    };
    let children = children_of(&dir.join("mod.rs"));
    let node = |path: &[String]| -> Option<String> {
        if !starts_with(path, parent) {
            return None;
        }
        match path.get(parent.len()) {
            Some(child) if children.contains(child) => Some(child.clone()),
            _ => Some(own.clone()),
        }
    };
    let mut graph: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for child in children.iter().chain([&own]) {
        graph.entry(child.clone()).or_default();
    }
    for r in refs {
        let (Some(from), Some(to)) = (node(&r.from), node(&r.to)) else {
            continue;
        };
        if from != to {
            graph
                .entry(from)
                .or_default()
                .entry(to)
                .or_insert_with(|| r.file.clone());
        }
    }
    graph
}

/// Every cycle of `graph`, once each (rotated to start at its least module), each step with
/// the file that makes it.
fn cycles_of(graph: &BTreeMap<String, BTreeMap<String, String>>) -> Vec<String> {
    let mut cycles = BTreeSet::new();
    for module in graph.keys() {
        if let Some(mut cycle) = cycle_through(graph, module) {
            let first = cycle.iter().enumerate().min_by_key(|(_, m)| *m).unwrap().0;
            cycle.rotate_left(first);
            cycles.insert(cycle);
        }
    }
    cycles
        .iter()
        .map(|cycle| {
            let mut steps = Vec::new();
            for (k, from) in cycle.iter().enumerate() {
                let to = &cycle[(k + 1) % cycle.len()];
                steps.push(format!("{from} → {to} ({})", graph[from][to]));
            }
            steps.join(", ")
        })
        .collect()
}

/// The graph as one line per module: `module → what it names`.
fn describe(graph: &BTreeMap<String, BTreeMap<String, String>>) -> String {
    graph
        .iter()
        .map(|(from, to)| {
            let to: Vec<&str> = to.keys().map(String::as_str).collect();
            format!("{from} → {}", to.join(", "))
        })
        .collect::<Vec<_>>()
        .join("\n  ")
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
fn the_backends_and_the_cpu_engines_layers_have_no_cycles() {
    let refs = resolved_references();
    let mut parents = vec![
        vec!["backend".to_string()],
        vec!["backend".into(), "cpu".into()],
    ];
    // And every folder below the CPU engine (its layers' own modules).
    let cpu = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/backend/cpu");
    for entry in std::fs::read_dir(&cpu).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            parents.push(vec!["backend".into(), "cpu".into(), name]);
        }
    }
    parents.sort();
    let mut failures = Vec::new();
    for parent in &parents {
        let parent: Vec<&str> = parent.iter().map(String::as_str).collect();
        let graph = child_graph(&refs, &parent);
        let cycles = cycles_of(&graph);
        if !cycles.is_empty() {
            failures.push(format!(
                "cycles between the modules of {}:\n  {}\nthe modules and what they name:\n  {}",
                parent.join("::"),
                cycles.join("\n  "),
                describe(&graph)
            ));
        }
    }
    // The scan sees the CPU engine's modules: the executor runs the passes.
    let cpu_graph = child_graph(&refs, &["backend", "cpu"]);
    let edges: usize = cpu_graph.values().map(BTreeMap::len).sum();
    assert!(cpu_graph.len() > 5 && edges > 5, "{cpu_graph:?}");
    assert!(!cpu_graph["executor"].is_empty(), "{cpu_graph:?}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn relative_paths_are_resolved() {
    let from: Vec<String> = ["backend", "cpu", "law", "forces"]
        .map(String::from)
        .to_vec();
    let children = ["kernels".to_string()];
    let text = "use super::lanes::{F4, V4};\nuse super::super::script::OWNER;\n\
                let x = self::inner::f(); kernels::g(); not_kernels::h(); a::super::b;\n\
                mod avx2 { use super::Isa; let s = \"}\"; } // }\n\
                mod tests { use super::*; kernels::t(); }";
    let found: Vec<String> = resolved_paths(text, &from, &children)
        .iter()
        .map(|p| p.join("::"))
        .collect();
    assert_eq!(
        found,
        [
            "backend::cpu::law::lanes::F4",
            "backend::cpu::law::lanes::V4",
            "backend::cpu::script::OWNER",
            "backend::cpu::law::forces::Isa",
            "backend::cpu::law::forces::inner::f",
            "backend::cpu::law::forces::kernels::g",
        ],
        "{found:?}"
    );
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
