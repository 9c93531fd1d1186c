//! Tests of the regime finder on curves built piecewise with known breakpoints.

use super::*;
use crate::analysis::fit::Eq13;
use crate::rng::Rng;

const ROWS: usize = 300;
/// First plateau row and first steep row of the synthetic curve.
const K1: usize = 12;
const K2: usize = 255;

/// φ of a box compressed at 7 m/s from 60 µm, rows 20 ns apart: φ₀·h₀/(h₀ − v t).
fn phi(i: usize) -> f64 {
    let h = 60e-6 - 7.0 * 20e-9 * i as f64;
    0.15 * 60e-6 / h
}

/// log₁₀P: a rise of 0.18 dex per row, a plateau rising 0.15 dex in all, a rise of 0.06 dex
/// per row; continuous, with the corners half-way between rows K1 − 1 and K1 and between
/// K2 − 1 and K2, so that no row lies on two pieces.
fn log_p(i: usize) -> f64 {
    let x = i as f64;
    let (c1, c2) = (K1 as f64 - 0.5, K2 as f64 - 0.5);
    let plateau = |x: f64| 3.7 + 0.15 * (x - c1) / (c2 - c1);
    if x < c1 {
        3.7 - 0.18 * (c1 - x)
    } else if x < c2 {
        plateau(x)
    } else {
        plateau(c2) + 0.06 * (x - c2)
    }
}

fn curve(noise: f64, rng: &mut Rng) -> Vec<(f64, f64)> {
    (0..ROWS)
        .map(|i| (10f64.powf(log_p(i) + noise * rng.normal()), phi(i)))
        .collect()
}

#[test]
fn exact_piecewise_curve_gives_its_breakpoints() {
    let c = curve(0.0, &mut Rng::new(0));
    let r = find_regimes(&c, &RegimeOptions::default()).unwrap();
    assert_eq!((r.plateau_start, r.steep_start), (K1, K2), "{r:?}");
    assert!(
        (r.critical_pressure.log10() - log_p(K1)).abs() < 1e-9,
        "{r:?}"
    );
    assert!(
        (r.plateau_end_pressure.log10() - log_p(K2 - 1)).abs() < 1e-9,
        "{r:?}"
    );
    assert_eq!(r.phi_at_plateau_start, phi(K1));
    assert_eq!(r.phi_at_steep_start, phi(K2));
    assert!((r.phi_rise_before_critical - (phi(K1) - phi(0))).abs() < 1e-15);
    assert!(r.three_regimes, "{r:?}");
    // The plateau's median pressure lies mid-way up its 0.15 dex.
    assert!((r.plateau_pressure.log10() - 3.775).abs() < 0.002, "{r:?}");

    // Rows without a pressure (the row before the first step, no wall contact yet) are
    // skipped and the indices still point into the curve as given.
    let mut padded = vec![(f64::NAN, 0.15), (0.0, 0.15)];
    padded.extend(&c);
    let r = find_regimes(&padded, &RegimeOptions::default()).unwrap();
    assert_eq!((r.plateau_start, r.steep_start), (K1 + 2, K2 + 2));
}

#[test]
fn noisy_curves_give_their_breakpoints_within_one_row() {
    // 0.02 dex of noise; a row moved across a corner costs its slope change squared
    // (0.18² and 0.06² against 4·10⁻⁴ per row of noise), so the corners stay sharp.
    let mut rng = Rng::new(31);
    for draw in 0..20 {
        let c = curve(0.02, &mut rng);
        let r = find_regimes(&c, &RegimeOptions::default()).unwrap();
        assert!(r.plateau_start.abs_diff(K1) <= 1, "draw {draw}: {r:?}");
        assert!(r.steep_start.abs_diff(K2) <= 1, "draw {draw}: {r:?}");
        assert!(
            (r.critical_pressure.log10() - 3.7).abs() < 0.03,
            "draw {draw}: {r:?}"
        );
        assert!(r.three_regimes, "draw {draw}: {r:?}");
    }
}

#[test]
fn smooth_quasi_static_curve_is_not_three_regimes() {
    // The Güttler curve followed at the same φ(t): log₁₀P rises smoothly, no plateau.
    let e = Eq13 {
        phi1: 0.15,
        phi2: 0.58,
        p_m: 16667.0,
        delta: 0.562,
    };
    let c: Vec<(f64, f64)> = (1..ROWS)
        .map(|i| (e.pressure_at(phi(i)).unwrap(), phi(i)))
        .collect();
    let r = find_regimes(&c, &RegimeOptions::default()).unwrap();
    println!("{r:?}");
    assert!(!r.three_regimes, "{r:?}");
    // Rejected by the plateau's slope alone, whatever φ does before it.
    let lax = RegimeOptions {
        phi_tol: 1.0,
        ..RegimeOptions::default()
    };
    assert!(!find_regimes(&c, &lax).unwrap().three_regimes);

    // A pressure jump at constant φ is compaction-free; with φ rising fast through the
    // first piece instead, regime (i) does not hold.
    let fast: Vec<(f64, f64)> = (0..ROWS)
        .map(|i| {
            (
                10f64.powf(log_p(i)),
                phi(i) + if i < K1 { 0.003 * i as f64 } else { 0.036 },
            )
        })
        .collect();
    let r = find_regimes(&fast, &RegimeOptions::default()).unwrap();
    assert_eq!((r.plateau_start, r.steep_start), (K1, K2));
    assert!(
        r.phi_rise_before_critical > 0.01 && !r.three_regimes,
        "{r:?}"
    );
}

#[test]
fn too_short_curves_have_no_regimes() {
    let c = curve(0.0, &mut Rng::new(0));
    // Regime (i) may lie before the first row; three rows of each other regime at least.
    assert!(find_regimes(&c[..5], &RegimeOptions::default()).is_none());
    assert!(find_regimes(&c[..6], &RegimeOptions::default()).is_some());
}

#[test]
fn regimes_of_runs_reads_each_run_in_time_order_and_summarises_the_seeds() {
    // Three noisy dynamic runs with corners at K1, K2 and two smooth quasi-static ones.
    let mut rng = Rng::new(77);
    let dynamic: Vec<Vec<(f64, f64)>> = (0..3).map(|_| curve(0.02, &mut rng)).collect();
    let refs: Vec<&[(f64, f64)]> = dynamic.iter().map(|c| c.as_slice()).collect();
    let s = regimes_of_runs(&refs, &RegimeOptions::default());
    assert_eq!((s.runs, s.three_regimes), (3, 3));
    let critical = s.critical_pa.unwrap();
    assert!((critical.mean.log10() - 3.7).abs() < 0.03, "{s:?}");
    // The plateau's median lies half-way up its 0.15 dex rise.
    let plateau = s.plateau_pa.unwrap();
    assert!((plateau.mean.log10() - 3.775).abs() < 0.03, "{s:?}");
    let steep = s.phi_steep.unwrap();
    assert!(
        (steep.mean - phi(K2)).abs() < 2.0 * (phi(K2 + 1) - phi(K2)),
        "{s:?}"
    );

    let e = Eq13 {
        phi1: 0.15,
        phi2: 0.58,
        p_m: 16667.0,
        delta: 0.562,
    };
    let smooth: Vec<(f64, f64)> = (1..ROWS)
        .map(|i| (e.pressure_at(phi(i)).unwrap(), phi(i)))
        .collect();
    let s = regimes_of_runs(&[&smooth, &smooth], &RegimeOptions::default());
    assert_eq!((s.runs, s.three_regimes), (2, 0));
    assert!(s.critical_pa.is_none());
}

#[test]
fn an_impact_spike_decaying_into_the_plateau_is_not_regime_i() {
    // At 15–25 m/s the first row already holds the impact's pressure, which decays by half a
    // decade before the plateau rises again; the corner to the steep rise stays at K2.
    let decay = |i: usize| 5.2 - 0.02 * i.min(25) as f64 + 0.002 * i.saturating_sub(25) as f64;
    let mut c = vec![(f64::NAN, 0.15)];
    let top = decay(K2 - 1);
    c.extend((1..ROWS).map(|i| {
        let lp = if i < K2 {
            decay(i)
        } else {
            top + 0.06 * (i - K2 + 1) as f64
        };
        (10f64.powf(lp), phi(i))
    }));
    let r = find_regimes(&c, &RegimeOptions::default()).unwrap();
    assert_eq!(r.plateau_start, 1, "{r:?}");
    assert!(r.steep_start.abs_diff(K2) <= 1, "{r:?}");
    assert!(r.three_regimes, "{r:?}");
    assert!((r.phi_rise_before_critical - (phi(1) - 0.15)).abs() < 1e-12);
}

/// A 5 m/s run whose first row already carries the plateau pressure (regime (i) shorter than
/// a row, as at 5 m/s seed 3 of the paper tier) and whose steep rise curves upwards: rows
/// 30 ns apart, log₁₀P rising 0.1 dex over the plateau's `KNEE` rows, then by 0.06 dex a
/// row plus 0.002 dex times the square of the rows since the knee.
fn knee_curve() -> Vec<(f64, f64)> {
    const KNEE: usize = 250;
    (0..300)
        .map(|i| {
            let phi = 0.15 * 60e-6 / (60e-6 - 5.0 * 30e-9 * i as f64);
            let log_p = if i < KNEE {
                4.0 + 0.1 * i as f64 / KNEE as f64
            } else {
                {
                    let k = (i - KNEE) as f64;
                    4.1 + 0.06 * k + 0.002 * k * k
                }
            };
            (10f64.powf(log_p), phi)
        })
        .collect()
}

#[test]
fn a_regime_i_shorter_than_a_row_puts_the_plateau_first_not_the_knee() {
    let c = knee_curve();
    let r = find_regimes(&c, &RegimeOptions::default()).unwrap();
    // The plateau starts at the first row (its φ is the start's), the steep rise at the knee
    // or a few rows into the rise's curved foot (row 260: 1.2 dex above the plateau), not
    // at the knee's far side (regime (i) = the whole plateau).
    assert!(r.plateau_start <= 1, "{r:?}");
    assert!((250..=260).contains(&r.steep_start), "{r:?}");
    assert!(r.three_regimes, "{r:?}");
}

#[test]
fn a_short_plateau_after_a_long_regime_i_is_found() {
    // 30 rows of regime (i) rising 0.1 dex a row at constant φ, a plateau of 10 rows, a
    // steep rise of 30 rows, each piece off the line of the one before: the plateau is
    // shorter than regime (i) and still found.
    let c: Vec<(f64, f64)> = (0..70)
        .map(|i| {
            let log_p = match i {
                0..30 => 1.0 + 0.1 * i as f64,
                30..40 => 4.05 + 0.001 * (i - 30) as f64,
                _ => 4.2 + 0.1 * (i - 40) as f64,
            };
            let phi = 0.15 + if i < 30 { 0.0 } else { 0.005 * (i - 29) as f64 };
            (10f64.powf(log_p), phi)
        })
        .collect();
    let r = find_regimes(&c, &RegimeOptions::default()).unwrap();
    assert_eq!((r.plateau_start, r.steep_start), (30, 40), "{r:?}");
    assert!(r.three_regimes, "{r:?}");
}
