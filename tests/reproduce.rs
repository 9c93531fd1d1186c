//! `dustdem reproduce`: the smoke tier runs its four sweeps, stores the finished cases and
//! writes REPRODUCTION.md with a verdict on every claim; a second call runs nothing and
//! changes nothing, and the store alone (no runs) rebuilds the report and its figures byte
//! for byte; `--slurm` writes one job array per study. The smoke tier's samples (150–300
//! monomers) take seconds.

mod common;

use common::exe::dustdem_ok;
use common::Scratch;
use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;

fn reproduce(out: &Path, extra: &[&str]) -> Output {
    let smoke = ["reproduce", "--tier", "smoke", "--jobs", "2", "--out"].map(OsStr::new);
    let extra = extra.iter().map(OsStr::new);
    dustdem_ok(smoke.into_iter().chain([out.as_os_str()]).chain(extra))
}

/// Every file under `dir` with its bytes, by path relative to `dir`.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let path = e.path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                out.insert(path.strip_prefix(dir).unwrap().to_path_buf(), bytes);
            }
        }
    }
    out
}

#[test]
fn the_smoke_tier_stores_its_cases_and_rebuilds_the_report_from_the_store_alone() {
    let scratch = Scratch::new("reproduce");
    let out = scratch.path().join("smoke");
    let runs = scratch.path().join("runs");
    let runs_arg = runs.to_str().unwrap();
    reproduce(&out, &["--runs", runs_arg]);
    let report = std::fs::read_to_string(out.join("REPRODUCTION.md")).expect("report");
    for section in [
        "## Conditions: the paper's and ours",
        "## Verdicts",
        "## Differences of method that remain",
        "## Quasi-static omnidirectional compression",
        "## Dynamic omnidirectional compression",
        "## Omnidirectional compression below 1 m/s",
        "## Unidirectional compression",
    ] {
        assert!(report.contains(section), "no {section:?} in\n{report}");
    }
    // Every claim has a verdict; no Rust debug output anywhere.
    for claim in [
        "| Three regimes at v ≥ 1 m/s",
        "| Compaction front speed v_p",
        "| p_m at 2 m/s (Eq. 15) | 5.41 kPa",
        "| Δ at 5 m/s (Eq. 17) |",
        "| Quasi-static omni, calibrated model",
        "| Unidirectional, unmodified model",
    ] {
        assert!(report.contains(claim), "no {claim:?} in\n{report}");
    }
    for debug in ["Some(", "Ok(", "Err(", "{ ", "Spread"] {
        assert!(
            !report.contains(debug),
            "debug output {debug:?} in\n{report}"
        );
    }
    // Every figure the report links exists.
    for line in report.lines().filter(|l| l.starts_with("![")) {
        let target = &line[line.find("](").unwrap() + 2..line.len() - 1];
        assert!(out.join(target).is_file(), "missing figure {target}");
    }
    // The store holds each finished case: 2 seeds, 2 models, each study's speeds.
    for (study, cases) in [
        ("quasi_static", 4),
        ("dynamic", 8),
        ("slow_dynamic", 4),
        ("uni", 4),
    ] {
        let index = std::fs::read_to_string(out.join(study).join("cases.toml")).unwrap();
        assert_eq!(
            index.matches("[[case]]").count(),
            cases,
            "{study}:\n{index}"
        );
    }
    assert!(
        !out.join("dynamic/runs").exists(),
        "runs went under the store"
    );

    // Again: every case is finished and stored, so nothing runs and nothing changes.
    let before = tree(&out);
    let again = reproduce(&out, &["--runs", runs_arg]);
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(!stderr.contains(" done v"), "a case ran again:\n{stderr}");
    assert_eq!(tree(&out), before);

    // The store alone, copied elsewhere without the runs, rebuilds every byte.
    let copy = scratch.path().join("copy");
    std::fs::create_dir_all(&copy).unwrap();
    for (path, bytes) in &before {
        let keep = path.extension().is_some_and(|x| x == "csv" || x == "toml");
        if keep {
            let target = copy.join(path);
            std::fs::create_dir_all(target.parent().unwrap()).unwrap();
            std::fs::write(target, bytes).unwrap();
        }
    }
    reproduce(&copy, &["--report-only"]);
    assert_eq!(tree(&copy), before);
}

#[test]
fn slurm_mode_writes_one_job_array_per_study_and_runs_nothing() {
    let scratch = Scratch::new("reproduce-slurm");
    let out = scratch.path().join("full");
    let args = ["reproduce", "--tier", "paper", "--slurm", "--out"].map(OsStr::new);
    dustdem_ok(args.into_iter().chain([out.as_os_str()]));
    for (study, cases, sizes) in [
        ("quasi_static", 2 * 6 * 2 * 3, "[2000, 4000, 11000]"),
        ("dynamic", 8 * 6 * 2, "[40000]"),
        ("slow_dynamic", 5 * 6 * 2, "[2000]"),
        ("uni", 6 * 2 * 3, "[2000, 4000, 18000]"),
    ] {
        let script =
            std::fs::read_to_string(out.join(study).join("runs/sweep.sbatch")).expect("job array");
        assert!(
            script.contains(&format!("--array=0-{}", cases - 1)),
            "{study}:\n{script}"
        );
        let sweep = std::fs::read_to_string(out.join(study).join("sweep.toml")).unwrap();
        assert!(sweep.contains(&format!("monomers = {sizes}")), "{sweep}");
        assert!(
            !out.join(study).join("runs/sweep.csv").exists(),
            "{study} ran"
        );
    }
    assert!(!out.join("REPRODUCTION.md").exists());
}

/// The committed tiers rebuild byte for byte from their stores alone (`--report-only` without
/// the runs): what the repository says can be re-derived from what it holds.
#[test]
fn the_committed_tiers_rebuild_byte_for_byte_from_their_stores() {
    for tier in ["paper", "quick"] {
        let committed = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("docs/reproduction")
            .join(tier);
        let scratch = Scratch::new(&format!("reproduce-committed-{tier}"));
        let copy = scratch.join(tier);
        copy_tree(&committed, &copy);
        let args = ["reproduce", "--tier", tier, "--report-only", "--out"].map(OsStr::new);
        dustdem_ok(args.into_iter().chain([copy.as_os_str()]));
        let (before, after) = (tree(&committed), tree(&copy));
        assert_eq!(
            before.keys().collect::<Vec<_>>(),
            after.keys().collect::<Vec<_>>(),
            "{tier}: files"
        );
        for (path, bytes) in &before {
            assert!(after[path] == *bytes, "{tier}: {} differs", path.display());
        }
    }
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}
