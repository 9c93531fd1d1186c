use super::*;
use crate::rng::Rng;

/// A run whose pressure follows `truth` along a φ ramp, rows in time order.
fn run_of(truth: &Eq13, noise: impl FnMut() -> f64, rows: usize) -> CurveTable {
    let mut noise = noise;
    let mut t = CurveTable::default();
    for k in 0..rows {
        let phi = 0.151 + 0.42 * k as f64 / (rows - 1) as f64;
        let p = truth.pressure_at(phi).unwrap_or(f64::NAN) * 10f64.powf(noise());
        t.step.push(100 * k as u64);
        t.time_s.push(k as f64 * 3e-8);
        t.wall_gap_m.push(6e-5 * 0.15 / phi);
        t.p_top_pa.push(p);
        t.phi.push(phi);
    }
    t
}

const TRUTH: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.58,
    p_m: 5e3,
    delta: 0.3,
};

#[test]
fn pressure_at_phi_interpolates_between_rows_and_refuses_unreached() {
    let run = run_of(&TRUTH, || 0.0, 43);
    // Rows at φ = 0.151 + 0.01 k: a quarter of the way from row 10 to row 11 lies φ = 0.2535.
    let want = run.p_top_pa[10] + 0.25 * (run.p_top_pa[11] - run.p_top_pa[10]);
    let got = pressure_at_phi(&run, 0.2535).unwrap();
    assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
    assert_eq!(pressure_at_phi(&run, 0.6), None);
    // Before the first row there is nothing to interpolate from.
    assert_eq!(pressure_at_phi(&run, 0.15), None);
}

#[test]
fn average_at_fixed_phi_is_the_mean_of_the_seeds_where_all_reached() {
    let a = run_of(&TRUTH, || 0.0, 43);
    let mut b = run_of(&TRUTH, || 0.0, 43);
    for p in &mut b.p_top_pa {
        *p *= 3.0;
    }
    b.phi.truncate(30);
    b.p_top_pa.truncate(30);
    let avg = average_at_fixed_phi(&[&a, &b], &phi_grid(0.2, 0.55, 0.05));
    // b stops at φ = 0.151 + 0.29 = 0.441: 0.45 and above are left out.
    assert_eq!(avg.len(), 5, "{avg:?}");
    for x in &avg {
        let one = pressure_at_phi(&a, x.phi).unwrap();
        assert!((x.p_mean / (2.0 * one) - 1.0).abs() < 1e-12);
        // sd of {1, 3}·p is √2·p.
        assert!((x.p_sd / (2f64.sqrt() * one) - 1.0).abs() < 1e-12);
    }
}

#[test]
fn student_t_matches_the_tables() {
    // Two-sided 68.27 % points: 1.8373 (1 dof), 1.3213 (2), 1.0906 (6), → 1.
    assert!((student_t68(1) - 1.837).abs() < 1e-3);
    assert!((student_t68(2) - 1.321).abs() < 1e-3);
    assert!((student_t68(6) - 1.091).abs() < 1e-3);
    assert!(student_t68(0).is_nan());
}

/// P(0 < T < t) for Student's t with ν degrees of freedom, by Simpson's rule on its density
/// (normalised by Γ((ν+1)/2)/Γ(ν/2), from 1/√π at ν = 1 and √π/2 at ν = 2 by Γ(x+1) = xΓ(x)).
fn t_probability_below(t: f64, dof: usize) -> f64 {
    let pi = std::f64::consts::PI;
    let mut ratio = if dof % 2 == 1 {
        1.0 / pi.sqrt()
    } else {
        pi.sqrt() / 2.0
    };
    let mut v = 2 - dof % 2;
    while v < dof {
        ratio *= (v + 1) as f64 / v as f64;
        v += 2;
    }
    let nu = dof as f64;
    let density = |x: f64| ratio / (nu * pi).sqrt() * (1.0 + x * x / nu).powf(-(nu + 1.0) / 2.0);
    let n = 2000;
    let h = t / n as f64;
    let inner: f64 = (1..n)
        .map(|k| if k % 2 == 1 { 4.0 } else { 2.0 } * density(k as f64 * h))
        .sum();
    (density(0.0) + inner + density(t)) * h / 3.0
}

#[test]
fn student_t_holds_68_percent_at_every_dof() {
    // Half of the two-sided 68.27 % (the normal ±1σ): erf(1/√2)/2 = 0.3413447.
    let half = 0.341_344_746;
    for dof in (1..=40).chain([50, 75, 100, 200, 1000]) {
        let t = student_t68(dof);
        // The table's 3 decimals move the probability by at most 5e-4 × density (< 0.25).
        let tolerance = if dof < 10 { 1.3e-4 } else { 2e-5 };
        let p = t_probability_below(t, dof);
        assert!((p - half).abs() < tolerance, "dof {dof}: t {t}, P {p}");
    }
    // The normal limit.
    assert!((student_t68(1_000_000) - 1.0).abs() < 1e-6);
}

/// Seeds differ by their own p_m and Δ (as samples do) and by row noise.
fn seed_runs(rng: &mut Rng, seeds: usize) -> Vec<CurveTable> {
    (0..seeds)
        .map(|_| {
            let own = Eq13 {
                p_m: TRUTH.p_m * 10f64.powf(0.08 * rng.normal()),
                delta: TRUTH.delta * (1.0 + 0.08 * rng.normal()),
                ..TRUTH
            };
            let mut noise = Rng::new(rng.uniform().to_bits());
            run_of(&own, move || 0.05 * noise.normal(), 43)
        })
        .collect()
}

#[test]
fn seed_errors_cover_the_ensemble_value_in_68_percent_of_trials() {
    let grid = phi_grid(0.16, 0.56, 0.01);
    let held = Held {
        phi1: Some(0.15),
        phi2: Some(0.58),
    };
    let mut rng = Rng::new(5);
    // The estimator's infinite-ensemble value: the same fit over many seeds.
    let many = seed_runs(&mut rng, 3000);
    let refs: Vec<&CurveTable> = many.iter().collect();
    let limit = fit_ensemble(&refs, &grid, held).unwrap().mean_fit.params;
    const TRIALS: usize = 400;
    let (mut cover_pm, mut cover_delta, mut cover_linear) = (0, 0, 0);
    for _ in 0..TRIALS {
        let runs = seed_runs(&mut rng, 3);
        let refs: Vec<&CurveTable> = runs.iter().collect();
        let f = fit_ensemble(&refs, &grid, held).unwrap();
        assert_eq!(f.seeds_fitted, 3);
        let d_log = (f.mean_fit.params.p_m / limit.p_m).log10().abs();
        cover_pm += usize::from(d_log <= f.err_log10_pm);
        // The same interval in p_m itself (delta method: p_m ln 10 σ_log).
        cover_linear += usize::from((f.mean_fit.params.p_m - limit.p_m).abs() <= f.err.p_m);
        cover_delta += usize::from((f.mean_fit.params.delta - limit.delta).abs() <= f.err.delta);
    }
    // 400 trials: binomial sd of a 68.3 % rate is 2.3 %; ±7 % is three sd.
    for (name, hits) in [
        ("log p_m", cover_pm),
        ("p_m", cover_linear),
        ("delta", cover_delta),
    ] {
        let rate = hits as f64 / TRIALS as f64;
        assert!((rate - 0.683).abs() < 0.07, "{name}: coverage {rate}");
    }
}

#[test]
fn one_seed_has_no_seed_error() {
    let runs = seed_runs(&mut Rng::new(9), 1);
    let grid = phi_grid(0.16, 0.56, 0.01);
    let held = Held {
        phi1: Some(0.15),
        phi2: None,
    };
    let f = fit_ensemble(&[&runs[0]], &grid, held).unwrap();
    assert!(f.err.delta.is_nan() && f.err_log10_pm.is_nan());
    assert_eq!(f.err.phi1, 0.0);
}

#[test]
fn a_row_without_pressure_at_the_crossing_gives_no_pressure() {
    let mut run = run_of(&TRUTH, || 0.0, 43);
    run.p_top_pa[10] = f64::NAN;
    assert_eq!(
        pressure_at_phi(&run, 0.2535),
        None,
        "row before the crossing"
    );
    let mut run = run_of(&TRUTH, || 0.0, 43);
    run.p_top_pa[11] = f64::NAN;
    assert_eq!(
        pressure_at_phi(&run, 0.2535),
        None,
        "row after the crossing"
    );
}

#[test]
fn the_phi_grid_keeps_its_upper_end() {
    // (0.7 − 0.16) / 0.01 is 53.99999999999999 in floating point: the end must survive it.
    let grid = phi_grid(0.16, 0.7, 0.01);
    assert_eq!(grid.len(), 55);
    assert!((grid[54] - 0.7).abs() < 1e-12, "{}", grid[54]);
    assert_eq!(phi_grid(0.2, 0.25, 0.1), vec![0.2]);
}

#[test]
fn held_filling_factors_are_held_and_free_ones_fitted() {
    let runs = seed_runs(&mut Rng::new(3), 3);
    let refs: Vec<&CurveTable> = runs.iter().collect();
    let grid = phi_grid(0.16, 0.56, 0.01);
    // Held away from the truth (0.15, 0.58), so a fit that frees them would move them.
    let held = Held {
        phi1: Some(0.12),
        phi2: Some(0.62),
    };
    let f = fit_ensemble(&refs, &grid, held).unwrap();
    assert_eq!(
        (f.mean_fit.params.phi1, f.mean_fit.params.phi2),
        (0.12, 0.62)
    );
    assert_eq!((f.err.phi1, f.err.phi2), (0.0, 0.0));
    let free = Held {
        phi1: Some(0.12),
        phi2: None,
    };
    let f = fit_ensemble(&refs, &grid, free).unwrap();
    assert_eq!(f.mean_fit.params.phi1, 0.12);
    assert!(f.mean_fit.params.phi2 != 0.62 && f.err.phi2 > 0.0, "{f:?}");
}

#[test]
fn points_without_pressure_are_left_out_of_a_fit() {
    let run = run_of(&TRUTH, || 0.0, 43);
    let grid = phi_grid(0.16, 0.56, 0.01);
    let held = Held {
        phi1: Some(0.15),
        phi2: Some(0.58),
    };
    let points: Vec<(f64, f64)> = average_at_fixed_phi(&[&run], &grid)
        .iter()
        .map(|a| (a.p_mean, a.phi))
        .collect();
    let with_zeros: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .chain([(0.0, 0.3), (0.0, 0.4)])
        .collect();
    assert_eq!(
        fit_points(&points, held).unwrap(),
        fit_points(&with_zeros, held).unwrap()
    );
}

#[test]
fn a_seed_that_cannot_be_fitted_voids_the_seed_errors() {
    // Three seeds; the third held no pressure at all (its own fit has no points), so the
    // seed-to-seed spread of two fits is not the spread of three: no errors.
    let mut runs = seed_runs(&mut Rng::new(4), 3);
    runs[2].p_top_pa.iter_mut().for_each(|p| *p = 0.0);
    let refs: Vec<&CurveTable> = runs.iter().collect();
    let held = Held {
        phi1: Some(0.15),
        phi2: Some(0.58),
    };
    let f = fit_ensemble(&refs, &phi_grid(0.16, 0.56, 0.01), held).unwrap();
    assert_eq!(f.seeds_fitted, 2);
    assert!(f.err.delta.is_nan() && f.err_log10_pm.is_nan(), "{f:?}");
    // The same two seeds alone have errors.
    let two = fit_ensemble(&refs[..2], &phi_grid(0.16, 0.56, 0.01), held).unwrap();
    assert!(two.err.delta > 0.0 && two.err_log10_pm > 0.0, "{two:?}");
}
