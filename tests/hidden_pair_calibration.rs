//! Two hidden effects of different kinds, each recovered within 25%: surface energy ×2
//! (a material constant) and side walls ×300 (walls), hidden together in synthetic omni, uni
//! and sticking data of 27 RBD samples of 120 monomers per curve (docs/calibration/hidden_pair/),
//! calibrated on 27 seeds with a first screen on 60 monomers and `--revisit`. On three samples
//! per curve (tests/calibrate) the side walls, which only the omni curve carries, come back
//! only inside their wide interval; that case's revisit, committed beside it, replaces
//! nothing.
//!
//! The calibration is rebuilt from its committed run cache (`--cache-only`: a run the cache
//! lacks is an error, never simulated), byte for byte, so a change to the search, the fits,
//! the decisions or the report that would change this answer fails here; its answer is then
//! checked against the hidden factors, which are written nowhere in the data file.

mod common;

use common::Scratch;
use dustdem::calibrate::{calibrate, Calibration, Effect, MeasuredSet, RunCache, Settings};
use dustdem::config::Config;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

const DIR: &str = "docs/calibration/hidden_pair";
const CONFIG: &str = "configs/calibrate_quick.toml";

/// The committed calibrations: measured file and output directory under `DIR`, and seeds.
const CASES: [(&str, &str, u64); 2] = [
    (
        "measured_surface_energy_side_walls.toml",
        "surface_energy_side_walls",
        27,
    ),
    ("measured_damping_side_walls.toml", "damping_side_walls", 3),
];

fn seeds(n: u64) -> String {
    (1..=n).map(|s| s.to_string()).collect::<Vec<_>>().join(",")
}

#[test]
fn the_committed_hidden_pair_calibrations_rebuild_from_their_run_cache() {
    let scratch = Scratch::new("hidden-pair");
    for (measured, dir, n) in CASES {
        let out = scratch.join(dir);
        let result = Command::new(env!("CARGO_BIN_EXE_dustdem"))
            .current_dir(repo(""))
            .args(["calibrate", "--measured", &format!("{DIR}/{measured}")])
            .args([
                "--config",
                CONFIG,
                "--seeds",
                &seeds(n),
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
            "{dir}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
        let committed = repo(DIR).join(dir);
        let compared = common::assert_rebuilt_as_committed(&out, &committed, dir);
        assert!(compared >= 4, "{dir}: {compared} files");
    }
}

/// Case `k` of `CASES` calibrated through the library from the committed run cache.
fn calibrated(k: usize) -> Calibration {
    let (measured, _, n) = CASES[k];
    let measured = MeasuredSet::load(&repo(&format!("{DIR}/{measured}"))).unwrap();
    let base = Config::load(&repo(CONFIG)).unwrap();
    let settings = Settings {
        seeds: (1..=n).collect(),
        screen_monomers: 60,
        revisit: true,
        threads: 2,
        ..Settings::default()
    };
    let cache = RunCache::read_only(&repo(&format!("{DIR}/run_cache")));
    calibrate(&measured, &base, &settings, &cache, &|_| {}).unwrap()
}

/// Surface energy ×2 and side walls ×300 on 27 samples per curve.
#[test]
fn both_hidden_effects_come_back_within_25_percent_after_the_revisit() {
    let cal = calibrated(0);
    let hidden = [
        (Effect::SurfaceEnergy, 2.0),
        (Effect::SideWallStrength, 300.0),
    ];
    assert_eq!(cal.applied.len(), 2, "{:?}", cal.applied);
    for (effect, hidden) in hidden {
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
    // again with them in, it moved toward the hidden factor and replaced the first fit, so
    // the side walls were searched for again too.
    assert_eq!(cal.applied[0].0, Effect::SurfaceEnergy);
    let first = cal.rounds[0].applied.expect("round 1 applied an effect");
    let revisit = &cal.revisits[0];
    assert!(revisit.replaced && revisit.was == first, "{revisit:?}");
    assert!((cal.applied[0].1 - 2.0).abs() < (first.1 - 2.0).abs());
    assert_eq!(cal.revisits.len(), 2);
    // Each revisit ran with the others as they stood then: the first with round 2's side
    // walls, the second with the revisited surface energy.
    assert_eq!(revisit.with, vec![cal.rounds[1].applied.unwrap()]);
    assert_eq!(cal.revisits[1].with, vec![cal.applied[0]]);
}

/// Damping ×2 and side walls ×300 on three samples per curve (the data of tests/calibrate's
/// two-effect case): the revisit finds the damping again at the same factor, the model it
/// re-simulates is the one it has (the same χ², not lower), so nothing is replaced and the
/// side walls are not searched for again.
#[test]
fn a_revisit_that_finds_the_same_fit_replaces_nothing() {
    let cal = calibrated(1);
    assert_eq!(cal.revisits.len(), 1, "{:?}", cal.revisits);
    let revisit = &cal.revisits[0];
    assert_eq!(revisit.round.decision.chosen(), Some(Effect::NormalDamping));
    assert_eq!(revisit.round.applied, Some(revisit.was));
    assert!(!revisit.replaced);
    assert_eq!(cal.applied[0], revisit.was);
    let after = revisit.round.gap_after.as_ref().unwrap();
    assert_eq!(after.chi2, revisit.chi2_before);
}
