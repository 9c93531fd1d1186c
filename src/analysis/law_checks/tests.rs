//! Tests of the speed-law checks: the paper's own points, values that are not values, and
//! errors that carry the scatter about a law.
use super::*;
use crate::analysis::speed_laws::{PAPER_DELTA, PAPER_PM_DYNAMIC, PAPER_PM_QUASI_STATIC};

/// The paper's laws at `speeds`, with 5 % errors.
fn paper_points(speeds: &[f64]) -> Vec<SpeedValue> {
    speeds
        .iter()
        .map(|&v| {
            let pm = if v < 1.0 {
                PAPER_PM_QUASI_STATIC.eval(v)
            } else {
                PAPER_PM_DYNAMIC.eval(v)
            };
            let d = PAPER_DELTA.eval(v);
            [v, pm, 0.05 * pm, d, 0.05 * d]
        })
        .collect()
}

#[test]
fn the_paper_s_own_points_give_the_paper_s_laws() {
    let laws = speed_laws(&paper_points(&[1.0, 2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0]));
    let pm = laws.pm_dynamic.fitted().expect("Eq. 15");
    assert!((pm.law.b - 1.93).abs() < 1e-3, "{:?}", pm.law);
    let delta = laws.delta.fitted().expect("Eq. 17");
    assert!((delta.law.c - 0.170).abs() < 1e-3, "{:?}", delta.law);
    let slow = speed_laws(&paper_points(&[0.1, 0.25, 0.5, 0.75, 0.9]));
    let (v, err) = slow.v_crit.expect("v_crit");
    // −b/(2a) of Eq. 14: 33.663 / 36.592.
    assert!((v - 33.663 / 36.592).abs() < 1e-6, "{v} ± {err}");
    // The 5 % errors of p_m carried through −b/(2a): a few per cent of v_crit.
    assert!(err > 0.005 && err < 0.05, "{v} ± {err}");
}

#[test]
fn errors_of_a_law_that_misses_its_points_cover_the_scatter_of_its_coefficients() {
    // Eq. 14 points with stated errors of 0.05 kPa but a true scatter four times larger
    // (χ²/dof ≈ 16): the reported v_crit error must match the v_crit spread over many
    // such data sets, which the stated errors alone understate fourfold.
    let speeds = [0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 1.0];
    let mut rng = crate::rng::Rng::new(11);
    let (mut values, mut reported) = (Vec::new(), Vec::new());
    for _ in 0..400 {
        let points: Vec<SpeedValue> = speeds
            .iter()
            .map(|&v| {
                let pm = PAPER_PM_QUASI_STATIC.eval(v) + 0.2 * rng.normal();
                [v, pm, 0.05, 0.5, 0.01]
            })
            .collect();
        let (law, v_crit) = quadratic(&points);
        let (v, err) = v_crit.expect("a minimum");
        assert!(law.fitted().is_some(), "Eq. 14");
        values.push(v);
        reported.push(err);
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let typical = reported.iter().sum::<f64>() / n;
    // 400 draws pin the spread to ±4 %; the scaled error's mean follows √(χ²/dof), whose
    // mean over 5 degrees of freedom lies about 5 % below 4.
    assert!((typical / sd - 1.0).abs() < 0.15, "{typical} against {sd}");
}

#[test]
fn too_few_speeds_a_negative_offset_or_a_shift_on_its_bound_are_not_values() {
    let few = speed_laws(&paper_points(&[2.5, 5.0, 10.0]));
    assert!(matches!(&few.pm_dynamic, Law::Unconstrained(w) if w.contains("at least 4")));
    // p_m = 0.5 v² − 20 kPa: the offset is negative far beyond its error.
    let negative: Vec<SpeedValue> = [5.0, 7.5, 10.0, 15.0, 20.0]
        .iter()
        .map(|&v| [v, 0.5 * v * v - 20.0, 0.5, 0.2, 0.01])
        .collect();
    let laws = speed_laws(&negative);
    assert!(
        matches!(&laws.pm_dynamic, Law::Unconstrained(w) if w.contains("c = ")),
        "{:?}",
        laws.pm_dynamic
    );
    // Δ = (v − 0.9999)^−1 + 0.1: the shift runs towards its bound a > −min v, and the
    // offset goes negative to make up for it (by less than twice its error once the errors
    // carry the misfit, χ²/dof in the thousands); either way no value is reported.
    let bound: Vec<SpeedValue> = [1.0, 1.5, 2.5, 5.0, 10.0]
        .iter()
        .map(|&v| [v, 1.0, 0.1, 1.0 / (v - 0.9999) + 0.1, 1e-3])
        .collect();
    let laws = speed_laws(&bound);
    assert!(
        matches!(&laws.delta, Law::Unconstrained(w) if w.contains("bound") || w.contains("c = ") || w.contains("converge")),
        "{:?}",
        laws.delta
    );
    // Δ = 0.05 (v − 0.9999)^−1 + 0.3: the shift lands on its bound (a = −0.9994 for
    // −min v = −1) with a negative offset; the bound is named first, as it says more.
    let on_bound: Vec<SpeedValue> = [1.0, 1.5, 2.5, 5.0, 10.0]
        .iter()
        .map(|&v| [v, 1.0, 0.1, 0.05 / (v - 0.9999) + 0.3, 1e-3])
        .collect();
    let laws = speed_laws(&on_bound);
    assert!(
        matches!(&laws.delta, Law::Unconstrained(w) if w.contains("on its bound")),
        "{:?}",
        laws.delta
    );
}

#[test]
fn a_law_that_passes_every_point_with_errors_in_the_thousands_is_not_a_value() {
    // Δ of the unmodified model at 2000 monomers, 0.1–1 m/s (seeds 1, 3, 3, 3, 3; the
    // single seed has no error, so the fit is unweighted): rising then falling, which
    // (v + a)^b + c can follow only with a, b and c known to ±800 or worse.
    let points: Vec<SpeedValue> = [
        (0.1, 0.500),
        (0.25, 0.523),
        (0.5, 0.564),
        (0.75, 0.496),
        (1.0, 0.401),
    ]
    .iter()
    .map(|&(v, d)| [v, 1.0, f64::NAN, d, f64::NAN])
    .collect();
    let laws = speed_laws(&points);
    assert!(
        matches!(&laws.delta, Law::Unconstrained(w) if w.contains("do not constrain")),
        "{:?}",
        laws.delta
    );
    // The paper's own points stay values (errors of a few per cent).
    let paper = speed_laws(&paper_points(&[1.0, 2.5, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0]));
    assert!(paper.delta.fitted().is_some() && paper.pm_dynamic.fitted().is_some());
}

#[test]
fn seed_errors_weight_the_fit_only_when_every_speed_has_a_positive_one() {
    let with =
        |e: f64| -> Vec<SpeedValue> { vec![[1.0, 2.0, 0.1, 0.3, 0.01], [2.0, 5.0, e, 0.2, e]] };
    assert_eq!(sigma(&with(0.2), 2), Some(vec![0.1, 0.2]));
    for e in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert_eq!(sigma(&with(e), 2), None, "{e}");
        assert_eq!(sigma(&with(e), 4), None, "{e}");
    }
}

#[test]
fn a_converged_fit_with_finite_values_but_an_error_not_finite_is_not_a_value() {
    let fit = |value: f64, error: f64| LawFit {
        law: [1.0, value],
        std_err: [0.1, error],
        correlation: Vec::new(),
        free: vec!["a", "b"],
        chi2_per_dof: 1.0,
        dof: 2,
        error_scale: 1.0,
        iterations: 3,
        converged: true,
    };
    let problem = |f: &LawFit<[f64; 2]>| problem_of(f, &f.law, &f.std_err);
    assert_eq!(problem(&fit(2.0, 0.1)), None);
    // Loose means beyond ten times max(|value|, 1): at exactly ten it is still a value.
    assert_eq!(problem(&fit(0.5, 10.0)), None);
    assert!(problem(&fit(0.5, 10.000001))
        .unwrap()
        .contains("do not constrain"));
    assert!(problem(&fit(-3.0, 30.000001))
        .unwrap()
        .contains("do not constrain"));
    for (value, error) in [(2.0, f64::NAN), (2.0, f64::INFINITY), (f64::NAN, 0.1)] {
        let why = problem(&fit(value, error)).unwrap();
        assert!(why.contains("not finite"), "{value} ± {error}: {why}");
    }
}

#[test]
fn negative_means_below_zero_by_more_than_two_standard_errors() {
    assert!(negative(-2.5, 1.0));
    assert!(!negative(-2.0, 1.0));
    assert!(!negative(-1.0, 1.0));
    assert!(!negative(0.5, 0.0));
}

#[test]
fn the_fewest_speeds_a_law_takes_give_a_value() {
    // Eq. 15 (a, b, c) and Eq. 17 from four speeds, Eq. 16 (b = 2) from three.
    let four = speed_laws(&paper_points(&[2.5, 5.0, 10.0, 20.0]));
    assert!(four.pm_dynamic.fitted().is_some(), "{:?}", four.pm_dynamic);
    assert!(four.delta.fitted().is_some(), "{:?}", four.delta);
    let three = speed_laws(&paper_points(&[2.5, 5.0, 10.0]));
    assert!(three.pm_square.fitted().is_some(), "{:?}", three.pm_square);
    assert!(matches!(&three.delta, Law::Unconstrained(w) if w.contains("at least 4")));
    let two = speed_laws(&paper_points(&[2.5, 5.0]));
    assert!(matches!(&two.pm_square, Law::Unconstrained(w) if w.contains("at least 3")));
}

#[test]
fn the_shift_is_on_its_bound_within_a_thousandth_of_the_slowest_speed() {
    assert!(shift_on_bound(1.0, -0.9995));
    assert!(!shift_on_bound(1.0, -0.998));
    // The margin scales with the slowest speed: 2 mm/s above −2.5 m/s is on the bound, 0.1
    // m/s is not, and a positive shift never is.
    assert!(shift_on_bound(2.5, -2.498));
    assert!(!shift_on_bound(2.5, -2.4));
    assert!(!shift_on_bound(2.5, -0.1));
    assert!(!shift_on_bound(2.5, 0.5));
    // Below 1 mm/s the margin stays 1 µm/s.
    assert!(shift_on_bound(1e-4, -1e-4 + 5e-7));
    assert!(!shift_on_bound(1e-4, -1e-4 + 2e-6));
    // Exactly the margin away is off the bound (v_min = 0: the margin 1e-3 · 1e-3 exactly).
    assert!(!shift_on_bound(0.0, 1e-3 * 1e-3));
}

/// p_m at `speeds` from p_m = a v² + b v + c [kPa] with a 5 % error and a ±3 % wobble
/// (so that the residuals, which scale the errors, are not zero).
fn slow_points(a: f64, b: f64, c: f64, speeds: &[f64]) -> Vec<SpeedValue> {
    speeds
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            let pm = (a * v * v + b * v + c) * if k % 2 == 0 { 1.03 } else { 0.97 };
            [v, pm, 0.05 * pm, 0.3, 0.01]
        })
        .collect()
}

#[test]
fn v_crit_needs_four_slow_speeds_and_a_minimum() {
    let four = speed_laws(&slow_points(18.3, -33.7, 16.7, &[0.1, 0.25, 0.5, 0.75]));
    assert!(four.v_crit.is_ok(), "{:?}", four.v_crit);
    let three = speed_laws(&slow_points(18.3, -33.7, 16.7, &[0.1, 0.5, 0.75]));
    assert!(matches!(&three.v_crit, Err(w) if w.contains("at least 4")));
    // p_m falling ever faster with v (a < 0): no minimum, no v_crit.
    let concave = speed_laws(&slow_points(-10.0, 2.0, 20.0, &[0.1, 0.25, 0.5, 0.75, 1.0]));
    assert!(concave.pm_slow.fitted().is_some());
    assert!(
        matches!(&concave.v_crit, Err(w) if w.contains("no minimum")),
        "{:?}",
        concave.v_crit
    );
}

#[test]
fn v_crit_error_is_the_fit_covariance_carried_through_minus_b_over_2a() {
    // Independent of the hand-written derivatives: the gradient of −b/(2a) by central
    // differences, contracted with the covariance of (a, b) built from the fit's errors
    // and correlation.
    let laws = speed_laws(&slow_points(
        18.3,
        -33.7,
        16.7,
        &[0.1, 0.25, 0.5, 0.75, 1.0],
    ));
    let f = laws.pm_slow.fitted().unwrap();
    let (_, err) = laws.v_crit.unwrap();
    let (a, b) = (f.law.a, f.law.b);
    let g = |a: f64, b: f64| -b / (2.0 * a);
    let (ha, hb) = (1e-6 * a.abs(), 1e-6 * b.abs());
    let grad = [
        (g(a + ha, b) - g(a - ha, b)) / (2.0 * ha),
        (g(a, b + hb) - g(a, b - hb)) / (2.0 * hb),
    ];
    let ia = f.free.iter().position(|n| *n == "a").unwrap();
    let ib = f.free.iter().position(|n| *n == "b").unwrap();
    let s = [f.std_err.a, f.std_err.b];
    let rho = f.correlation[ia][ib];
    assert!(
        rho.abs() > 0.5,
        "a and b of a quadratic are correlated: {rho}"
    );
    let var = (grad[0] * s[0]).powi(2)
        + (grad[1] * s[1]).powi(2)
        + 2.0 * rho * grad[0] * grad[1] * s[0] * s[1];
    assert!(
        (err - var.sqrt()).abs() < 1e-6 * err,
        "{err} vs {}",
        var.sqrt()
    );
}
