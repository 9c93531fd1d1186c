//! `dustdem reproduce`: the smoke tier runs its three sweeps, analyses them and writes
//! REPRODUCTION.md with every study and figure it names; a second call resumes (nothing is
//! run again) and `--report-only` writes the same report; `--slurm` writes one job array per
//! study. The smoke tier's samples (150–300 monomers) take seconds.

mod common;

use common::Scratch;
use std::path::Path;
use std::process::{Command, Output};

fn reproduce(out: &Path, extra: &[&str]) -> Output {
    let output = Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(["reproduce", "--tier", "smoke", "--jobs", "2", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .expect("dustdem runs");
    assert!(
        output.status.success(),
        "reproduce {extra:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// The report without the time this call took, which differs between calls.
fn without_times(report: &str) -> String {
    report
        .lines()
        .map(|l| match (l.find("; "), l.find(" in this call")) {
            (Some(start), Some(end)) if start < end => format!("{}{}", &l[..start], &l[end..]),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn the_smoke_tier_writes_a_report_of_every_study_and_resumes() {
    let scratch = Scratch::new("reproduce");
    let out = scratch.path().join("smoke");
    reproduce(&out, &[]);
    let report = std::fs::read_to_string(out.join("REPRODUCTION.md")).expect("report");
    for section in [
        "## Quasi-static omnidirectional compression",
        "## Dynamic omnidirectional compression",
        "## Unidirectional compression",
        "## What this tier cannot show",
    ] {
        assert!(report.contains(section), "no {section:?} in\n{report}");
    }
    // Both models beside the measured curves, with φ from the runs.
    for reference in [
        "| Güttler et al. 2009 (Eq. 13) | 0.1581 |",
        "| Blum & Schräpler 2004 (Eq. 13) | 0.1509 |",
    ] {
        assert!(report.contains(reference), "no {reference:?}");
    }
    assert_eq!(report.matches("\n| modified | ").count(), 2, "{report}");
    assert_eq!(report.matches("\n| unmodified | ").count(), 2, "{report}");
    // One dynamic row per speed, with the paper's p_m at that speed (5.413 kPa at 2 m/s).
    assert!(report
        .lines()
        .any(|l| l.starts_with("| 2 | 2 |") && l.contains("| 5.413 |")));
    // Every figure the report links exists.
    let mut figures = 0;
    for line in report.lines().filter(|l| l.starts_with("![")) {
        let target = &line[line.find("](").unwrap() + 2..line.len() - 1];
        assert!(out.join(target).is_file(), "missing figure {target}");
        figures += 1;
    }
    // Quasi-static: one curve figure per model; dynamic: curves, p_m(v), Δ(v) and the
    // profiles of each of its two speeds; uni: one per model.
    assert_eq!(figures, 2 + 3 + 2 + 2);
    for study in ["quasi_static", "dynamic", "uni"] {
        assert!(out.join(study).join("runs/analysis.md").is_file());
    }

    // Again: every case is finished, so nothing runs and the numbers are the same.
    let again = reproduce(&out, &[]);
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(!stderr.contains(" done v"), "a case ran again:\n{stderr}");
    let second = std::fs::read_to_string(out.join("REPRODUCTION.md")).unwrap();
    assert_eq!(without_times(&second), without_times(&report));

    reproduce(&out, &["--report-only"]);
    let third = std::fs::read_to_string(out.join("REPRODUCTION.md")).unwrap();
    assert!(third.contains("not timed in this call"));
    // The cases' own times come from their status files, whichever call reports them.
    assert!(third.contains(" s in all ("), "{third}");
    assert_eq!(without_times(&third), without_times(&report));
}

#[test]
fn slurm_mode_writes_one_job_array_per_study_and_runs_nothing() {
    let scratch = Scratch::new("reproduce-slurm");
    let out = scratch.path().join("full");
    let output = Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(["reproduce", "--tier", "full", "--slurm", "--out"])
        .arg(&out)
        .output()
        .expect("dustdem runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for (study, cases, monomers) in [
        ("quasi_static", 2 * 6 * 2, 11_000),
        ("dynamic", 8 * 6, 40_000),
        ("uni", 6 * 2, 18_000),
    ] {
        let script =
            std::fs::read_to_string(out.join(study).join("runs/sweep.sbatch")).expect("job array");
        assert!(
            script.contains(&format!("--array=0-{}", cases - 1)),
            "{study}:\n{script}"
        );
        let sweep = std::fs::read_to_string(out.join(study).join("sweep.toml")).unwrap();
        assert!(
            sweep.contains(&format!("monomers = [{monomers}]")),
            "{sweep}"
        );
        assert!(
            !out.join(study).join("runs/sweep.csv").exists(),
            "{study} ran"
        );
    }
    assert!(!out.join("REPRODUCTION.md").exists());
}
