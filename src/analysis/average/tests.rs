//! Tests of the seed average: synthetic Eq. 13 curves with known per-seed offsets.

use super::*;
use crate::analysis::fit::Eq13;
use crate::rng::Rng;

const GUETTLER: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.58,
    p_m: 16667.0,
    delta: 0.562,
};

/// Largest spacing of the sampled log₁₀P, in decades.
const MAX_STEP: f64 = 0.02;

/// Bound of the error of linear interpolation in x = log₁₀P between samples at most
/// `MAX_STEP` apart: h²/8 · max|φ''(x)|, with φ'' = −(φ₂ − φ₁)·s''(u)/Δ² and
/// max|s''| = max|σ(1 − σ)(1 − 2σ)| = 1/(6√3) for the logistic σ.
fn interpolation_bound() -> f64 {
    let max_s2 = 1.0 / (6.0 * 3f64.sqrt());
    let curvature = (GUETTLER.phi2 - GUETTLER.phi1) * max_s2 / GUETTLER.delta.powi(2);
    MAX_STEP * MAX_STEP / 8.0 * curvature
}

/// A curve φ = Eq13(P) + offset sampled with jittered log-spacing from 10 Pa to `p_max`,
/// every spacing between 0.4 and 1.6 times 0.0125 decades.
fn synthetic_curve(offset: f64, p_max: f64, rng: &mut Rng) -> Vec<(f64, f64)> {
    let step = 0.0125;
    let mut x = 1.0;
    let mut out = Vec::new();
    while x < p_max.log10() {
        let p = 10f64.powf(x);
        out.push((p, GUETTLER.phi(p) + offset));
        x += step * rng.uniform_range(0.4, 1.6);
    }
    out.push((p_max, GUETTLER.phi(p_max) + offset));
    out
}

#[test]
fn log_grid_spacing_and_ends() {
    let g = log_grid(10.0, 1e6, 10);
    assert_eq!(g.len(), 51);
    assert_eq!(g[0], 10.0);
    assert!((g[50] / 1e6 - 1.0).abs() < 1e-12);
    for w in g.windows(2) {
        assert!(((w[1] / w[0]).log10() - 0.1).abs() < 1e-12);
    }
    // A range that is not a whole number of steps still ends at hi.
    let g = log_grid(1.0, 5.0, 4);
    assert_eq!(g.len(), 4);
    assert!((g[3] - 5.0).abs() < 1e-12);
}

#[test]
fn mean_and_spread_are_those_of_the_known_offsets() {
    let offsets = [0.012, -0.007, 0.003, -0.015, 0.009, 0.001];
    // Highest pressures half a grid step (0.05 dex) off the grid points 10^(k/10).
    let p_max = [
        1e6 * 1.2,
        10f64.powf(4.05),
        1e6 * 1.2,
        10f64.powf(5.45),
        1e6 * 1.2,
        1e6 * 1.2,
    ];
    let mut rng = Rng::new(11);
    let mut curves: Vec<Vec<(f64, f64)>> = offsets
        .iter()
        .zip(&p_max)
        .map(|(&d, &pm)| synthetic_curve(d, pm, &mut rng))
        .collect();

    // Curve 0: the pressure drops back from 10^4.5 to 10^4 and recovers while φ holds still;
    // the grid points 10^4.1..10^4.4 must still read the first rise, not the dip. Five rows
    // hold the pressure before and after the dip, so that the nine-row running median sees a
    // monotone window at both of its edges and the reading stays exact there.
    let c = &mut curves[0];
    let at = c.iter().position(|&(p, _)| p >= 10f64.powf(4.5)).unwrap();
    let (p_dip, phi_dip) = c[at];
    let mut dip = vec![(p_dip, phi_dip); 4];
    dip.extend((1..40).map(|k| {
        let depth = 0.5 * (1.0 - ((k as f64 - 20.0) / 20.0).abs());
        (p_dip * 10f64.powf(-depth), phi_dip)
    }));
    dip.extend([(p_dip, phi_dip); 5]);
    c.splice(at + 1..at + 1, dip);

    let grid = log_grid(10.0, 1e6, 10);
    let avg = average_curves(&curves, &grid);
    assert_eq!(
        avg.len(),
        grid.len(),
        "every grid pressure is reached by some curve"
    );
    let tol = interpolation_bound();
    assert!(tol < 1e-5, "{tol}");
    for (a, &p) in avg.iter().zip(&grid) {
        assert_eq!(a.p, p);
        // The curves reaching p, by construction.
        let d: Vec<f64> = offsets
            .iter()
            .zip(&p_max)
            .filter(|(_, &pm)| pm >= p)
            .map(|(&d, _)| d)
            .collect();
        assert_eq!(a.count, d.len(), "count at {p}");
        let n = d.len() as f64;
        let mean_d = d.iter().sum::<f64>() / n;
        let sd_d = (d.iter().map(|v| (v - mean_d).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let want = GUETTLER.phi(p) + mean_d;
        // Each value is off by at most `tol`, so the mean by at most `tol` and the sample
        // standard deviation by at most tol·√(n/(n − 1)) (it is Lipschitz in the values).
        assert!(
            (a.mean - want).abs() <= tol,
            "{p}: mean {} want {want}",
            a.mean
        );
        assert!(
            (a.sd - sd_d).abs() <= tol * (n / (n - 1.0)).sqrt(),
            "{p}: sd {} want {sd_d}",
            a.sd
        );
        assert!((a.sem - a.sd / n.sqrt()).abs() < 1e-15);
    }
    // The offsets' spread is far above the tolerance, so a wrong normalisation shows.
    assert!(avg[0].sd > 100.0 * tol);
}

#[test]
fn a_single_row_spike_does_not_count_as_reaching_its_pressure() {
    let mut rng = Rng::new(5);
    let clean = synthetic_curve(0.0, 1e6, &mut rng);
    let mut spiky = clean.clone();
    let at = spiky.iter().position(|&(p, _)| p >= 1e3).unwrap();
    spiky[at].0 *= 100.0;
    // Far from the spike the reading is that of the clean curve, bit for bit; a reader that
    // took the raw running maximum would read 10^4 and 10^5 Pa at the spike row's φ ≈ 0.19.
    for p in [1e2, 1e4, 1e5] {
        assert_eq!(phi_at(&spiky, p), phi_at(&clean, p), "{p}");
    }
    assert!((phi_at(&spiky, 1e4) - GUETTLER.phi(1e4)).abs() <= interpolation_bound());
}

#[test]
fn unreached_grid_points_are_left_out_and_one_curve_has_no_spread() {
    let mut rng = Rng::new(3);
    let curve = synthetic_curve(0.0, 1e4 * 1.2, &mut rng);
    let avg = average_curves(&[curve.clone(), Vec::new()], &[1e2, 1e3, 1e4, 1e5]);
    assert_eq!(avg.iter().map(|a| a.p).collect::<Vec<_>>(), [1e2, 1e3, 1e4]);
    for a in &avg {
        assert_eq!(a.count, 1);
        assert!(a.sd.is_nan() && a.sem.is_nan());
        assert!((a.mean - GUETTLER.phi(a.p)).abs() <= interpolation_bound());
        assert_eq!(a.mean, phi_at(&curve, a.p));
    }
    assert!(phi_at(&curve, 1e5).is_nan());
    assert!(average_curves(&[], &[1e3]).is_empty());

    let auto = average_on_log_grid(&[curve], 5);
    assert!((auto[0].p - 10.0).abs() < 1e-9);
    assert!(auto.len() >= 15 && auto.last().unwrap().p <= 1.2e4);
}

#[test]
fn rows_without_a_positive_finite_pressure_do_not_set_the_log_grid() {
    let mut rng = Rng::new(4);
    let mut curve = synthetic_curve(0.0, 1e4, &mut rng);
    let clean = average_on_log_grid(std::slice::from_ref(&curve), 5);
    // A zero, a negative, an infinite and a NaN pressure change nothing.
    curve.insert(0, (0.0, 0.15));
    curve.insert(1, (-5.0, 0.15));
    curve.push((f64::INFINITY, 0.6));
    curve.push((f64::NAN, 0.6));
    let grid: Vec<f64> = average_on_log_grid(&[curve], 5)
        .iter()
        .map(|a| a.p)
        .collect();
    assert_eq!(grid, clean.iter().map(|a| a.p).collect::<Vec<_>>());
}
