//! Calibration end to end on the small test system (configs/calibrate_quick.toml): every effect
//! changes the simulation; data synthesized with a hidden effect (only the data file is handed
//! over) name that effect and recover its factor; data without one name nothing; a single
//! number that two effects explain is reported as a tie; the measured sticking velocity names
//! the damping; bad measured files exit 2 with a message.
//!
//! All calibrations share one run cache and the calibration seeds 1, 2, 3, so the baseline and
//! the screen of every effect are simulated once for the whole file; synthetic data use other
//! seeds (101–103, 201–203, 301–303, 401–403) and added noise.

#[path = "../common/mod.rs"]
mod common;
mod effects_and_synth;
mod hidden_effects;
mod measured_files_and_cli;
#[path = "../common/pair_answer.rs"]
mod pair_answer;
mod paper_dynamic;
mod sticking_damping;

use common::Scratch;
use dustdem::calibrate::measured::Geometry;
use dustdem::calibrate::report::{describe_curve_shrinks, gap_shrink, write_outputs};
use dustdem::calibrate::synth::{synthesize, SynthSpec};
use dustdem::calibrate::{calibrate, Calibration, Effect, MeasuredSet, RunCache, Settings};
use dustdem::config::Config;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

fn base() -> Config {
    Config::load(&repo("configs/calibrate_quick.toml")).unwrap()
}

fn cache() -> &'static RunCache {
    static CACHE: OnceLock<RunCache> = OnceLock::new();
    CACHE.get_or_init(RunCache::new)
}

fn settings() -> Settings {
    search(Settings {
        seeds: vec![1, 2, 3],
        threads: 2,
        max_rounds: 2,
        candidates: 2,
        refinements: 3,
        ..Settings::default()
    })
}

/// The first screen's sample size in every case: half of the test system's 120 monomers.
const FIRST_SCREEN_MONOMERS: usize = 60;

/// The search every case uses: the cheapest (a first screen on 60 of the 120 monomers that only
/// drops effects, then the screen at the upper range end on one seed with common random
/// numbers, effects that cannot come near the best dropped, leaders polished on every seed);
/// with `DUSTDEM_SCREEN_MONOMERS=N` the first screen on N monomers (0: none, the CLI's
/// default); with `DUSTDEM_FULL_SEARCH=1` the search before all savings (no first screen, both
/// range ends, every seed, every effect widened), to measure what they save (the tables in
/// docs/guide/src/calibration.md).
fn search(s: Settings) -> Settings {
    let screen_monomers = match std::env::var("DUSTDEM_SCREEN_MONOMERS") {
        Ok(m) => m.parse().expect("DUSTDEM_SCREEN_MONOMERS: a sample size"),
        Err(_) => FIRST_SCREEN_MONOMERS,
    };
    if std::env::var_os("DUSTDEM_FULL_SEARCH").is_some() {
        Settings {
            screen_seeds: 0,
            screen_monomers: 0,
            prune: false,
            both_ends: true,
            ..s
        }
    } else {
        Settings {
            screen_monomers,
            ..s
        }
    }
}

fn quiet(_: &str) {}

/// The calibration's progress lines on stderr with `DUSTDEM_TEST_PROGRESS=1` (what each step of
/// the search requested), else nothing.
fn progress(line: &str) {
    if std::env::var_os("DUSTDEM_TEST_PROGRESS").is_some() && !line.contains("runs done") {
        eprintln!("{line}");
    }
}

/// Data from the test system with `effect` at `factor`, written to a file and read back: the
/// calibration sees nothing but that file.
fn synthetic(
    name: &str,
    hidden: Option<(Effect, f64)>,
    geometries: &[Geometry],
    seeds: &[u64],
) -> MeasuredSet {
    let config = match hidden {
        Some((e, f)) => e.apply(&base(), f),
        None => base(),
    };
    let spec = SynthSpec {
        geometries: geometries.to_vec(),
        seeds: seeds.to_vec(),
        noise_seed: seeds[0],
        ..SynthSpec::default()
    };
    let set = synthesize(&config, &spec, cache(), 2, &quiet).unwrap();
    let dir = Scratch::new(&format!("calibrate-{name}"));
    let path = dir.join("data.toml");
    std::fs::write(&path, set.to_toml()).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    for e in Effect::ALL {
        assert!(!text.contains(e.name()), "the data file names no effect");
    }
    MeasuredSet::load(&path).unwrap()
}

fn run_calibration(name: &str, measured: &MeasuredSet, settings: &Settings) -> Calibration {
    let start = Instant::now();
    let cal = calibrate(measured, &base(), settings, cache(), &progress).unwrap();
    let before = cal.baseline_gap();
    let after = cal.final_gap();
    eprintln!(
        "{name}: {:.0} s, {} runs requested ({} compressions, {} of them at the screen's size, \
         {} sticking, {:.0} CPU-s); \
         chi2 {:.2} -> {:.2} (threshold {:.2}), normalised shrink {:.0}%; RMS gap shrink of \
         the curves beyond noise: {}",
        start.elapsed().as_secs_f64(),
        cal.runs,
        cal.cost.compressions,
        cal.cost.screen_size_compressions,
        cal.cost.sticking,
        cal.cost.cpu_seconds,
        before.chi2,
        after.chi2,
        after.threshold,
        100.0 * gap_shrink(before, &after),
        describe_curve_shrinks(before, &after)
    );
    for (k, r) in cal.rounds.iter().enumerate() {
        eprintln!("{name}: round {}: {:?}", k + 1, r.decision);
        for f in r.fits.iter().take(4) {
            eprintln!("{name}:   {} held out {:?}", f.summary(), f.held_out);
        }
    }
    // The report, plot and corrected config are written for every case.
    let out = Scratch::new(&format!("calibrate-{name}"));
    let files = write_outputs(&cal, &out, "data.toml", Path::new("base.toml")).unwrap();
    assert!(files.iter().all(|f| f.is_file()));
    cal
}
