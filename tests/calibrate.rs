//! Calibration end to end on the small test system (configs/calibrate_quick.toml): every effect
//! changes the simulation; data synthesized with a hidden effect (only the data file is handed
//! over) name that effect and recover its factor; data without one name nothing; a single
//! number that two effects explain is reported as a tie; the measured sticking velocity names
//! the damping; bad measured files exit 2 with a message.
//!
//! All calibrations share one run cache and the calibration seeds 1, 2, 3, so the baseline and
//! the screen of every effect are simulated once for the whole file; synthetic data use other
//! seeds (101–103, 201–203, 301–303, 401–403) and added noise.

mod common;

use common::Scratch;
use dustdem::calibrate::attribution::Decision;
use dustdem::calibrate::gap::chi2_quantile_95;
use dustdem::calibrate::measured::Geometry;
use dustdem::calibrate::report::{
    curve_shrinks, describe_curve_shrinks, gap_shrink, write_outputs,
};
use dustdem::calibrate::simulate::{compression_config, run_all, sticking_config, Output, Run};
use dustdem::calibrate::synth::{synthesize, SynthSpec};
use dustdem::calibrate::{calibrate, Calibration, Effect, MeasuredSet, RunCache, Settings};
use dustdem::config::Config;
use std::path::{Path, PathBuf};
use std::process::Command;
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

/// The search every case uses: the default (screen at the upper range end on one seed with
/// common random numbers, effects that cannot come near the best dropped), or with
/// `DUSTDEM_FULL_SEARCH=1` the search before those savings (both range ends, every seed, every
/// effect widened), to measure what they save (the table in docs/guide/src/calibration.md).
fn search(s: Settings) -> Settings {
    if std::env::var_os("DUSTDEM_FULL_SEARCH").is_some() {
        Settings {
            screen_seeds: 0,
            prune: false,
            both_ends: true,
            ..s
        }
    } else {
        s
    }
}

fn quiet(_: &str) {}

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
    let cal = calibrate(measured, &base(), settings, cache(), &quiet).unwrap();
    let before = cal.baseline_gap();
    let after = cal.final_gap();
    eprintln!(
        "{name}: {:.0} s, {} runs requested ({} compressions, {} sticking, {:.0} CPU-s); \
         chi2 {:.2} -> {:.2} (threshold {:.2}), normalised shrink {:.0}%; RMS gap shrink of \
         the curves beyond noise: {}",
        start.elapsed().as_secs_f64(),
        cal.runs,
        cal.cost.compressions,
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

/// The hidden effect is named alone in the first round and its factor recovered: within 25%,
/// or inside the fit's own interval (Δχ² = 1) where the data pin the factor less tightly than
/// that. Every curve that was beyond noise at the baseline is explained: its RMS gap shrinks by
/// at least 70%, or the corrected curve is within noise on its own (χ² below the 95% limit of
/// one degree of freedom) — a curve whose noise floor is more than 30% of its baseline gap
/// cannot shrink by 70%. The corrected model fits the whole data set (controls included)
/// within noise.
///
/// Measured with 120-monomer samples at 0.3 ns: side walls ×300 came out ×431.5 with the
/// interval [272, 861] (the omni curve alone carries it: wall factors of 1e-3 × 300 change the
/// curve weakly); surface energy's omni gap went 0.0319 → 0.0098 against a floor of 0.0096.
fn assert_recovered(cal: &Calibration, effect: Effect, factor: f64) {
    let first = &cal.rounds[0];
    assert_eq!(first.decision, Decision::Named(effect));
    // Consistency with the detection limits: a change that was named lies beyond them.
    let limit = first
        .detection
        .iter()
        .find(|d| d.effect == effect)
        .expect("a detection limit per effect");
    eprintln!(
        "{}: detection limits {:?} / {:?}",
        effect.name(),
        limit.lower,
        limit.upper
    );
    assert!(!limit.hides(factor), "{limit:?} hides x{factor}");
    let (applied, recovered) = cal.applied[0];
    assert_eq!(applied, effect);
    let fit = first
        .fits
        .iter()
        .find(|f| f.effect == effect)
        .expect("the named effect was fitted");
    let inside = fit.interval.0 <= factor && factor <= fit.interval.1;
    assert!(
        (recovered / factor - 1.0).abs() <= 0.25 || inside,
        "{} recovered x{recovered:.3} {:?}, hidden x{factor}",
        effect.name(),
        fit.interval
    );
    let limit = chi2_quantile_95(1);
    let after = cal.final_gap();
    let shrinks = curve_shrinks(cal.baseline_gap(), &after);
    assert!(
        !shrinks.is_empty(),
        "the hidden effect put a curve beyond noise"
    );
    for c in &shrinks {
        let corrected = after.curves.iter().find(|g| g.name == c.name).unwrap();
        assert!(
            c.shrink() >= 0.7 || corrected.chi2 <= limit,
            "{}: RMS gap {:.4} -> {:.4} (noise {:.4}, chi2 {:.2})",
            c.name,
            c.rms_before,
            c.rms_after,
            corrected.noise,
            corrected.chi2
        );
    }
    assert!(cal.final_gap().within_noise());
}

#[test]
fn every_effect_changes_the_simulation() {
    // A tiny compression (60 monomers, fast wall) and the sticking run, at the top of each
    // effect's range against the baseline: at least one of them must differ.
    let mut small = base();
    small.sample.monomers = 60;
    small.experiment.wall_speed_m_s = 2.0;
    let runs_of = |c: &Config| {
        vec![
            Run::Compression(compression_config(c, Geometry::Omni, 7, 1e4)),
            Run::Sticking(sticking_config(c)),
        ]
    };
    let mut runs = runs_of(&small);
    for e in Effect::ALL {
        runs.extend(runs_of(&e.apply(&small, e.range().1)));
    }
    let out = run_all(&runs, cache(), 2, &|_, _| {});
    let out: Vec<Output> = out.into_iter().map(|o| o.unwrap()).collect();
    for (k, e) in Effect::ALL.iter().enumerate() {
        let (comp, stick) = (&out[2 + 2 * k], &out[3 + 2 * k]);
        let compression_changed = comp != &out[0];
        let sticking_changed = stick != &out[1];
        eprintln!(
            "{:<24} compression changed {compression_changed}, sticking {:?} -> {:?}",
            e.name(),
            out[1],
            stick
        );
        assert!(compression_changed || sticking_changed, "{}", e.name());
        // Contact stiffness and strength reach the compression; damping and the material the
        // two-monomer collision.
        match e {
            Effect::NormalDamping | Effect::SurfaceEnergy | Effect::YoungsModulus => {
                assert!(sticking_changed, "{}", e.name())
            }
            _ => assert!(compression_changed, "{}", e.name()),
        }
    }
}

#[test]
fn hidden_side_wall_strength_is_named_from_omni_uni_and_sticking() {
    // Omni alone cannot tell stronger side walls from stronger rolling; the uni curve (no side
    // walls) can. The uni curve and the sticking velocity stay within noise here: they are the
    // controls, so the data set's normalised shrink (which counts their noise) stays near 55%
    // while the omni curve's RMS gap shrinks by 85%.
    let hidden = (Effect::SideWallStrength, 300.0);
    let m = synthetic(
        "walls",
        Some(hidden),
        &[Geometry::Omni, Geometry::Uni],
        &[101, 102, 103],
    );
    let cal = run_calibration("walls", &m, &settings());
    assert_recovered(&cal, hidden.0, hidden.1);
}

#[test]
fn hidden_damping_is_named_from_omni_uni_and_sticking() {
    let hidden = (Effect::NormalDamping, 2.0);
    let m = synthetic(
        "damping",
        Some(hidden),
        &[Geometry::Omni, Geometry::Uni],
        &[101, 102, 103],
    );
    let cal = run_calibration("damping", &m, &settings());
    assert_recovered(&cal, hidden.0, hidden.1);
}

#[test]
fn hidden_surface_energy_is_named_from_omni_uni_and_sticking() {
    // Surface energy moves the omni curve by only a few times its noise floor, and a curve can
    // show a 70% shrink of its RMS gap only if its baseline gap is at least 1/0.3 of that floor:
    // x1.6 with three seeds gave 0.034 against 0.012 (68%; six seeds lowered the floor to
    // 0.0096 at twice the cost). x2.0, 40 mJ/m2, inside the measured 10-50 mJ/m2, moves it
    // further with the three seeds every other case uses.
    let hidden = (Effect::SurfaceEnergy, 2.0);
    let m = synthetic(
        "gamma",
        Some(hidden),
        &[Geometry::Omni, Geometry::Uni],
        &[101, 102, 103],
    );
    let cal = run_calibration("gamma", &m, &settings());
    assert_recovered(&cal, hidden.0, hidden.1);
}

#[test]
fn data_without_a_hidden_effect_name_no_effect() {
    let m = synthetic(
        "null",
        None,
        &[Geometry::Omni, Geometry::Uni],
        &[201, 202, 203],
    );
    let cal = run_calibration("null", &m, &settings());
    assert_eq!(cal.rounds[0].decision, Decision::WithinNoise);
    assert!(cal.applied.is_empty() && cal.named().is_empty());
}

#[test]
fn one_sticking_velocity_cannot_tell_damping_from_surface_energy() {
    // A single number, reachable by stronger damping and by stickier surfaces alike: the
    // calibration must say that both explain it rather than pick one.
    let m = synthetic("tie", Some((Effect::NormalDamping, 1.5)), &[], &[101]);
    let cal = run_calibration("tie", &m, &settings());
    match &cal.rounds[0].decision {
        Decision::Undetermined(tied) => {
            assert!(tied.contains(&Effect::NormalDamping), "{tied:?}");
            assert!(tied.contains(&Effect::SurfaceEnergy), "{tied:?}");
        }
        other => panic!("expected a tie, got {other:?}"),
    }
    assert!(cal.named().is_empty());
}

#[test]
fn measured_sticking_velocity_names_damping_and_reaches_it() {
    let m = MeasuredSet::load(&repo("configs/measured/poppe2000_sticking.toml")).unwrap();
    let s = Settings {
        refinements: 6,
        refine_tolerance: 0.01,
        candidates: 3,
        ..settings()
    };
    let cal = run_calibration("poppe", &m, &s);
    assert_eq!(cal.named(), vec![Effect::NormalDamping]);
    let v = match cal.final_predictions[0] {
        dustdem::calibrate::gap::Prediction::Sticking { velocity, .. } => velocity,
        _ => unreachable!(),
    };
    eprintln!("poppe: corrected sticking velocity {v:.4} m/s");
    assert!((v / 1.2 - 1.0).abs() <= 0.1, "{v} m/s");
}

#[test]
fn a_change_below_the_detection_limit_passes_as_noise_and_the_limit_says_so() {
    // Rolling stiffness x1.5: the plan of this data set (omni + uni + sticking, three seeds
    // each side, 120 monomers) puts rolling's upper limit at x2.2, so x1.5 must pass as noise
    // and the reported limit must lie above it.
    let hidden = (Effect::RollingStiffness, 1.5);
    let m = synthetic(
        "below",
        Some(hidden),
        &[Geometry::Omni, Geometry::Uni],
        &[301, 302, 303],
    );
    let cal = run_calibration("below", &m, &settings());
    assert_eq!(cal.rounds[0].decision, Decision::WithinNoise);
    let limit = cal.rounds[0]
        .detection
        .iter()
        .find(|d| d.effect == hidden.0)
        .unwrap();
    eprintln!(
        "below: rolling limits {:?} / {:?}",
        limit.lower, limit.upper
    );
    assert!(limit.hides(hidden.1), "{limit:?}");
    // Every effect has its limits in the report, under the heading for data that named nothing.
    let out = Scratch::new("calibrate-below-report");
    write_outputs(&cal, &out, "data.toml", Path::new("base.toml")).unwrap();
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("## What these data could not have seen"),
        "{md}"
    );
    for e in Effect::ALL.iter().filter(|e| e.identity_at_one()) {
        assert!(md.contains(&format!("| {} |", e.name())), "{}", e.name());
    }
}

/// Omni and uni data at the given wall speeds (the config says 0.5 m/s), sticking included,
/// with the speeds removed from the file: the wall speed is not in the library.
fn data_at_wall_speeds(omni: f64, uni: f64) -> MeasuredSet {
    let curve = |geometry: Geometry, speed: f64, sticking: bool, noise_seed: u64| {
        let mut c = base();
        c.experiment.wall_speed_m_s = speed;
        let spec = SynthSpec {
            geometries: vec![geometry],
            sticking,
            seeds: vec![401, 402, 403],
            noise_seed,
            ..SynthSpec::default()
        };
        synthesize(&c, &spec, cache(), 2, &quiet).unwrap()
    };
    let mut m = MeasuredSet::merge(vec![
        curve(Geometry::Omni, omni, false, 401),
        curve(Geometry::Uni, uni, true, 402),
    ]);
    for c in &mut m.compression {
        c.wall_speed = None;
    }
    m
}

#[test]
fn data_with_one_curve_at_another_wall_speed_are_not_explained_by_a_library_effect() {
    // Only the uni curve was compressed at 2.5 m/s (two experiments, two speeds; the config
    // and the omni curve at 0.5 m/s). With both curves at 2.5 m/s
    // (docs/guide/src/calibration.md, "Test system and results") the data cannot tell the faster wall from stiffer rolling: that case ends
    // undetermined between rolling_stiffness x9.5 and critical_rolling_length x12.3, each
    // predicting every curve. No library effect stiffens the uni curve and leaves the
    // omni curve alone, so whatever fits jointly must fail to predict one of them, or nothing
    // lowers chi2 enough to be named.
    // One round: the decision under test is the first one (a second round, measured once, names
    // nothing more: docs/guide/src/calibration.md, "Test system and results").
    let m = data_at_wall_speeds(0.5, 2.5);
    let one_round = Settings {
        max_rounds: 1,
        ..settings()
    };
    let cal = run_calibration("uni-speed", &m, &one_round);
    let first = &cal.rounds[0];
    assert!(
        !first.gap_before.within_noise(),
        "the speed changed the uni curve"
    );
    match &first.decision {
        Decision::NoEffectExplains | Decision::Unpredictive { .. } => {}
        other => panic!("a library effect claimed to explain another wall speed: {other:?}"),
    }
}

#[test]
fn two_hidden_effects_of_different_kinds_are_named_in_two_rounds() {
    // Stronger side walls (walls) and stronger damping (dissipation) together: round 1 names
    // the damping (its failed prediction of the omni curve shown: the side walls are still
    // missing), round 2 the side walls. The damping comes back within 25%; the side walls,
    // which only the omni curve's three 120-monomer samples carry, within 25% or inside the
    // fit's own interval (measured: x442 with the interval 122-596, as in the single-effect
    // case where x300 came back as x269 [124, 417]).
    let hidden = [
        (Effect::NormalDamping, 2.0),
        (Effect::SideWallStrength, 300.0),
    ];
    let config = hidden.iter().fold(base(), |c, (e, f)| e.apply(&c, *f));
    let spec = SynthSpec {
        geometries: vec![Geometry::Omni, Geometry::Uni],
        seeds: vec![101, 102, 103],
        noise_seed: 101,
        ..SynthSpec::default()
    };
    let m = synthesize(&config, &spec, cache(), 2, &quiet).unwrap();
    let cal = run_calibration("two", &m, &settings());
    let order: Vec<Effect> = cal.applied.iter().map(|(e, _)| *e).collect();
    assert_eq!(order, vec![hidden[0].0, hidden[1].0], "{:?}", cal.applied);
    let (damping, walls) = (cal.applied[0].1, cal.applied[1].1);
    assert!(
        (damping / hidden[0].1 - 1.0).abs() <= 0.25,
        "damping x{damping}"
    );
    let fit = cal.rounds[1]
        .fits
        .iter()
        .find(|f| f.effect == hidden[1].0)
        .unwrap();
    assert!(
        (walls / hidden[1].1 - 1.0).abs() <= 0.25
            || (fit.interval.0 <= hidden[1].1 && hidden[1].1 <= fit.interval.1),
        "side walls x{walls} {:?}",
        fit.interval
    );
    assert!(matches!(
        cal.rounds[0].decision,
        Decision::Unpredictive { .. } | Decision::Named(_)
    ));
    assert_eq!(cal.rounds[1].decision, Decision::Named(hidden[1].0));
    assert!(cal.final_gap().within_noise());
}

/// The paper's unmodified damping, viscous κ = 1e-6 g/s, on the test system.
fn paper_damping() -> Config {
    let mut paper = base();
    paper.model.damping = dustdem::model::Damping::Viscous { kappa: 1e-6 };
    paper
}

#[test]
fn a_factor_beyond_the_default_range_is_found_by_widening() {
    // Viscous damping x100 is 25 times the default range's end (x4); the sticking velocity
    // alone carries it (the damping in its own form is the only effect searched, so nothing
    // else competes). Viscous, not viscoelastic: from T_vis = 1.25e-11 s a few times more
    // already overdamps head-on collisions at every speed below the 30 m/s search cap, so
    // larger factors all give the cap and cannot be told apart.
    let hidden = (Effect::NormalDamping, 100.0);
    let data_config = hidden.0.apply(&paper_damping(), hidden.1);
    let spec = SynthSpec {
        geometries: Vec::new(),
        seeds: vec![101],
        noise_seed: 101,
        ..SynthSpec::default()
    };
    let m = synthesize(&data_config, &spec, cache(), 2, &quiet).unwrap();
    let s = Settings {
        effects: vec![Effect::NormalDamping],
        ..settings()
    };
    let cal = calibrate(&m, &paper_damping(), &s, cache(), &quiet).unwrap();
    let fit = &cal.rounds[0].fits[0];
    eprintln!("wide: {}", fit.summary());
    assert_eq!(cal.named(), vec![hidden.0]);
    assert!(fit.bound.is_none(), "interior after widening: {fit:?}");
    assert!(
        fit.grid_factors.iter().any(|&f| f > 4.0),
        "{:?}",
        fit.grid_factors
    );
    let (_, recovered) = cal.applied[0];
    assert!((recovered / hidden.1 - 1.0).abs() <= 0.25, "x{recovered}");
}

#[test]
fn poppe_from_the_papers_viscous_model_needs_a_damping_far_beyond_the_screen() {
    // From kappa = 1e-6 g/s (JKR sticking at 0.11 m/s) to Poppe et al.'s 1.2 m/s: both damping
    // forms reach it after widening, the config's viscous form is kept, and the report says
    // which form and value.
    let paper = paper_damping();
    let m = MeasuredSet::load(&repo("configs/measured/poppe2000_sticking.toml")).unwrap();
    let s = Settings {
        effects: vec![
            Effect::NormalDamping,
            Effect::DampingForm,
            Effect::SurfaceEnergy,
        ],
        ..settings()
    };
    let cal = calibrate(&m, &paper, &s, cache(), &quiet).unwrap();
    let first = &cal.rounds[0];
    for f in &first.fits {
        eprintln!("poppe-kappa: {}", f.summary());
    }
    assert_eq!(first.decision, Decision::Named(Effect::NormalDamping));
    let form = first
        .fits
        .iter()
        .find(|f| f.effect == Effect::DampingForm)
        .unwrap();
    assert!(
        form.bound.is_none() && form.chi2 < 1.0,
        "{}",
        form.summary()
    );
    // Surface energy stops at its limit (x2.5, 50 mJ/m2) short of 1.2 m/s: a bound.
    let gamma = first
        .fits
        .iter()
        .find(|f| f.effect == Effect::SurfaceEnergy)
        .unwrap();
    assert!(gamma
        .bound
        .as_ref()
        .is_some_and(|b| b.upper && b.limit.is_some()));
    let (_, kappa_factor) = cal.applied[0];
    assert!(kappa_factor > 100.0, "x{kappa_factor}");
    let out = Scratch::new("calibrate-poppe-kappa");
    write_outputs(&cal, &out, "poppe", Path::new("paper.toml")).unwrap();
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("Damping: chose the config's own form, kappa ="),
        "{md}"
    );
    assert!(md.contains("rests on one observable"), "{md}");
}

#[test]
fn synth_clips_a_curve_to_the_pressures_reached() {
    // A 60-monomer sample at 2 m/s asked for 1e9 Pa: the curve is clipped with a warning.
    let mut small = base();
    small.sample.monomers = 60;
    small.experiment.wall_speed_m_s = 2.0;
    let spec = SynthSpec {
        sticking: false,
        seeds: vec![7],
        pressure_range: (1e2, 1e9),
        points: 15,
        ..SynthSpec::default()
    };
    let warnings = std::sync::Mutex::new(Vec::new());
    let record = |line: &str| warnings.lock().unwrap().push(line.to_string());
    let m = synthesize(&small, &spec, cache(), 1, &record).unwrap();
    let c = &m.compression[0];
    assert!(
        c.pressure.len() >= 2 && c.pressure.len() < 15,
        "{:?}",
        c.pressure
    );
    assert!(c.phi.iter().all(|v| v.is_finite()));
    let w = warnings.lock().unwrap();
    assert!(
        w.iter()
            .any(|l| l.starts_with("warning: synth:") && l.contains("clipped")),
        "{w:?}"
    );
}

fn dustdem(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(args)
        .output()
        .expect("dustdem runs")
}

#[test]
fn bad_measured_files_exit_2_naming_file_field_and_value() {
    let dir = Scratch::new("calibrate-bad");
    let good = "[[compression]]\ngeometry = \"omni\"\npressure_pa = [1e2, 1e3]\nphi = [0.15, 0.2]\nphi_sigma = 0.01\n";
    let cases = [
        (
            "missing",
            good.replace("phi = [0.15, 0.2]\n", ""),
            "phi",
            "(missing)",
        ),
        (
            "negative",
            good.replace("1e2, 1e3", "-1e2, 1e3"),
            "pressure_pa[0]",
            "-100",
        ),
        (
            "nan",
            good.replace("0.15, 0.2", "nan, 0.2"),
            "phi[0]",
            "NaN",
        ),
        ("unknown", format!("{good}colour = 3\n"), "colour", "colour"),
    ];
    let config = repo("configs/calibrate_quick.toml");
    for (name, text, field, value) in cases {
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let out = dustdem(&[
            "calibrate",
            "--measured",
            path.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(path.to_str().unwrap()), "{name}: {err}");
        assert!(err.contains(field) && err.contains(value), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
}

#[test]
fn synth_and_calibrate_from_the_command_line() {
    // Sticking only (cheap): synth writes data with stronger damping, calibrate finds it,
    // reports progress on stderr and writes the report, the PNG and the corrected config. The
    // same seeds give the same file.
    let dir = Scratch::new("calibrate-cli");
    let config = repo("configs/calibrate_quick.toml");
    let data = dir.join("data.toml");
    let synth = |out: &Path| {
        dustdem(&[
            "synth",
            "--config",
            config.to_str().unwrap(),
            "--effect",
            "normal_damping=1.5",
            "--geometry",
            "omni",
            "--seeds",
            "101",
            "--p-max",
            "1e3",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let out = synth(&data);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let again = dir.join("again.toml");
    assert!(synth(&again).status.success());
    let text = std::fs::read_to_string(&data).unwrap();
    assert_eq!(text, std::fs::read_to_string(&again).unwrap());
    assert!(!text.contains("damping"), "{text}");
    // Keep only the sticking velocity for the calibration.
    let mut m = MeasuredSet::load(&data).unwrap();
    m.compression.clear();
    let sticking = dir.join("sticking.toml");
    std::fs::write(&sticking, m.to_toml()).unwrap();
    let report = dir.join("report");
    // The same file twice: curves of several files are fitted jointly.
    let out = dustdem(&[
        "calibrate",
        "--measured",
        sticking.to_str().unwrap(),
        "--measured",
        sticking.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
        "--threads",
        "2",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("round 1: screen"), "{stderr}");
    // One sticking velocity ties damping with surface energy (see the test above); either
    // way the damping is among the explanations and the corrected config changes the model.
    assert!(stdout.contains("normal_damping"), "{stdout}");
    for f in ["report.md", "calibration.png", "corrected.toml"] {
        assert!(report.join(f).is_file(), "{f}");
    }
    // A panel per sticking velocity (the file was given twice), no SVG without a compression
    // curve.
    let png = std::fs::read(report.join("calibration.png")).unwrap();
    let reader = png::Decoder::new(png.as_slice()).read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (2 * 560, 420));
    assert!(!report.join("curve_1.svg").exists());
    // The nominal best of the tie is applied: the corrected config differs from the base.
    let corrected = Config::load(&report.join("corrected.toml")).unwrap();
    assert_ne!(corrected, base(), "{stdout}");
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(
        md.contains("## Round 1") && md.contains("calibration.png"),
        "{md}"
    );
}

#[test]
fn literature_files_load_and_match_physics_md() {
    // The Eq. 13 fits sampled by the loader reproduce the tabulated values at both ends.
    for (file, lo, hi) in [
        ("configs/measured/guettler2009_omni.toml", 0.1581, 0.5626),
        (
            "configs/measured/blum_schraepler2004_uni.toml",
            0.1509,
            0.3298,
        ),
    ] {
        let m = MeasuredSet::load(&repo(file)).unwrap();
        let c = &m.compression[0];
        let (p_lo, p_hi) = c.pressure_range();
        assert!((p_lo / 1e2 - 1.0).abs() < 1e-12 && (p_hi / 1e6 - 1.0).abs() < 1e-12);
        let n = c.phi.len();
        assert!(
            (c.phi[0] - lo).abs() < 1e-4 && (c.phi[n - 1] - hi).abs() < 1e-4,
            "{file}"
        );
        assert!(!m.source.citation.is_empty() && !m.source.what.is_empty());
    }
    let poppe = MeasuredSet::load(&repo("configs/measured/poppe2000_sticking.toml")).unwrap();
    assert_eq!(poppe.sticking[0].velocity, 1.2);
}
