//! Weighted nonlinear least squares in up to four parameters by Marquardt's damped
//! Gauss–Newton iteration, shared by the Eq. 13 fit and the speed laws.

use super::linalg::{invert_spd, solve_spd, Mat};

/// Relative step below which the iteration counts as converged.
const XTOL: f64 = 1e-10;

/// A model's value and gradient in θ at abscissa x.
pub(in crate::analysis) type Model<'a> = &'a dyn Fn(&[f64; 4], f64) -> (f64, [f64; 4]);

/// Data (x, y) with weights w = 1/σ², a model and its domain.
pub(in crate::analysis) struct Problem<'a> {
    pub x: &'a [f64],
    pub y: &'a [f64],
    pub w: &'a [f64],
    pub model: Model<'a>,
    /// Whether a trial θ lies in the model's domain; steps outside are refused.
    pub admissible: &'a dyn Fn(&[f64; 4]) -> bool,
}

impl Problem<'_> {
    pub fn chi2(&self, theta: &[f64; 4]) -> f64 {
        self.x
            .iter()
            .zip(self.y)
            .zip(self.w)
            .map(|((&x, &y), &w)| w * (y - (self.model)(theta, x).0).powi(2))
            .sum()
    }

    /// Σ(yᵢ − f(xᵢ))², unweighted.
    pub fn rss(&self, theta: &[f64; 4]) -> f64 {
        self.x
            .iter()
            .zip(self.y)
            .map(|(&x, &y)| (y - (self.model)(theta, x).0).powi(2))
            .sum()
    }

    /// JᵀWJ and JᵀWr over the free parameters `idx`.
    pub fn normal_equations(&self, theta: &[f64; 4], idx: &[usize]) -> (Mat, [f64; 4]) {
        let mut a = [[0.0; 4]; 4];
        let mut g = [0.0; 4];
        for ((&x, &y), &w) in self.x.iter().zip(self.y).zip(self.w) {
            let (f, grad) = (self.model)(theta, x);
            let r = y - f;
            for (i, &pi) in idx.iter().enumerate() {
                g[i] += w * grad[pi] * r;
                for (j, &pj) in idx.iter().enumerate() {
                    a[i][j] += w * grad[pi] * grad[pj];
                }
            }
        }
        (a, g)
    }

    /// (JᵀWJ)⁻¹ over the free parameters at θ, unscaled; `None` if singular.
    pub fn covariance(&self, theta: &[f64; 4], idx: &[usize]) -> Option<Mat> {
        let (a, _) = self.normal_equations(theta, idx);
        invert_spd(&a, idx.len())
    }

    /// Marquardt's damped Gauss–Newton iteration from `theta` over the free parameters
    /// `idx`: (θ, iterations, converged).
    pub fn levenberg_marquardt(
        &self,
        mut theta: [f64; 4],
        idx: &[usize],
        max_iterations: usize,
    ) -> ([f64; 4], usize, bool) {
        let k = idx.len();
        let mut chi2 = self.chi2(&theta);
        let mut lambda = 1e-3;
        for iteration in 1..=max_iterations {
            let (a, g) = self.normal_equations(&theta, idx);
            let max_diag = (0..k).map(|i| a[i][i]).fold(0.0, f64::max);
            let mut accepted = None;
            while lambda <= 1e16 {
                let mut damped = a;
                for (i, row) in damped.iter_mut().enumerate().take(k) {
                    row[i] += lambda * a[i][i].max(1e-12 * max_diag).max(f64::MIN_POSITIVE);
                }
                if let Some(step) = solve_spd(&damped, &g, k) {
                    let mut trial = theta;
                    for (s, &j) in step.iter().zip(idx) {
                        trial[j] += s;
                    }
                    if (self.admissible)(&trial) && trial.iter().all(|v| v.is_finite()) {
                        let c = self.chi2(&trial);
                        if c <= chi2 {
                            accepted = Some((trial, c, step));
                            break;
                        }
                    }
                }
                lambda *= 10.0;
            }
            // Not even a tiny gradient step lowers χ²: stationary to rounding.
            let Some((trial, c, step)) = accepted else {
                return (theta, iteration, true);
            };
            lambda = (lambda * 0.1).max(1e-12);
            let small_step = step
                .iter()
                .zip(idx)
                .all(|(s, &j)| s.abs() <= XTOL * (theta[j].abs() + XTOL));
            theta = trial;
            chi2 = c;
            if small_step || chi2 == 0.0 {
                return (theta, iteration, true);
            }
        }
        (theta, max_iterations, false)
    }
}
