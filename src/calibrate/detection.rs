//! Detection limits: the smallest factor of each effect that data like the measured set
//! would show beyond noise, from the screened grid.

use super::effects::Effect;
use super::gap::{chi2_quantile_95, shift_chi2, PointNoise, Prediction};
use super::grid::Grid;
use super::measured::MeasuredSet;

/// The smallest factor, each way, that data made with it would show beyond noise against the
/// config's model at 95%: the χ² of the model against such data, the noise at its expected
/// value of one per curve, passes the 95% quantile of χ² with one degree per curve, i.e.
/// n + λ(f) > χ²₉₅(n) with λ the noise-free shift ([`shift_chi2`]). Found on the screened
/// grid (linear in ln factor); None where the searched range does not reach it. Where
/// nothing was simulated below factor 1 (the screen looks upwards), the lower limits mirror
/// the upper response, −Δφ(−u) = Δφ(u), down to the screen's lower end or the mirror of the
/// highest simulated factor, whichever is nearer: linear in ln factor, and marked so.
#[derive(Clone, Debug, PartialEq)]
pub struct DetectionLimit {
    pub effect: Effect,
    /// Below 1 and above 1, with the data as they are.
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    /// The searched range the limits were looked for in.
    pub searched: (f64, f64),
    /// The lower limits mirror the upper response (nothing simulated below factor 1).
    pub lower_mirrored: bool,
    /// The same with four times the simulated samples per curve (the simulation's noise
    /// variance / 4; four times the monomers per sample does about as much).
    pub lower_4x_samples: Option<f64>,
    pub upper_4x_samples: Option<f64>,
    /// The same with the measurement's uncertainty halved.
    pub lower_half_sigma: Option<f64>,
    pub upper_half_sigma: Option<f64>,
    /// Share of the noise variance (mean over compared points) from the simulated samples.
    pub simulated_share: f64,
}

impl DetectionLimit {
    /// The six limits as text, in the order lower, upper, lower and upper with 4× the
    /// samples, lower and upper with the measured σ halved.
    pub fn texts(&self) -> [String; 6] {
        let (lo, hi) = self.searched;
        let mirrored = if self.lower_mirrored {
            " (mirrored)"
        } else {
            ""
        };
        let lower = |limit| limit_text(limit, lo) + mirrored;
        [
            lower(self.lower),
            limit_text(self.upper, hi),
            lower(self.lower_4x_samples),
            limit_text(self.upper_4x_samples, hi),
            lower(self.lower_half_sigma),
            limit_text(self.upper_half_sigma, hi),
        ]
    }

    /// Whether a factor `f` lies within the limits (would pass as noise).
    pub fn hides(&self, f: f64) -> bool {
        if f >= 1.0 {
            self.upper.is_none_or(|u| f < u)
        } else {
            self.lower.is_none_or(|l| f > l)
        }
    }
}

/// Points per side of the detection-limit scan.
pub(super) const LIMIT_SCAN: usize = 400;

/// The detection limits of `grid`'s effect; `grid` must hold the config's own predictions at
/// u = 0 (the effects whose factor 1 changes the model have none).
pub fn detection_limit(m: &MeasuredSet, grid: &Grid) -> Option<DetectionLimit> {
    if !grid.effect.identity_at_one() {
        return None;
    }
    let reference = &grid.points.iter().find(|(u, _)| *u == 0.0)?.1;
    let n = reference.len();
    let threshold = chi2_quantile_95(n) - n as f64;
    let mirrored = grid.lower_unsearched();
    let (lo, hi) = if mirrored {
        // No further down than the mirror of the highest simulated factor.
        let hi = grid.ends().1;
        (grid.effect.range().0.ln().max(-hi), hi)
    } else {
        grid.ends()
    };
    let at = |u: f64| -> Vec<Prediction> {
        if u < 0.0 && mirrored {
            let up = grid.interpolate(-u);
            reference
                .iter()
                .zip(&up)
                .map(|(r, p)| Prediction::blend(r, p, -1.0))
                .collect()
        } else {
            grid.interpolate(u)
        }
    };
    let first = |end: f64, scale: (f64, f64)| -> Option<f64> {
        (1..=LIMIT_SCAN).find_map(|k| {
            let u = end * k as f64 / LIMIT_SCAN as f64;
            let shift: f64 = shift_chi2(m, reference, &at(u), scale).iter().sum();
            (shift > threshold).then(|| u.exp())
        })
    };
    let simulated_share = simulated_share(&super::gap::noise(m, reference));
    Some(DetectionLimit {
        effect: grid.effect,
        lower: first(lo, (1.0, 1.0)),
        upper: first(hi, (1.0, 1.0)),
        searched: (lo.exp(), hi.exp()),
        lower_mirrored: mirrored,
        lower_4x_samples: first(lo, (0.25, 1.0)),
        upper_4x_samples: first(hi, (0.25, 1.0)),
        lower_half_sigma: first(lo, (1.0, 0.25)),
        upper_half_sigma: first(hi, (1.0, 0.25)),
        simulated_share,
    })
}

/// Mean share of the noise variance from the simulated samples, over the compared points
/// that have a noise (a target pressure no seed reached has none).
fn simulated_share(noise: &[Vec<PointNoise>]) -> f64 {
    let shares: Vec<f64> = noise
        .iter()
        .flatten()
        .map(|p| p.simulated / (p.simulated + p.measured))
        .filter(|s| s.is_finite())
        .collect();
    shares.iter().sum::<f64>() / shares.len().max(1) as f64
}

/// "x0.42", or "beyond x0.125" when the searched range holds no detectable factor.
pub fn limit_text(limit: Option<f64>, end: f64) -> String {
    match limit {
        Some(f) => format!("x{}", short_factor(f)),
        None => format!("not within x{}", short_factor(end)),
    }
}

fn short_factor(f: f64) -> String {
    if (0.01..1000.0).contains(&f) {
        format!("{f:.3}")
    } else {
        format!("{f:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_simulated_share_skips_points_without_a_noise() {
        let point = |simulated, measured| PointNoise {
            simulated,
            measured,
        };
        // 1/4 and 3/4 average to 1/2; an unreached target (NaN) and a noiseless point (0/0)
        // are left out instead of turning the mean into NaN.
        let noise = vec![
            vec![point(1.0, 3.0), point(f64::NAN, 1.0)],
            vec![point(3.0, 1.0), point(0.0, 0.0)],
        ];
        assert_eq!(simulated_share(&noise), 0.5);
        assert_eq!(simulated_share(&[]), 0.0);
    }
}
