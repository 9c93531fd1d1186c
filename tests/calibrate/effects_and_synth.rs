//! Every effect changes the simulation at the end of its range, and `synthesize` clips a curve
//! to the pressures the sample reached.

use super::*;
use dustdem::calibrate::simulate::{compression_config, run_all, sticking_config, Output, Run};

#[test]
fn every_effect_changes_the_simulation() {
    // A tiny compression (60 monomers, fast wall) and the sticking run, at the top of each
    // effect's range against the baseline: at least one of them must differ.
    let mut small = base();
    small.sample.monomers = 60;
    small.experiment.wall_speed_m_s = 2.0;
    let runs_of = |c: &Config| {
        vec![
            Run::Compression(compression_config(c, Geometry::Omni, None, 7, 1e4)),
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
