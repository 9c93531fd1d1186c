//! Two hidden effects of different kinds, each recovered within 25%: surface energy ×2
//! (a material constant) and side walls ×300 (walls), hidden together in synthetic omni, uni
//! and sticking data of 27 RBD samples of 120 monomers per curve (docs/calibration/hidden_pair/),
//! calibrated on 27 seeds with a first screen on 60 monomers and `--revisit`. On three samples
//! per curve (tests/calibrate) the side walls, which only the omni curve carries, come back
//! only inside their wide interval.
//!
//! The calibration is rebuilt from its committed run cache (`--cache-only`: a run the cache
//! lacks is an error, never simulated), byte for byte, so a change to the search, the fits,
//! the decisions or the report that would change this answer fails here; its answer is then
//! checked against the hidden factors, which are written nowhere in the data file.

mod common;

use common::Scratch;
use dustdem::calibrate::{calibrate, Effect, MeasuredSet, RunCache, Settings};
use dustdem::config::Config;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

const DIR: &str = "docs/calibration/hidden_pair";
const CONFIG: &str = "configs/calibrate_quick.toml";
/// What `dustdem synth` hid in the data (the command is in the directory's README).
const HIDDEN: [(Effect, f64); 2] = [
    (Effect::SurfaceEnergy, 2.0),
    (Effect::SideWallStrength, 300.0),
];

fn seeds() -> String {
    (1..=27)
        .map(|s| s.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

#[test]
fn the_committed_hidden_pair_calibration_rebuilds_from_its_run_cache() {
    let scratch = Scratch::new("hidden-pair");
    let out = scratch.join("calibration");
    let result = Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .current_dir(repo(""))
        .args(["calibrate", "--measured", &format!("{DIR}/measured.toml")])
        .args([
            "--config",
            CONFIG,
            "--seeds",
            &seeds(),
            "--screen-monomers",
            "60",
        ])
        .args(["--revisit", "--threads", "2", "--cache-only", "--cache"])
        .arg(repo(&format!("{DIR}/run_cache")))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let committed = repo(DIR).join("calibration");
    let mut compared = 0;
    for entry in std::fs::read_dir(&out).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let old = std::fs::read(committed.join(&name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            std::fs::read(&path).unwrap() == old,
            "{name} differs from its rebuild from the run cache"
        );
        compared += 1;
    }
    assert!(compared >= 4, "{compared} files");
}

#[test]
fn both_hidden_effects_come_back_within_25_percent_after_the_revisit() {
    let measured = MeasuredSet::load(&repo(&format!("{DIR}/measured.toml"))).unwrap();
    let base = Config::load(&repo(CONFIG)).unwrap();
    let settings = Settings {
        seeds: (1..=27).collect(),
        screen_monomers: 60,
        revisit: true,
        threads: 2,
        ..Settings::default()
    };
    let cache = RunCache::read_only(&repo(&format!("{DIR}/run_cache")));
    let cal = calibrate(&measured, &base, &settings, &cache, &|_| {}).unwrap();
    assert_eq!(cal.applied.len(), 2, "{:?}", cal.applied);
    for (effect, hidden) in HIDDEN {
        let (_, factor) = cal
            .applied
            .iter()
            .find(|(e, _)| *e == effect)
            .unwrap_or_else(|| panic!("{} not applied: {:?}", effect.name(), cal.applied));
        assert!(
            (factor / hidden - 1.0).abs() <= 0.25,
            "{} x{factor}, hidden x{hidden}",
            effect.name()
        );
    }
    assert!(cal.final_gap().within_noise());
    // The first round fitted the surface energy with the side walls missing; searched for
    // again with them in, it moved toward the hidden factor and replaced the first fit.
    assert_eq!(cal.applied[0].0, Effect::SurfaceEnergy);
    let first = cal.rounds[0].applied.expect("round 1 applied an effect");
    let revisit = &cal.revisits[0];
    assert!(revisit.replaced && revisit.was == first, "{revisit:?}");
    assert!((cal.applied[0].1 - 2.0).abs() < (first.1 - 2.0).abs());
}
