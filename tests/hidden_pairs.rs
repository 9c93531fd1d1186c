//! Four pairs of hidden effects of different kinds, each in synthetic omni, uni and sticking
//! data of three 120-monomer samples per curve (docs/calibration/hidden_pairs/, made by its
//! `make.sh`), calibrated on three other seeds with a first screen on 60 monomers. The
//! calibrations are rebuilt from their committed run cache (`--cache-only`), byte for byte,
//! and their answers checked against the hidden factors, which the data files do not hold:
//!
//! | hidden | answer (measured) |
//! |---|---|
//! | rolling stiffness ×4 + normal damping ×2 | undetermined: damping (other form) + ξ_crit, damping (other form) + rolling stiffness |
//! | surface energy ×0.75 + twisting ×6 | undetermined: normal damping, monomer radius |
//! | side walls ×300 + surface energy ×1.5 | surface energy named, ×1.452 |
//! | ξ_crit ×4 + normal damping ×0.5 | normal damping named, ×0.527 |
//!
//! What holds for all four, and is tested: no effect that was not hidden is named, and an
//! effect named alone comes back with its hidden factor inside its interval. Only the first
//! case has the hidden pair among its candidates; in the third and fourth the second effect,
//! though above its detection limit alone, improves χ² by less than the tie threshold next to
//! the first (Δχ² 1.0 and 1.8 with it held at its limit), and in the second neither hidden
//! effect is among the candidates: three samples per curve do not resolve these pairs.

mod common;
#[path = "common/pair_answer.rs"]
mod pair_answer;

use common::Scratch;
use dustdem::calibrate::attribution::Decision;
use dustdem::calibrate::{calibrate, Calibration, Effect, MeasuredSet, RunCache, Settings};
use dustdem::config::Config;
use std::path::{Path, PathBuf};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

const DIR: &str = "docs/calibration/hidden_pairs";
const CONFIG: &str = "configs/calibrate_quick.toml";

/// The cases: output directory (and measured file `measured_<dir>.toml`) and the hidden pair.
const CASES: [(&str, [(Effect, f64); 2]); 4] = [
    (
        "rolling_stiffness-4_normal_damping-2",
        [
            (Effect::RollingStiffness, 4.0),
            (Effect::NormalDamping, 2.0),
        ],
    ),
    (
        "surface_energy-0.75_twisting_stiffness-6",
        [
            (Effect::SurfaceEnergy, 0.75),
            (Effect::TwistingStiffness, 6.0),
        ],
    ),
    (
        "side_wall_strength-300_surface_energy-1.5",
        [
            (Effect::SideWallStrength, 300.0),
            (Effect::SurfaceEnergy, 1.5),
        ],
    ),
    (
        "critical_rolling_length-4_normal_damping-0.5",
        [
            (Effect::CriticalRollingLength, 4.0),
            (Effect::NormalDamping, 0.5),
        ],
    ),
];

fn measured(dir: &str) -> String {
    format!("{DIR}/measured_{dir}.toml")
}

#[test]
fn the_hidden_pair_calibrations_rebuild_from_their_run_cache() {
    let scratch = Scratch::new("hidden-pairs");
    for (dir, _) in CASES {
        let measured = measured(dir);
        common::assert_calibration_rebuilds(
            &[
                "--measured",
                &measured,
                "--config",
                CONFIG,
                "--seeds",
                "1,2,3",
                "--screen-monomers",
                "60",
                "--threads",
                "2",
            ],
            &repo(&format!("{DIR}/run_cache")),
            &scratch.join(dir),
            &repo(DIR).join(dir),
        );
    }
}

fn calibrated(dir: &str) -> Calibration {
    let m = MeasuredSet::load(&repo(&measured(dir))).unwrap();
    let base = Config::load(&repo(CONFIG)).unwrap();
    let settings = Settings {
        seeds: vec![1, 2, 3],
        screen_monomers: 60,
        threads: 2,
        ..Settings::default()
    };
    let cache = RunCache::read_only(&repo(&format!("{DIR}/run_cache")));
    calibrate(&m, &base, &settings, &cache, &|_| {}).unwrap()
}

/// A named effect (alone or in a pair) is one of the hidden ones (by family: the damping's
/// two forms are one effect), and one named alone has its hidden factor inside its interval.
fn assert_no_wrong_name(dir: &str, cal: &Calibration, hidden: [(Effect, f64); 2]) {
    let hidden_family = |e: Effect| hidden.iter().find(|(h, _)| h.family() == e.family());
    for round in &cal.rounds {
        match &round.decision {
            Decision::Named(e) | Decision::Unpredictive { effect: e, .. } => {
                let (h, f) = hidden_family(*e).unwrap_or_else(|| panic!("{dir}: named {e:?}"));
                let fit = round.fits.iter().find(|x| x.effect == *e).unwrap();
                let inside = fit.interval.0 <= *f && *f <= fit.interval.1;
                assert!(h != e || inside, "{dir}: {} outside {:?}", f, fit.interval);
            }
            Decision::NamedPair(p) => {
                for e in p {
                    assert!(hidden_family(*e).is_some(), "{dir}: named pair {p:?}");
                }
            }
            Decision::Undetermined { .. } => {
                let d = round.discrimination.as_ref().expect("a proposal");
                assert!(d
                    .proposals
                    .windows(2)
                    .all(|w| w[0].separation >= w[1].separation));
            }
            Decision::WithinNoise | Decision::NoEffectExplains => {}
        }
    }
}

#[test]
fn no_hidden_pair_is_answered_by_an_effect_that_was_not_hidden() {
    for (dir, hidden) in CASES {
        let cal = calibrated(dir);
        let answer = pair_answer::pair_answer(&cal, hidden);
        eprintln!("{dir}: {answer:?}");
        assert_no_wrong_name(dir, &cal, hidden);
        if dir.starts_with("rolling_stiffness") {
            assert!(answer.is_ok(), "{dir}: {answer:?}");
        }
    }
}
