//! Tests of the Eq. 13 fit's guards and start, written against the survivors of `cargo mutants`
//! (docs/guide/src/validation.md, "Mutation testing"): the inverse's refusals, the option
//! checks, the plateaus' least squares and the grid start.

use super::tests::{logspace, GUETTLER};
use super::*;

#[test]
fn pressure_at_refuses_parameters_without_a_transition() {
    // Δ ≤ 0 is no transition: without the guard Δ = 0 would put every φ at p_m.
    for delta in [0.0, -0.5] {
        let e = Eq13 { delta, ..GUETTLER };
        assert_eq!(e.pressure_at(0.3), None, "Δ = {delta}");
    }
    for p_m in [0.0, -1e4, f64::INFINITY] {
        let e = Eq13 { p_m, ..GUETTLER };
        assert_eq!(e.pressure_at(0.3), None, "p_m = {p_m}");
    }
    let open = Eq13 {
        phi2: f64::INFINITY,
        ..GUETTLER
    };
    assert_eq!(open.pressure_at(0.3), None);
}

#[test]
fn pressure_at_refuses_pressures_beyond_f64() {
    // A transition 50 decades wide: 0.2 % of the span from either plateau lies 10^±135 decades
    // from p_m, beyond what f64 holds; the inverse overflows to ∞ or underflows to 0.
    let wide = Eq13 {
        delta: 50.0,
        ..GUETTLER
    };
    let span = wide.phi2 - wide.phi1;
    assert_eq!(wide.pressure_at(wide.phi2 - 0.002 * span), None, "overflow");
    assert_eq!(
        wide.pressure_at(wide.phi1 + 0.001 * span),
        None,
        "underflow"
    );
    // Nearer the middle the same law inverts.
    let p = wide.pressure_at(wide.phi1 + 0.5 * span).unwrap();
    assert!((p / wide.p_m - 1.0).abs() < 1e-12, "{p}");
}

#[test]
fn negative_sigma_and_non_positive_initial_values_are_refused() {
    let p = logspace(1e2, 1e6, 8);
    let phi: Vec<f64> = p.iter().map(|&p| GUETTLER.phi(p)).collect();
    let opt = FitOptions::default();
    let mut sigma = vec![0.01; 8];
    sigma[5] = -0.01;
    let e = fit_eq13(&p, &phi, Some(&sigma), &opt).unwrap_err();
    assert_eq!(
        e,
        FitError::InvalidSigma {
            index: 5,
            sigma: -0.01
        }
    );
    for (initial, name) in [
        (
            Eq13 {
                p_m: 0.0,
                ..GUETTLER
            },
            "initial.p_m",
        ),
        (
            Eq13 {
                p_m: -1e4,
                ..GUETTLER
            },
            "initial.p_m",
        ),
        (
            Eq13 {
                delta: 0.0,
                ..GUETTLER
            },
            "initial.delta",
        ),
    ] {
        let options = FitOptions {
            initial: Some(initial),
            ..opt
        };
        let e = fit_eq13(&p, &phi, None, &options).unwrap_err();
        assert!(
            matches!(e, FitError::InvalidOption { name: n, .. } if n == name),
            "{initial:?}: {e:?}"
        );
    }
}

/// The fit's problem on points (x = log₁₀p, φ, weight), with every θ admissible.
fn problem<'a>(x: &'a [f64], y: &'a [f64], w: &'a [f64]) -> Problem<'a> {
    Problem {
        x,
        y,
        w,
        model: &model,
        admissible: &|_| true,
    }
}

/// Noise-free points of `truth` at 31 pressures from 10 Pa to 1 MPa, as the fit sees them.
fn noise_free(truth: Eq13) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let p = logspace(1e1, 1e6, 31);
    let x: Vec<f64> = p.iter().map(|v| v.log10()).collect();
    let y: Vec<f64> = p.iter().map(|&v| truth.phi(v)).collect();
    (x, y, vec![1.0; p.len()])
}

#[test]
fn best_plateaus_solve_the_linear_least_squares_exactly() {
    let truth = GUETTLER;
    let (x, y, w) = noise_free(truth);
    let d = problem(&x, &y, &w);
    let (log_pm, delta) = (truth.p_m.log10(), truth.delta);
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
    let (p1, p2) = best_plateaus(&d, log_pm, delta, None, None).unwrap();
    assert!(close(p1, truth.phi1) && close(p2, truth.phi2), "{p1} {p2}");
    let (p1, p2) = best_plateaus(&d, log_pm, delta, Some(truth.phi1), None).unwrap();
    assert!(p1 == truth.phi1 && close(p2, truth.phi2), "{p2}");
    let (p1, p2) = best_plateaus(&d, log_pm, delta, None, Some(truth.phi2)).unwrap();
    assert!(close(p1, truth.phi1) && p2 == truth.phi2, "{p1}");
    assert_eq!(
        best_plateaus(&d, log_pm, delta, Some(0.1), Some(0.2)),
        Some((0.1, 0.2))
    );
}

#[test]
fn the_grid_start_lands_next_to_the_truth() {
    // Transitions narrower and wider than the midpoint start's Δ = 0.5, across the sampled
    // range: the start is the grid node next to the truth, one step of
    // (range + 1 decade)/60 in log p_m and one factor 100^(1/19) in Δ.
    for truth in [
        Eq13 {
            p_m: 3e2,
            delta: 0.12,
            ..GUETTLER
        },
        Eq13 {
            p_m: 1e3,
            delta: 0.9,
            ..GUETTLER
        },
        // Next to the lowest pressure: the grid reaches half a decade below the data.
        Eq13 {
            p_m: 10f64.powf(1.25),
            delta: 0.15,
            ..GUETTLER
        },
        // Next to the highest: the grid reaches half a decade above.
        Eq13 {
            p_m: 10f64.powf(5.75),
            delta: 0.15,
            ..GUETTLER
        },
    ] {
        let (x, y, w) = noise_free(truth);
        let d = problem(&x, &y, &w);
        let [_, _, log_pm, delta] = initial_guess(&d, None, None);
        let step = (5.0 + 1.0) / 60.0;
        assert!(
            (log_pm - truth.p_m.log10()).abs() <= step,
            "{truth:?}: log p_m {log_pm}"
        );
        // A node of the grid: log p_m = (x_min − 0.5) + i·step, i = 0…60, and
        // Δ = 0.03·100^(j/19), j = 0…19.
        let i = ((log_pm - 0.5) / step).round();
        assert!(
            (0.0..=60.0).contains(&i) && (0.5 + i * step - log_pm).abs() < 1e-12,
            "{log_pm}"
        );
        let j = ((delta / 0.03).ln() / 100f64.ln() * 19.0).round();
        let node = 0.03 * 100f64.powf(j / 19.0);
        assert!(
            (0.0..=19.0).contains(&j) && (node / delta - 1.0).abs() < 1e-12,
            "{delta}"
        );
        let factor = 100f64.powf(1.0 / 19.0);
        assert!(
            delta / truth.delta <= factor && truth.delta / delta <= factor,
            "{truth:?}: Δ {delta}"
        );
        assert!(d.chi2(&initial_guess(&d, None, None)) < d.chi2(&midpoint_guess(&d, None, None)));
    }
}

#[test]
fn the_midpoint_start_crosses_half_way_between_the_plateaus() {
    let truth = GUETTLER;
    let (x, y, w) = noise_free(truth);
    let d = problem(&x, &y, &w);
    let (lo, hi) = (truth.phi(1e1), truth.phi(1e6));
    let [phi1, phi2, log_pm, delta] = midpoint_guess(&d, None, None);
    assert_eq!((phi1, phi2, delta), (lo, hi, 0.5));
    // The crossing of the half-way φ, interpolated between the two samples around it, against
    // the law's own inverse: the interpolation's error is below a tenth of the 1/6-decade
    // sample spacing.
    let crossing = truth.pressure_at(0.5 * (lo + hi)).unwrap().log10();
    assert!((log_pm - crossing).abs() < 0.02, "{log_pm} for {crossing}");
    // Held plateaus set the half-way φ: 0.15 and 0.4 cross at the law's φ = 0.275.
    let [phi1, phi2, log_pm, _] = midpoint_guess(&d, Some(0.15), Some(0.4));
    assert_eq!((phi1, phi2), (0.15, 0.4));
    let crossing = truth.pressure_at(0.275).unwrap().log10();
    assert!((log_pm - crossing).abs() < 0.02, "{log_pm} for {crossing}");
    // A half-way φ no sample crosses: the sample nearest to it, here the lowest pressure.
    let [_, _, log_pm, _] = midpoint_guess(&d, Some(0.0), Some(0.2));
    assert_eq!(log_pm, x[0]);
}
