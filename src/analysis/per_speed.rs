//! Eq. 13 fitted to the curve of one wall speed twice: with φ₁ and φ₂ held (as the paper
//! does, at the Güttler values for omnidirectional compression) and with all four free.

use super::fit::{fit_eq13, FitError, FitOptions, FitResult};

/// φ₁ of the Güttler et al. (2009) fit, at which the paper holds it for every speed.
pub const GUETTLER_PHI1: f64 = 0.15;
/// φ₂ of the Güttler et al. (2009) fit.
pub const GUETTLER_PHI2: f64 = 0.58;

/// Both fits of one speed. Either may fail on its own: a dynamic curve that stops short of
/// the upper plateau often cannot pin φ₂ free, while the fixed fit still works.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedFit {
    /// φ₁, φ₂ held; p_m and Δ fitted, with errors.
    pub fixed: Result<FitResult, FitError>,
    /// All four parameters fitted, with errors.
    pub free: Result<FitResult, FitError>,
}

/// The points of `curve` with P > 0 and their σ (given for all points of `curve`, as for a
/// seed average's standard errors).
fn usable(curve: &[(f64, f64)], sigma: Option<&[f64]>) -> (Vec<f64>, Vec<f64>, Option<Vec<f64>>) {
    let keep: Vec<usize> = (0..curve.len()).filter(|&i| curve[i].0 > 0.0).collect();
    let p = keep.iter().map(|&i| curve[i].0).collect();
    let phi = keep.iter().map(|&i| curve[i].1).collect();
    // A σ of the wrong length is passed on whole, for fit_eq13 to report.
    let s = sigma.map(|s| {
        if s.len() == curve.len() {
            keep.iter().map(|&i| s[i]).collect()
        } else {
            s.to_vec()
        }
    });
    (p, phi, s)
}

fn fit_points(
    curve: &[(f64, f64)],
    sigma: Option<&[f64]>,
    fix: Option<(f64, f64)>,
) -> Result<FitResult, FitError> {
    let (p, phi, s) = usable(curve, sigma);
    let opt = FitOptions {
        fix_phi1: fix.map(|f| f.0),
        fix_phi2: fix.map(|f| f.1),
        ..FitOptions::default()
    };
    fit_eq13(&p, &phi, s.as_deref(), &opt)
}

/// Eq. 13 with φ₁, φ₂ held at `phi1`, `phi2`, fitted to the points (P [Pa], φ) of `curve`
/// (pressures ≤ 0 are left out). `sigma`, when given, holds one-sigma errors of φ for every
/// point of `curve`; without it the residual scatter scales the errors.
pub fn fit_fixed(
    curve: &[(f64, f64)],
    sigma: Option<&[f64]>,
    phi1: f64,
    phi2: f64,
) -> Result<FitResult, FitError> {
    fit_points(curve, sigma, Some((phi1, phi2)))
}

/// Both fits of one speed: [`fit_fixed`] and all four parameters free.
pub fn fit_speed(curve: &[(f64, f64)], sigma: Option<&[f64]>, phi1: f64, phi2: f64) -> SpeedFit {
    SpeedFit {
        fixed: fit_fixed(curve, sigma, phi1, phi2),
        free: fit_points(curve, sigma, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::fit::Eq13;
    use crate::analysis::speed_laws::{PAPER_DELTA, PAPER_PM_DYNAMIC};
    use crate::rng::Rng;

    /// Eq. 13 at 7 m/s by the paper's laws.
    fn at_7_m_s() -> Eq13 {
        Eq13 {
            phi1: GUETTLER_PHI1,
            phi2: GUETTLER_PHI2,
            p_m: PAPER_PM_DYNAMIC.eval(7.0) * 1e3,
            delta: PAPER_DELTA.eval(7.0),
        }
    }

    fn curve(truth: &Eq13, n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let p = 10f64.powf(3.0 + 3.0 * i as f64 / (n - 1) as f64);
                (p, truth.phi(p))
            })
            .collect()
    }

    #[test]
    fn both_fits_recover_exact_curves() {
        let truth = at_7_m_s();
        let mut c = curve(&truth, 40);
        c.insert(0, (0.0, 0.15));
        let f = fit_speed(&c, None, GUETTLER_PHI1, GUETTLER_PHI2);
        for r in [f.fixed.unwrap(), f.free.unwrap()] {
            assert!((r.params.p_m / truth.p_m - 1.0).abs() < 1e-8, "{r:?}");
            assert!((r.params.delta - truth.delta).abs() < 1e-9, "{r:?}");
            assert!((r.params.phi2 - truth.phi2).abs() < 1e-9, "{r:?}");
        }
        // Held at other values, the fixed fit reports them untouched.
        let f = fit_speed(&c, None, 0.14, 0.6);
        let r = f.fixed.unwrap();
        assert_eq!((r.params.phi1, r.params.phi2), (0.14, 0.6));
        assert_eq!(r.free, ["log10_p_m", "delta"]);
        assert!(r.rss > 1e-6);
    }

    #[test]
    fn fixed_fit_errors_match_monte_carlo_scatter() {
        // 300 noisy copies; see speed_laws::tests for the tolerances' derivation.
        const NOISE: f64 = 0.01;
        const DRAWS: usize = 300;
        let truth = at_7_m_s();
        let exact = curve(&truth, 30);
        let sigma = vec![NOISE; exact.len()];
        let mut rng = Rng::new(17);
        let want = [truth.p_m.log10(), truth.delta];
        let (mut sum, mut sum2, mut err) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        for _ in 0..DRAWS {
            let noisy: Vec<(f64, f64)> = exact
                .iter()
                .map(|&(p, phi)| (p, phi + NOISE * rng.normal()))
                .collect();
            let r = fit_fixed(&noisy, Some(&sigma), GUETTLER_PHI1, GUETTLER_PHI2).unwrap();
            let got = [r.params.p_m.log10(), r.params.delta];
            let e = [r.std_err_log10_pm, r.std_err.delta];
            for j in 0..2 {
                sum[j] += got[j];
                sum2[j] += got[j] * got[j];
                err[j] += e[j];
            }
        }
        let m = DRAWS as f64;
        for j in 0..2 {
            let mean = sum[j] / m;
            let sd = ((sum2[j] - m * mean * mean) / (m - 1.0)).sqrt();
            let ratio = sd / (err[j] / m);
            assert!((ratio - 1.0).abs() < 0.2, "param {j}: sd/err {ratio}");
            assert!(
                (mean - want[j]).abs() < 4.0 * sd / m.sqrt(),
                "param {j}: {mean}"
            );
        }
    }
}
