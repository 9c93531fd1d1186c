//! Tests of the speed laws: the paper's constants, exact recovery, and reported errors
//! against the scatter of fits to noisy copies.

use super::*;
use crate::rng::Rng;

const V_STATIC: [f64; 9] = [0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0];
const V_DYNAMIC: [f64; 11] = [1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.0, 10.0, 15.0, 20.0, 25.0];
const V_ALL: [f64; 15] = [
    0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 15.0, 20.0, 25.0,
];

#[test]
fn paper_constants_are_consistent_with_the_paper_text() {
    // At v = 0 the laws give the Güttler fit (p_m = 16.667 kPa, Δ = 0.562).
    assert_eq!(PAPER_PM_QUASI_STATIC.eval(0.0), 16.667);
    assert!((PAPER_DELTA.eval(0.0) - 0.562).abs() < 5e-4);
    // The quadratic's minimum, 33.663 / 36.592 = 0.91996 m/s by hand, is what the text
    // rounds to "≈ 0.9 m/s".
    let vertex = PAPER_PM_QUASI_STATIC.vertex();
    assert!((vertex - 0.919955).abs() < 1e-6, "{vertex}");
    assert!((vertex - PAPER_V_CRIT).abs() < 0.05, "{vertex}");
    // Hand-evaluated values.
    assert!((PAPER_PM_QUASI_STATIC.eval(1.0) - 1.3).abs() < 1e-12);
    assert!((PAPER_PM_DYNAMIC.eval(1.0) - 1.647).abs() < 1e-12);
    assert!((PAPER_PM_DYNAMIC_SQUARE.eval(10.0) - 109.26).abs() < 1e-9);
    assert!((PAPER_PM_DYNAMIC.eval(10.0) - (1.340 * 10f64.powf(1.93) + 0.307)).abs() < 1e-12);
    // The two dynamic fits describe the same data: within 15% over 1–25 m/s.
    for v in V_DYNAMIC {
        let r = PAPER_PM_DYNAMIC_SQUARE.eval(v) / PAPER_PM_DYNAMIC.eval(v);
        assert!((r - 1.0).abs() < 0.15, "{v}: {r}");
    }
}

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs().max(1.0)
}

#[test]
fn recovers_the_paper_fits_from_exact_points() {
    let y: Vec<f64> = V_STATIC
        .iter()
        .map(|&v| PAPER_PM_QUASI_STATIC.eval(v))
        .collect();
    let f = fit_quadratic(&V_STATIC, &y, None).unwrap();
    let (l, t) = (f.law, PAPER_PM_QUASI_STATIC);
    assert!(
        close(l.a, t.a, 1e-9) && close(l.b, t.b, 1e-9) && close(l.c, t.c, 1e-9),
        "{f:?}"
    );
    assert_eq!(f.dof, 6);

    let y: Vec<f64> = V_DYNAMIC
        .iter()
        .map(|&v| PAPER_PM_DYNAMIC.eval(v))
        .collect();
    let f = fit_power_law(&V_DYNAMIC, &y, None, None).unwrap();
    let (l, t) = (f.law, PAPER_PM_DYNAMIC);
    assert!(f.converged, "{f:?}");
    assert!(
        close(l.a, t.a, 1e-7) && close(l.b, t.b, 1e-7) && close(l.c, t.c, 1e-7),
        "{f:?}"
    );
    assert_eq!(f.free, ["a", "b", "c"]);

    let y: Vec<f64> = V_DYNAMIC
        .iter()
        .map(|&v| PAPER_PM_DYNAMIC_SQUARE.eval(v))
        .collect();
    let f = fit_power_law(&V_DYNAMIC, &y, None, Some(2.0)).unwrap();
    let (l, t) = (f.law, PAPER_PM_DYNAMIC_SQUARE);
    assert!(
        close(l.a, t.a, 1e-9) && l.b == 2.0 && close(l.c, t.c, 1e-9),
        "{f:?}"
    );
    assert_eq!((f.std_err.b, f.free.clone()), (0.0, vec!["a", "c"]));

    let y: Vec<f64> = V_ALL.iter().map(|&v| PAPER_DELTA.eval(v)).collect();
    let f = fit_shifted_power_law(&V_ALL, &y, None).unwrap();
    let (l, t) = (f.law, PAPER_DELTA);
    assert!(f.converged, "{f:?}");
    assert!(
        close(l.a, t.a, 1e-6) && close(l.b, t.b, 1e-6) && close(l.c, t.c, 1e-6),
        "{f:?}"
    );
}

/// Summary of fits to `draws` noisy copies of exact values `y` with one-sigma noise `sigma`.
struct Scatter {
    /// Empirical sd of each parameter over the mean reported error.
    sd_over_err: [f64; 3],
    /// |mean − truth| over the standard error of that mean.
    bias_in_sem: [f64; 3],
    /// Fraction of fits whose 1σ interval holds the truth.
    coverage: [f64; 3],
    mean_chi2_per_dof: f64,
}

/// A fit of noisy values with optional σ: (parameters, reported errors, χ²/dof).
type Fit<'a> = &'a dyn Fn(&[f64], Option<&[f64]>) -> ([f64; 3], [f64; 3], f64);

fn scatter(
    y: &[f64],
    sigma: &[f64],
    truth: [f64; 3],
    draws: usize,
    seed: u64,
    weighted: bool,
    fit: Fit,
) -> Scatter {
    let mut rng = Rng::new(seed);
    let (mut sum, mut sum2, mut err, mut hits, mut chi2) =
        ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3], 0.0);
    for _ in 0..draws {
        let noisy: Vec<f64> = y
            .iter()
            .zip(sigma)
            .map(|(&y, &s)| y + s * rng.normal())
            .collect();
        let (p, e, c) = fit(&noisy, weighted.then_some(sigma));
        for j in 0..3 {
            sum[j] += p[j];
            sum2[j] += p[j] * p[j];
            err[j] += e[j];
            hits[j] += f64::from(u8::from((p[j] - truth[j]).abs() <= e[j]));
        }
        chi2 += c;
    }
    let m = draws as f64;
    let mut s = Scatter {
        sd_over_err: [0.0; 3],
        bias_in_sem: [0.0; 3],
        coverage: [0.0; 3],
        mean_chi2_per_dof: chi2 / m,
    };
    for j in 0..3 {
        let mean = sum[j] / m;
        let sd = ((sum2[j] - m * mean * mean) / (m - 1.0)).sqrt();
        s.sd_over_err[j] = sd / (err[j] / m);
        s.bias_in_sem[j] = (mean - truth[j]).abs() / (sd / m.sqrt());
        s.coverage[j] = hits[j] / m;
    }
    s
}

/// With `draws` = 300 the sample sd is within ±20% of the true one at about 5σ
/// (its relative error is 1/√(2·300) ≈ 4%), a mean is off by less than 4 of its standard
/// errors, and the 1σ coverage (68.3% for Gaussian estimates) lies within ±9% at about 3σ
/// (binomial sd √(0.68·0.32/300) ≈ 2.7%).
fn assert_scatter(name: &str, s: &Scatter, free: &[usize], chi2: f64) {
    println!(
        "{name}: sd/err {:.3?}, bias/sem {:.2?}, coverage {:.3?}, chi2/dof {:.3}",
        s.sd_over_err, s.bias_in_sem, s.coverage, s.mean_chi2_per_dof
    );
    for &j in free {
        assert!((s.sd_over_err[j] - 1.0).abs() < 0.2, "{name}[{j}]: sd/err");
        assert!(s.bias_in_sem[j] < 4.0, "{name}[{j}]: bias");
        assert!(
            (s.coverage[j] - 0.683).abs() < 0.09,
            "{name}[{j}]: coverage"
        );
    }
    assert!(
        (s.mean_chi2_per_dof / chi2 - 1.0).abs() < 0.15,
        "{name}: chi2/dof"
    );
}

const DRAWS: usize = 300;

#[test]
fn reported_errors_match_monte_carlo_scatter() {
    // Heteroscedastic errors (3% of p_m, floored): an unweighted fit would scatter far more
    // than the weighted errors it reports.
    let rel = |y: &[f64]| -> Vec<f64> { y.iter().map(|y| 0.03 * y.abs().max(1.0)).collect() };

    let t = PAPER_PM_QUASI_STATIC;
    let y: Vec<f64> = V_STATIC.iter().map(|&v| t.eval(v)).collect();
    let sigma = rel(&y);
    let f = |y: &[f64], s: Option<&[f64]>| {
        let r = fit_quadratic(&V_STATIC, y, s).unwrap();
        let (l, e) = (r.law, r.std_err);
        ([l.a, l.b, l.c], [e.a, e.b, e.c], r.chi2_per_dof)
    };
    let s = scatter(&y, &sigma, [t.a, t.b, t.c], DRAWS, 1, true, &f);
    assert_scatter("quadratic", &s, &[0, 1, 2], 1.0);
    // Without σ the residual scatter sets the errors; equal noise on every point.
    let flat = vec![0.3; y.len()];
    let s = scatter(&y, &flat, [t.a, t.b, t.c], DRAWS, 2, false, &f);
    assert_scatter("quadratic, no sigma", &s, &[0, 1, 2], 0.09);

    let t = PAPER_PM_DYNAMIC;
    let y: Vec<f64> = V_DYNAMIC.iter().map(|&v| t.eval(v)).collect();
    let sigma = rel(&y);
    let f = |y: &[f64], s: Option<&[f64]>| {
        let r = fit_power_law(&V_DYNAMIC, y, s, None).unwrap();
        assert!(r.converged);
        let (l, e) = (r.law, r.std_err);
        ([l.a, l.b, l.c], [e.a, e.b, e.c], r.chi2_per_dof)
    };
    let s = scatter(&y, &sigma, [t.a, t.b, t.c], DRAWS, 3, true, &f);
    assert_scatter("power law", &s, &[0, 1, 2], 1.0);

    let t = PAPER_PM_DYNAMIC_SQUARE;
    let y: Vec<f64> = V_DYNAMIC.iter().map(|&v| t.eval(v)).collect();
    let sigma = rel(&y);
    let f = |y: &[f64], s: Option<&[f64]>| {
        let r = fit_power_law(&V_DYNAMIC, y, s, Some(2.0)).unwrap();
        let (l, e) = (r.law, r.std_err);
        ([l.a, l.b, l.c], [e.a, e.b, e.c], r.chi2_per_dof)
    };
    let s = scatter(&y, &sigma, [t.a, t.b, t.c], DRAWS, 4, true, &f);
    assert_scatter("power law, b = 2", &s, &[0, 2], 1.0);

    let t = PAPER_DELTA;
    let y: Vec<f64> = V_ALL.iter().map(|&v| t.eval(v)).collect();
    let sigma: Vec<f64> = y.iter().map(|y| 0.005 * y).collect();
    let f = |y: &[f64], s: Option<&[f64]>| {
        let r = fit_shifted_power_law(&V_ALL, y, s).unwrap();
        assert!(r.converged);
        let (l, e) = (r.law, r.std_err);
        ([l.a, l.b, l.c], [e.a, e.b, e.c], r.chi2_per_dof)
    };
    let s = scatter(&y, &sigma, [t.a, t.b, t.c], DRAWS, 5, true, &f);
    assert_scatter("shifted power law", &s, &[0, 1, 2], 1.0);
}

#[test]
fn errors_given_are_not_rescaled_by_the_scatter() {
    // Noise twice the stated σ: the reported errors stay those of σ, and χ²/dof shows 4.
    let t = PAPER_PM_QUASI_STATIC;
    let y: Vec<f64> = V_STATIC.iter().map(|&v| t.eval(v)).collect();
    let sigma = vec![0.2; y.len()];
    let exact = fit_quadratic(&V_STATIC, &y, Some(&sigma)).unwrap();
    let mut rng = Rng::new(9);
    let mut chi2 = 0.0;
    for _ in 0..DRAWS {
        let noisy: Vec<f64> = y.iter().map(|y| y + 0.4 * rng.normal()).collect();
        let r = fit_quadratic(&V_STATIC, &noisy, Some(&sigma)).unwrap();
        assert_eq!(r.std_err, exact.std_err);
        chi2 += r.chi2_per_dof;
    }
    let mean = chi2 / DRAWS as f64;
    assert!((mean / 4.0 - 1.0).abs() < 0.15, "{mean}");
}

#[test]
fn rejects_bad_input() {
    let y = [1.0, 2.0, 3.0, 4.0];
    assert_eq!(
        fit_quadratic(&[1.0, 2.0, 3.0], &y, None).unwrap_err(),
        LawError::LengthMismatch {
            expected: 3,
            found: 4
        }
    );
    assert!(matches!(
        fit_quadratic(&[0.1, 0.2, 0.3], &y[..3], None).unwrap_err(),
        LawError::TooFewPoints { points: 3, free: 3 }
    ));
    let e = fit_power_law(&[0.0, 1.0, 2.0, 3.0], &y, None, None).unwrap_err();
    assert_eq!(
        e,
        LawError::InvalidPoint {
            index: 0,
            v: 0.0,
            y: 1.0
        }
    );
    assert!(e.to_string().contains("point 0"));
    assert!(fit_power_law(&[1.0, 2.0, 3.0], &y[..3], None, Some(2.0)).is_ok());
    let e =
        fit_shifted_power_law(&[1.0, 2.0, 3.0, 4.0], &y, Some(&[0.1, 0.0, 0.1, 0.1])).unwrap_err();
    assert_eq!(
        e,
        LawError::InvalidSigma {
            index: 1,
            sigma: 0.0
        }
    );
    // One speed repeated cannot fix a curve.
    assert_eq!(
        fit_quadratic(&[1.0; 5], &[1.0, 2.0, 1.5, 1.2, 1.1], None).unwrap_err(),
        LawError::Singular
    );
}
