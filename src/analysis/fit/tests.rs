//! Tests of the Eq. 13 fit: known parameters recovered, errors, options and bad data.

use super::*;
use crate::rng::Rng;

pub(super) const GUETTLER: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.58,
    p_m: 16667.0,
    delta: 0.562,
};
const BLUM: Eq13 = Eq13 {
    phi1: 0.15,
    phi2: 0.33,
    p_m: 5600.0,
    delta: 0.33,
};

pub(super) fn logspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let (a, b) = (lo.log10(), hi.log10());
    (0..n)
        .map(|i| 10f64.powf(a + (b - a) * i as f64 / (n - 1) as f64))
        .collect()
}

#[test]
fn pinned_values() {
    let p = [1e2, 1e3, 1e4, 1e5, 1e6];
    let guettler = [0.1581, 0.1939, 0.3231, 0.4939, 0.5626];
    let blum = [0.1509, 0.1669, 0.2728, 0.3260, 0.3298];
    for (params, want) in [(GUETTLER, guettler), (BLUM, blum)] {
        for (&p, &want) in p.iter().zip(&want) {
            let got = params.phi(p);
            assert!((got - want).abs() <= 5e-5, "{params:?} at {p}: {got}");
        }
    }
}

#[test]
fn limits_and_inverse() {
    assert_eq!(GUETTLER.phi(0.0), 0.15);
    assert_eq!(GUETTLER.phi(1e300), 0.58);
    assert!((GUETTLER.phi(GUETTLER.p_m) - 0.365).abs() < 1e-15);
    assert!(GUETTLER.phi(-1.0).is_nan());
    for p in logspace(1.0, 1e7, 15) {
        let back = GUETTLER.pressure_at(GUETTLER.phi(p)).unwrap();
        assert!((back / p - 1.0).abs() < 1e-9, "{p} -> {back}");
    }
    for phi in [0.15, 0.58, 0.1, 0.7, f64::NAN] {
        assert_eq!(GUETTLER.pressure_at(phi), None, "{phi}");
    }
    let flat = Eq13 {
        phi2: 0.15,
        ..GUETTLER
    };
    assert_eq!(flat.pressure_at(0.15), None);
}

fn assert_recovers(truth: Eq13, fix1: bool, fix2: bool) {
    let p = logspace(1e2, 1e6, 21);
    let phi: Vec<f64> = p.iter().map(|&p| truth.phi(p)).collect();
    let opt = FitOptions {
        fix_phi1: fix1.then_some(truth.phi1),
        fix_phi2: fix2.then_some(truth.phi2),
        ..FitOptions::default()
    };
    let r = fit_eq13(&p, &phi, None, &opt).unwrap();
    let ctx = format!("{truth:?} fix=({fix1},{fix2}): {r:?}");
    assert!(r.converged, "{ctx}");
    assert!((r.params.phi1 - truth.phi1).abs() < 1e-9, "{ctx}");
    assert!((r.params.phi2 - truth.phi2).abs() < 1e-9, "{ctx}");
    assert!((r.params.p_m / truth.p_m - 1.0).abs() < 1e-8, "{ctx}");
    assert!((r.params.delta - truth.delta).abs() < 1e-9, "{ctx}");
    assert!(r.rss < 1e-24, "{ctx}");
    assert_eq!(r.free.len(), 4 - fix1 as usize - fix2 as usize);
    assert_eq!(r.dof, 21 - r.free.len());
    if fix1 {
        assert_eq!((r.params.phi1, r.std_err.phi1), (truth.phi1, 0.0));
    }
    if fix2 {
        assert_eq!((r.params.phi2, r.std_err.phi2), (truth.phi2, 0.0));
    }
}

#[test]
fn recovers_noise_free_parameters() {
    for truth in [GUETTLER, BLUM] {
        for (fix1, fix2) in [(false, false), (true, true), (true, false), (false, true)] {
            assert_recovers(truth, fix1, fix2);
        }
    }
}

#[test]
fn explicit_initial_guess_is_used() {
    let p = logspace(1e2, 1e6, 21);
    let phi: Vec<f64> = p.iter().map(|&p| BLUM.phi(p)).collect();
    let opt = FitOptions {
        initial: Some(Eq13 {
            phi1: 0.1,
            phi2: 0.4,
            p_m: 1e5,
            delta: 1.0,
        }),
        ..FitOptions::default()
    };
    let r = fit_eq13(&p, &phi, None, &opt).unwrap();
    assert!(r.converged);
    assert!((r.params.p_m / BLUM.p_m - 1.0).abs() < 1e-8, "{r:?}");
    let stuck = fit_eq13(
        &p,
        &phi,
        None,
        &FitOptions {
            max_iterations: 1,
            ..opt
        },
    )
    .unwrap();
    assert!(!stuck.converged);
    assert_eq!(stuck.iterations, 1);
}

#[test]
fn correlation_matrix_is_symmetric_with_unit_diagonal() {
    let p = logspace(1e2, 1e6, 21);
    let mut rng = Rng::new(7);
    let phi: Vec<f64> = p
        .iter()
        .map(|&p| GUETTLER.phi(p) + 0.005 * rng.normal())
        .collect();
    let r = fit_eq13(&p, &phi, None, &FitOptions::default()).unwrap();
    assert_eq!(r.free, ["phi1", "phi2", "log10_p_m", "delta"]);
    for i in 0..4 {
        assert!((r.correlation[i][i] - 1.0).abs() < 1e-12);
        for j in 0..4 {
            assert!((r.correlation[i][j] - r.correlation[j][i]).abs() < 1e-12);
            assert!(r.correlation[i][j].abs() <= 1.0 + 1e-12);
        }
    }
    let ln10 = std::f64::consts::LN_10;
    assert!((r.std_err.p_m - r.params.p_m * ln10 * r.std_err_log10_pm).abs() < 1e-9);
    assert!((r.chi2_per_dof - r.rss / r.dof as f64).abs() < 1e-18);
}

struct Coverage {
    /// Empirical sd of the estimates over reported mean error, per parameter.
    sd_over_err: [f64; 4],
    /// Fraction of fits whose 1σ interval holds the truth.
    within_1sigma: [f64; 4],
    mean_chi2_per_dof: f64,
}

fn monte_carlo(with_sigma: bool, draws: usize, seed: u64) -> Coverage {
    const NOISE: f64 = 0.005;
    let p = logspace(1e2, 1e6, 40);
    let sigma = vec![NOISE; p.len()];
    let truth = GUETTLER;
    let want = [truth.phi1, truth.phi2, truth.p_m.log10(), truth.delta];
    let mut rng = Rng::new(seed);
    let (mut sum, mut sum2, mut err, mut hits) = ([0.0; 4], [0.0; 4], [0.0; 4], [0usize; 4]);
    let mut chi2 = 0.0;
    for _ in 0..draws {
        let phi: Vec<f64> = p
            .iter()
            .map(|&p| truth.phi(p) + NOISE * rng.normal())
            .collect();
        let s = with_sigma.then_some(&sigma[..]);
        let r = fit_eq13(&p, &phi, s, &FitOptions::default()).unwrap();
        assert!(r.converged, "{r:?}");
        let got = [
            r.params.phi1,
            r.params.phi2,
            r.params.p_m.log10(),
            r.params.delta,
        ];
        let e = [
            r.std_err.phi1,
            r.std_err.phi2,
            r.std_err_log10_pm,
            r.std_err.delta,
        ];
        for j in 0..4 {
            sum[j] += got[j];
            sum2[j] += got[j] * got[j];
            err[j] += e[j];
            hits[j] += usize::from((got[j] - want[j]).abs() <= e[j]);
        }
        chi2 += r.chi2_per_dof;
    }
    let m = draws as f64;
    let mut c = Coverage {
        sd_over_err: [0.0; 4],
        within_1sigma: [0.0; 4],
        mean_chi2_per_dof: chi2 / m,
    };
    for j in 0..4 {
        let mean = sum[j] / m;
        let sd = ((sum2[j] - m * mean * mean) / (m - 1.0)).sqrt();
        c.sd_over_err[j] = sd / (err[j] / m);
        c.within_1sigma[j] = hits[j] as f64 / m;
    }
    c
}

#[test]
fn reported_errors_match_monte_carlo_scatter() {
    for (with_sigma, seed) in [(true, 1), (false, 2)] {
        let c = monte_carlo(with_sigma, 400, seed);
        println!(
            "sigma given: {with_sigma}; sd/err (phi1, phi2, log10_p_m, delta) = {:.3?}; \
             1-sigma coverage = {:.3?}; mean chi2/dof = {:.4e}",
            c.sd_over_err, c.within_1sigma, c.mean_chi2_per_dof
        );
        for (j, name) in NAMES.iter().enumerate() {
            assert!(
                (c.sd_over_err[j] - 1.0).abs() < 0.2,
                "{name}: sd/err = {}",
                c.sd_over_err[j]
            );
            assert!(
                (0.60..=0.76).contains(&c.within_1sigma[j]),
                "{name}: coverage {}",
                c.within_1sigma[j]
            );
        }
        // With σ given, χ²/dof should scatter about 1; without, it is s² ≈ σ².
        let expect = if with_sigma { 1.0 } else { 0.005f64.powi(2) };
        assert!((c.mean_chi2_per_dof / expect - 1.0).abs() < 0.05);
    }
}

#[test]
fn rejects_bad_input() {
    let p = logspace(1e2, 1e6, 8);
    let phi: Vec<f64> = p.iter().map(|&p| GUETTLER.phi(p)).collect();
    let opt = FitOptions::default();

    let mut bad = p.clone();
    bad[3] = 0.0;
    let e = fit_eq13(&bad, &phi, None, &opt).unwrap_err();
    assert_eq!(
        e,
        FitError::InvalidPoint {
            index: 3,
            pressure: 0.0,
            phi: phi[3]
        }
    );
    assert_eq!(
        e.to_string(),
        "point 3: pressure 0 Pa is not finite and positive"
    );
    bad[3] = -5.0;
    assert!(fit_eq13(&bad, &phi, None, &opt)
        .unwrap_err()
        .to_string()
        .contains("point 3: pressure -5 Pa"));
    bad[3] = f64::INFINITY;
    assert!(fit_eq13(&bad, &phi, None, &opt)
        .unwrap_err()
        .to_string()
        .contains("inf"));

    let mut bad_phi = phi.clone();
    bad_phi[5] = f64::NAN;
    let e = fit_eq13(&p, &bad_phi, None, &opt).unwrap_err();
    assert_eq!(e.to_string(), "point 5: filling factor NaN is not finite");

    let e = fit_eq13(&p, &phi[..7], None, &opt).unwrap_err();
    assert!(matches!(e, FitError::LengthMismatch { what: "phi", .. }));
    let e = fit_eq13(&p, &phi, Some(&[0.01; 3]), &opt).unwrap_err();
    assert!(matches!(e, FitError::LengthMismatch { what: "sigma", .. }));
    let mut sigma = vec![0.01; 8];
    sigma[2] = 0.0;
    let e = fit_eq13(&p, &phi, Some(&sigma), &opt).unwrap_err();
    assert_eq!(
        e,
        FitError::InvalidSigma {
            index: 2,
            sigma: 0.0
        }
    );

    let e = fit_eq13(&p[..4], &phi[..4], None, &opt).unwrap_err();
    assert_eq!(e, FitError::TooFewPoints { points: 4, free: 4 });
    assert!(e.to_string().contains("at least 5"));
    let fixed = FitOptions {
        fix_phi1: Some(0.15),
        fix_phi2: Some(0.58),
        ..opt
    };
    assert!(fit_eq13(&p[..3], &phi[..3], None, &fixed).is_ok());
    assert!(fit_eq13(&p[..2], &phi[..2], None, &fixed).is_err());
    assert!(fit_eq13(&[], &[], None, &opt).is_err());

    let e = fit_eq13(
        &p,
        &phi,
        None,
        &FitOptions {
            fix_phi1: Some(f64::NAN),
            ..opt
        },
    )
    .unwrap_err();
    assert!(matches!(
        e,
        FitError::InvalidOption {
            name: "fix_phi1",
            ..
        }
    ));
    let e = fit_eq13(
        &p,
        &phi,
        None,
        &FitOptions {
            initial: Some(Eq13 {
                delta: -0.5,
                ..GUETTLER
            }),
            ..opt
        },
    )
    .unwrap_err();
    assert!(matches!(
        e,
        FitError::InvalidOption {
            name: "initial.delta",
            ..
        }
    ));

    // All points at one pressure cannot locate the transition.
    let same = [1e4; 6];
    let e = fit_eq13(&same, &[0.2, 0.21, 0.19, 0.2, 0.22, 0.18], None, &opt).unwrap_err();
    assert_eq!(e, FitError::Singular);

    let boxed: Box<dyn Error> = Box::new(FitError::Singular);
    assert!(!boxed.to_string().is_empty());
}
