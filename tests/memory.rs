//! The CPU engine's memory per monomer, as the user guide states it (about 1.6 kB per monomer
//! with the default 12 pair and 3 wall slots, `docs/guide/src/benchmarks.md`), held against
//! what the operating system reports for a run of 10⁵ monomers: the process's peak resident
//! memory, which `dustdem run` prints with the engine's own count of its arrays.

mod common;

use common::Scratch;
use std::process::Command;

/// The guide's figure [B per monomer].
const STATED_BYTES_PER_MONOMER: f64 = 1600.0;
const N: f64 = 100_000.0;
const MIB: f64 = 1048576.0;

/// The MiB after `label` in the run's memory line.
fn mib_after(line: &str, label: &str) -> f64 {
    let rest = &line[line
        .find(label)
        .unwrap_or_else(|| panic!("{label}: {line}"))
        + label.len()..];
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn a_run_of_1e5_monomers_holds_the_stated_memory_per_monomer() {
    let dir = Scratch::new("memory");
    let config = dir.join("run.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 100000\nseed = 3\n[experiment]\nkind = \"omni\"\n\
         wall_speed_m_s = 0.5\nmax_steps = 200\n[output]\nsnapshot_format = \"none\"\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(["run", "--backend", "cpu", "--force", "--out"])
        .arg(dir.join("run"))
        .arg(&config)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = stdout
        .lines()
        .find(|l| l.starts_with("memory:"))
        .unwrap_or_else(|| panic!("no memory line: {stdout}"));
    let stated = STATED_BYTES_PER_MONOMER * N / MIB;
    let (arrays, peak) = (
        mib_after(line, "engine arrays "),
        mib_after(line, "peak resident "),
    );
    eprintln!("{line} (stated {stated:.1} MiB)");
    // Measured on a 2-core AMD EPYC: arrays 145.0 MiB, peak 157.2 MiB (the program itself
    // about 9 MiB of it).
    assert!(
        (peak / stated - 1.0).abs() < 0.2,
        "{line}: stated {stated:.1} MiB"
    );
    assert!(
        (arrays / stated - 1.0).abs() < 0.2,
        "{line}: stated {stated:.1} MiB"
    );
}
