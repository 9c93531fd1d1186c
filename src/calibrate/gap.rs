//! The gap between simulation and measurement: per curve the RMS difference of φ at
//! log-spaced pressures (or of the sticking velocity), its noise from sample-to-sample scatter
//! and the measurement's own uncertainty, and where along the curve it sits.
//!
//! Sign convention: Δφ = φ_sim − φ_meas at the same pressure. Δφ > 0 means the simulated
//! sample is denser at that pressure, i.e. the model is too soft.

use super::measured::{log_spaced, MeasuredSet};

/// Pressures per compression curve at which the gap is measured.
pub const TARGETS: usize = 12;

/// What the simulation predicts for one measured curve.
#[derive(Clone, Debug, PartialEq)]
pub enum Prediction {
    /// Per target pressure: mean φ over seeds (NaN where a seed never reached it) and the
    /// scatter between seeds (sample standard deviation), with the number of seeds.
    Compression {
        phi: Vec<f64>,
        scatter: Vec<f64>,
        seeds: usize,
    },
    /// Sticking threshold [m/s] and its bisection half-width [m/s].
    Sticking { velocity: f64, resolution: f64 },
}

impl Prediction {
    /// From per-seed φ at the targets.
    pub fn from_seeds(per_seed: &[Vec<f64>]) -> Prediction {
        let n = per_seed.len();
        let k = per_seed.first().map_or(0, |v| v.len());
        let mut phi = vec![f64::NAN; k];
        let mut scatter = vec![f64::NAN; k];
        for j in 0..k {
            let v: Vec<f64> = per_seed.iter().map(|s| s[j]).collect();
            if v.iter().all(|x| x.is_finite()) {
                let mean = v.iter().sum::<f64>() / n as f64;
                phi[j] = mean;
                scatter[j] = if n > 1 {
                    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
                } else {
                    0.0
                };
            }
        }
        Prediction::Compression {
            phi,
            scatter,
            seeds: n,
        }
    }

    /// Linear blend (1 − t) a + t b of two predictions of the same curve (for the 1-D fits;
    /// sticking speeds blend in log).
    pub fn blend(a: &Prediction, b: &Prediction, t: f64) -> Prediction {
        let mix = |x: f64, y: f64| x + t * (y - x);
        match (a, b) {
            (
                Prediction::Compression {
                    phi: pa,
                    scatter: sa,
                    seeds,
                },
                Prediction::Compression {
                    phi: pb,
                    scatter: sb,
                    ..
                },
            ) => Prediction::Compression {
                phi: pa.iter().zip(pb).map(|(&x, &y)| mix(x, y)).collect(),
                scatter: sa.iter().zip(sb).map(|(&x, &y)| mix(x, y)).collect(),
                seeds: *seeds,
            },
            (
                Prediction::Sticking {
                    velocity: va,
                    resolution: ra,
                },
                Prediction::Sticking {
                    velocity: vb,
                    resolution: rb,
                },
            ) => Prediction::Sticking {
                velocity: mix(va.ln(), vb.ln()).exp(),
                resolution: mix(*ra, *rb),
            },
            _ => panic!("blending predictions of different curves"),
        }
    }
}

/// Target pressures of every compression curve of `m`, in order.
pub fn targets(m: &MeasuredSet) -> Vec<Vec<f64>> {
    m.compression
        .iter()
        .map(|c| {
            let (lo, hi) = c.pressure_range();
            log_spaced(lo, hi, TARGETS)
        })
        .collect()
}

/// How one part of a curve compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    WithinNoise,
    /// Simulation denser at the same pressure (or sticking too slowly).
    TooSoft,
    /// Simulation less dense at the same pressure (or sticking too fast).
    TooStiff,
    /// Beyond noise, but too soft in one part and too stiff in another.
    Mixed,
}

impl Verdict {
    fn of(mean: f64, sigma: f64) -> Verdict {
        if mean.abs() <= 2.0 * sigma {
            Verdict::WithinNoise
        } else if mean > 0.0 {
            Verdict::TooSoft
        } else {
            Verdict::TooStiff
        }
    }

    pub fn text(self) -> &'static str {
        match self {
            Verdict::WithinNoise => "within noise",
            Verdict::TooSoft => "too soft (simulation denser)",
            Verdict::TooStiff => "too stiff (simulation less dense)",
            Verdict::Mixed => "differs in shape (see the bands)",
        }
    }
}

/// One third of a compression curve's pressure range.
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    pub p_lo: f64,
    pub p_hi: f64,
    /// Mean Δφ over the band's covered pressures.
    pub mean: f64,
    /// Mean 1σ noise there.
    pub sigma: f64,
    pub verdict: Verdict,
}

#[derive(Clone, Debug, PartialEq)]
pub struct CurveGap {
    pub name: String,
    /// Per target: Δφ (NaN if the simulation did not reach that pressure) and its 1σ noise;
    /// for sticking one entry, v_sim − v_meas [m/s].
    pub residual: Vec<f64>,
    pub sigma: Vec<f64>,
    /// RMS of the residuals (φ, or m/s for sticking).
    pub rms: f64,
    /// RMS of the noise.
    pub noise: f64,
    /// Mean of (Δ/σ)² over covered points: about 1 when the model fits within noise.
    pub chi2: f64,
    pub covered: usize,
    pub bands: Vec<Band>,
    pub verdict: Verdict,
}

/// The whole data set against one model.
#[derive(Clone, Debug, PartialEq)]
pub struct Gap {
    pub curves: Vec<CurveGap>,
    /// Σ over curves of each curve's χ²: the points of one curve are strongly correlated, so
    /// each curve counts as one measurement and χ² has one degree of freedom per curve.
    pub chi2: f64,
    /// 95% quantile of χ² with that many degrees of freedom.
    pub threshold: f64,
}

impl Gap {
    /// The model agrees with the data within sample-to-sample and measurement noise.
    pub fn within_noise(&self) -> bool {
        self.chi2 <= self.threshold
    }
}

/// The noise of one compared point, in its two parts: the simulation's (sample-to-sample
/// scatter over the seeds, or the sticking bisection's half-width) and the measurement's,
/// both as variances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointNoise {
    pub simulated: f64,
    pub measured: f64,
}

impl PointNoise {
    pub fn sigma(self) -> f64 {
        (self.simulated + self.measured).sqrt()
    }

    /// The variance if the simulation's part were `simulated` times and the measurement's
    /// `measured` times what it is (what-if: more seeds, a tighter measurement).
    pub fn scaled_variance(self, simulated: f64, measured: f64) -> f64 {
        simulated * self.simulated + measured * self.measured
    }
}

/// Per curve of `m` (compression first, then sticking) and per compared point: the noise of
/// comparing `predictions` with the data.
pub fn noise(m: &MeasuredSet, predictions: &[Prediction]) -> Vec<Vec<PointNoise>> {
    let targets = targets(m);
    let mut all = Vec::new();
    for ((curve, p), prediction) in m.compression.iter().zip(&targets).zip(predictions) {
        let Prediction::Compression { scatter, seeds, .. } = prediction else {
            panic!("prediction order")
        };
        // Per-pressure scatter of a few seeds is itself noisy: shrink it halfway towards the
        // curve's pooled scatter.
        let finite: Vec<f64> = scatter.iter().copied().filter(|s| s.is_finite()).collect();
        let pooled =
            (finite.iter().map(|s| s * s).sum::<f64>() / finite.len().max(1) as f64).sqrt();
        all.push(
            p.iter()
                .enumerate()
                .map(|(k, &pk)| {
                    let (_, measured_sigma) = curve.at(pk);
                    let s2 = 0.5 * (scatter[k].powi(2) + pooled * pooled);
                    PointNoise {
                        simulated: s2 / *seeds as f64,
                        measured: measured_sigma * measured_sigma,
                    }
                })
                .collect(),
        );
    }
    for (s, prediction) in m.sticking.iter().zip(&predictions[m.compression.len()..]) {
        let Prediction::Sticking { resolution, .. } = prediction else {
            panic!("prediction order")
        };
        all.push(vec![PointNoise {
            simulated: resolution * resolution,
            measured: s.sigma * s.sigma,
        }]);
    }
    all
}

/// The simulated values of every curve at its compared points (φ at the target pressures,
/// or the sticking velocity in m/s).
pub fn values(prediction: &Prediction) -> Vec<f64> {
    match prediction {
        Prediction::Compression { phi, .. } => phi.clone(),
        Prediction::Sticking { velocity, .. } => vec![*velocity],
    }
}

/// Per curve: how far `changed` lies from `reference` in units of the noise of comparing
/// `reference` with the data, mean of (Δ/σ)² over the points both cover (the χ² that data made
/// by `changed` would show against `reference`, noise aside). `scale` multiplies the
/// simulation's and the measurement's noise variance (1, 1 for the data as they are). A curve
/// neither covers counts as 0.
pub fn shift_chi2(
    m: &MeasuredSet,
    reference: &[Prediction],
    changed: &[Prediction],
    scale: (f64, f64),
) -> Vec<f64> {
    noise(m, reference)
        .iter()
        .zip(reference.iter().zip(changed))
        .map(|(noise, (r, c))| {
            let (r, c) = (values(r), values(c));
            let terms: Vec<f64> = noise
                .iter()
                .zip(r.iter().zip(&c))
                .filter(|(_, (a, b))| a.is_finite() && b.is_finite())
                .map(|(n, (a, b))| (b - a).powi(2) / n.scaled_variance(scale.0, scale.1))
                .collect();
            terms.iter().sum::<f64>() / terms.len().max(1) as f64
        })
        .collect()
}

/// The gap of `predictions` (compression curves first, then sticking, as in `m`).
pub fn gap(m: &MeasuredSet, predictions: &[Prediction]) -> Gap {
    let targets = targets(m);
    let noise = noise(m, predictions);
    let mut curves = Vec::new();
    for (((curve, p), prediction), noise) in m
        .compression
        .iter()
        .zip(&targets)
        .zip(predictions)
        .zip(&noise)
    {
        let Prediction::Compression { phi, .. } = prediction else {
            panic!("prediction order")
        };
        let mut residual = Vec::new();
        let mut sigma = Vec::new();
        for (k, &pk) in p.iter().enumerate() {
            let (measured, _) = curve.at(pk);
            residual.push(phi[k] - measured);
            sigma.push(noise[k].sigma());
        }
        let bands = (0..3)
            .map(|b| {
                let range = b * TARGETS / 3..(b + 1) * TARGETS / 3;
                let covered: Vec<usize> =
                    range.clone().filter(|&k| residual[k].is_finite()).collect();
                let n = covered.len().max(1) as f64;
                let mean = covered.iter().map(|&k| residual[k]).sum::<f64>() / n;
                let sig = covered.iter().map(|&k| sigma[k]).sum::<f64>() / n;
                Band {
                    p_lo: p[range.start],
                    p_hi: p[range.end - 1],
                    mean: if covered.is_empty() { f64::NAN } else { mean },
                    sigma: sig,
                    verdict: Verdict::of(mean, sig),
                }
            })
            .collect();
        curves.push(summarise(&curve.name, residual, sigma, bands));
    }
    let n_comp = m.compression.len();
    for ((s, prediction), noise) in m
        .sticking
        .iter()
        .zip(&predictions[n_comp..])
        .zip(&noise[n_comp..])
    {
        let Prediction::Sticking { velocity, .. } = prediction else {
            panic!("prediction order")
        };
        let sigma = noise[0].sigma();
        // Sticking too slowly means too little loss: the same direction as "too soft".
        let residual = s.velocity - velocity;
        let mut g = summarise(&s.name, vec![residual], vec![sigma], Vec::new());
        g.residual = vec![velocity - s.velocity];
        curves.push(g);
    }
    let chi2 = curves.iter().map(|c| c.chi2).sum();
    Gap {
        threshold: chi2_quantile_95(curves.len()),
        curves,
        chi2,
    }
}

fn summarise(name: &str, residual: Vec<f64>, sigma: Vec<f64>, bands: Vec<Band>) -> CurveGap {
    let covered: Vec<usize> = (0..residual.len())
        .filter(|&k| residual[k].is_finite())
        .collect();
    let n = covered.len() as f64;
    let (rms, noise, chi2, mean, mean_sigma) = if covered.is_empty() {
        (f64::NAN, f64::NAN, f64::INFINITY, f64::NAN, f64::NAN)
    } else {
        let sq = |f: &dyn Fn(usize) -> f64| covered.iter().map(|&k| f(k)).sum::<f64>() / n;
        (
            sq(&|k| residual[k].powi(2)).sqrt(),
            sq(&|k| sigma[k].powi(2)).sqrt(),
            sq(&|k| (residual[k] / sigma[k]).powi(2)),
            sq(&|k| residual[k]),
            sq(&|k| sigma[k]),
        )
    };
    // A curve is judged by its χ²; the sign comes from the mean residual when that is clear.
    let verdict = if chi2 <= chi2_quantile_95(1) {
        Verdict::WithinNoise
    } else {
        match Verdict::of(mean, mean_sigma) {
            Verdict::WithinNoise => Verdict::Mixed,
            v => v,
        }
    };
    CurveGap {
        name: name.to_string(),
        verdict,
        residual,
        sigma,
        rms,
        noise,
        chi2,
        covered: covered.len(),
        bands,
    }
}

/// 95% quantile of χ² with `dof` degrees of freedom (Wilson–Hilferty; 3.75 for one degree
/// against the exact 3.84, within 1% from two on).
pub fn chi2_quantile_95(dof: usize) -> f64 {
    let k = dof.max(1) as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + 1.6449 * a.sqrt()).powi(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measured() -> MeasuredSet {
        MeasuredSet::parse(
            r#"
[[compression]]
geometry = "omni"
pressure_pa = [1e2, 1e5]
phi = [0.2, 0.5]
phi_sigma = 0.01
[[sticking]]
velocity_m_s = 1.0
sigma_m_s = 0.1
"#,
            "t",
        )
        .unwrap()
    }

    fn line(offset: f64) -> Vec<f64> {
        (0..TARGETS)
            .map(|k| 0.2 + 0.3 * k as f64 / (TARGETS - 1) as f64 + offset)
            .collect()
    }

    #[test]
    fn a_model_that_matches_is_within_noise_and_a_denser_one_is_too_soft() {
        let m = measured();
        let exact = [
            Prediction::from_seeds(&[line(0.0), line(0.0)]),
            Prediction::Sticking {
                velocity: 1.0,
                resolution: 0.0,
            },
        ];
        let g = gap(&m, &exact);
        assert!(g.chi2 < 1e-20 && g.within_noise());
        let soft = [
            Prediction::from_seeds(&[line(0.05), line(0.05)]),
            Prediction::Sticking {
                velocity: 0.5,
                resolution: 0.0,
            },
        ];
        let g = gap(&m, &soft);
        assert!(!g.within_noise());
        assert!((g.curves[0].rms - 0.05).abs() < 1e-12);
        assert!((g.curves[0].chi2 - 25.0).abs() < 1e-9);
        assert!(g.curves[0]
            .bands
            .iter()
            .all(|b| b.verdict == Verdict::TooSoft));
        assert_eq!(g.curves[1].verdict, Verdict::TooSoft);
        assert!((g.curves[1].residual[0] + 0.5).abs() < 1e-12);
    }

    #[test]
    fn quantiles_match_the_table() {
        for (k, q) in [(1, 3.841), (2, 5.991), (3, 7.815), (6, 12.59)] {
            assert!((chi2_quantile_95(k) / q - 1.0).abs() < 0.03, "{k}");
        }
    }
}
