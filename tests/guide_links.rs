//! Every relative link of the user guide (docs/guide/src) and of README.md points at a file
//! that exists and, where it names an anchor in a Markdown file, at a heading of that file; every
//! `{{#include}}` names a file that exists; every chapter is listed in SUMMARY.md. No network:
//! web links are not followed.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn guide_pages() -> Vec<PathBuf> {
    let mut pages = Vec::new();
    let mut dirs = vec![root().join("docs/guide/src")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                pages.push(path);
            }
        }
    }
    pages.sort();
    pages
}

/// The text without fenced code blocks and inline code, where brackets are not links.
fn prose(text: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            out.push('\n');
            continue;
        }
        if !fenced {
            let kept: String = line.split('`').step_by(2).collect::<Vec<_>>().join("");
            out.push_str(&kept);
        }
        out.push('\n');
    }
    out
}

/// Targets of inline links and images: `[text](target)`, `![alt](target "title")`.
fn link_targets(text: &str) -> Vec<String> {
    let text = prose(text);
    let mut targets = Vec::new();
    let mut rest = text.as_str();
    while let Some(at) = rest.find("](") {
        rest = &rest[at + 2..];
        let end = rest.find(')').unwrap_or(rest.len());
        let target = rest[..end].split_whitespace().next().unwrap_or("");
        targets.push(target.trim_matches(['<', '>']).to_string());
    }
    targets
}

/// Heading anchors as mdBook makes them: lowercase alphanumerics, `_` and `-`, spaces to `-`,
/// the rest dropped; repeated ones numbered.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        }
        if fenced || !line.starts_with('#') {
            continue;
        }
        let title = line.trim_start_matches('#').trim();
        let id: String = title
            .chars()
            .filter_map(|c| {
                if c.is_alphanumeric() || c == '_' || c == '-' {
                    Some(c.to_ascii_lowercase())
                } else if c.is_whitespace() {
                    Some('-')
                } else {
                    None
                }
            })
            .collect();
        let mut unique = id.clone();
        let mut n = 1;
        while seen.contains(&unique) {
            unique = format!("{id}-{n}");
            n += 1;
        }
        seen.insert(unique);
    }
    seen
}

/// The Markdown a page shows: its own text with `{{#include}}` files spliced in.
fn expanded(page: &Path) -> String {
    let text = std::fs::read_to_string(page).unwrap();
    let mut out = String::new();
    for line in text.lines() {
        match include_target(line) {
            Some(target) => {
                let file = page.parent().unwrap().join(target);
                out.push_str(&std::fs::read_to_string(&file).unwrap_or_default());
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

fn include_target(line: &str) -> Option<&str> {
    let inner = line
        .trim()
        .strip_prefix("{{#include ")?
        .strip_suffix("}}")?;
    Some(inner.trim().split(':').next().unwrap())
}

fn check_page(page: &Path, problems: &mut Vec<String>) {
    let raw = std::fs::read_to_string(page).unwrap();
    for line in raw.lines() {
        if let Some(target) = include_target(line) {
            if !page.parent().unwrap().join(target).is_file() {
                problems.push(format!("{}: include {target} not found", page.display()));
            }
        }
    }
    let text = expanded(page);
    for target in link_targets(&text) {
        if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let (file, anchor) = match target.split_once('#') {
            Some((f, a)) => (f, Some(a)),
            None => (target.as_str(), None),
        };
        let path = if file.is_empty() {
            page.to_path_buf()
        } else {
            page.parent().unwrap().join(file)
        };
        if !path.exists() {
            problems.push(format!("{}: {target}: no such file", page.display()));
            continue;
        }
        if let Some(anchor) = anchor {
            if path.extension().is_some_and(|e| e == "md")
                && !anchors(&expanded(&path)).contains(anchor)
            {
                problems.push(format!("{}: {target}: no such heading", page.display()));
            }
        }
    }
}

#[test]
fn every_relative_link_of_the_guide_and_the_readme_resolves() {
    let mut pages = guide_pages();
    assert!(pages.len() >= 10, "the guide has {} pages", pages.len());
    pages.push(root().join("README.md"));
    let mut problems = Vec::new();
    for page in &pages {
        check_page(page, &mut problems);
    }
    assert!(
        problems.is_empty(),
        "broken links:\n{}",
        problems.join("\n")
    );
}

#[test]
fn every_chapter_is_in_the_summary() {
    let src = root().join("docs/guide/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let listed: BTreeSet<PathBuf> = link_targets(&summary)
        .into_iter()
        .map(|t| src.join(t))
        .collect();
    for page in guide_pages() {
        if page.file_name().is_some_and(|n| n == "SUMMARY.md") {
            continue;
        }
        assert!(
            listed.contains(&page),
            "{} is not in SUMMARY.md",
            page.display()
        );
    }
}

#[test]
fn the_checker_finds_a_broken_link_and_a_missing_heading() {
    let text = "# A title\n\nSee [there](#a-title), [gone](#nowhere) and `[code](x.md)`.\n";
    assert_eq!(link_targets(text), vec!["#a-title", "#nowhere"]);
    let ids =
        anchors("# The `dustdem bench` command\n## Güttler et al. 2009\n## Güttler et al. 2009\n");
    assert!(ids.contains("the-dustdem-bench-command"), "{ids:?}");
    assert!(
        ids.contains("güttler-et-al-2009") && ids.contains("güttler-et-al-2009-1"),
        "{ids:?}"
    );
    let dir = std::env::temp_dir().join(format!("dustdem-test-links-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("page.md");
    std::fs::write(
        &page,
        format!("{text}[file](missing.md) [ok](page.md#a-title)\n"),
    )
    .unwrap();
    let mut problems = Vec::new();
    check_page(&page, &mut problems);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(
        problems[0].contains("#nowhere") && problems[1].contains("missing.md"),
        "{problems:?}"
    );
}
