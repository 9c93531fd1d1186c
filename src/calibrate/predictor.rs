//! Turns configurations into predictions of every measured curve, and counts what that cost.
//!
//! Two kinds of prediction: a full one (every calibration seed) for the baseline and every
//! correction a round keeps, and a screening one on the first `screen_seeds` seeds with common
//! random numbers: the same samples as the full prediction of the current model, so the
//! screened configuration's curve is that prediction moved by the per-seed difference
//! between the two models on those samples. A difference on common samples carries much less
//! sample-to-sample noise than either curve, so the screen needs fewer seeds to rank and
//! bound the effects; the noise of the prediction stays the full prediction's seed scatter.
//!
//! The screen may also run on a smaller sample (`screen_monomers`, multi-fidelity in size):
//! both the screened configuration and the current model are then simulated at that size on
//! the screen seeds, and their difference moves the current model's full prediction at the
//! target size. The gaps, the noise and every full prediction stay at the target size.

use super::gap::{targets, Prediction};
use super::measured::MeasuredSet;
use super::simulate::{
    compression_config, run_all, sticking_config, Output, Run, RunCache, STICKING_TOLERANCE,
};
use super::workflow::Settings;
use crate::config::Config;

/// What one configuration gave for one measured curve before averaging over seeds.
enum Raw {
    /// Per seed, φ at the curve's target pressures.
    Compression(Vec<Vec<f64>>),
    /// Sticking threshold [m/s].
    Sticking(f64),
}

/// Which of a batch's runs are new requests and count towards the cost.
#[derive(Clone, Copy, PartialEq)]
enum Counted {
    None,
    All,
    /// The compressions only: the batch's sticking run repeats one counted before.
    Compressions,
}

/// What the predictions of a calibration cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cost {
    /// Compressions requested (a run the cache already held counts too: the count does not
    /// depend on what an earlier calibration left in the cache).
    pub compressions: usize,
    /// Of `compressions`, those run on the screen's smaller sample (0 without one).
    pub screen_size_compressions: usize,
    /// Sticking-threshold runs requested.
    pub sticking: usize,
    /// Each requested run's own wall-clock time, summed [s; CPU-seconds where every run had a
    /// core to itself];
    /// runs read from a cache on disk, whose cost this process did not see, add nothing.
    pub cpu_seconds: f64,
}

impl Cost {
    pub fn runs(&self) -> usize {
        self.compressions + self.sticking
    }
}

/// Predicts every measured curve for each config (all runs in one parallel batch).
pub struct Predictor<'a> {
    pub measured: &'a MeasuredSet,
    pub cache: &'a RunCache,
    pub settings: &'a Settings,
    pub progress: &'a (dyn Fn(&str) + Sync),
    pub cost: Cost,
    /// Sample size of the screening runs; 0: the config's own. Set to the setting's value
    /// only for the first screen on smaller samples ([`super::search::screen_by_size`]).
    pub screen_monomers: usize,
    /// The current models whose screen-size reference runs were counted already (repeated
    /// requests of one reference are cache hits, not new compressions).
    counted_references: Vec<Config>,
}

impl<'a> Predictor<'a> {
    pub fn new(
        measured: &'a MeasuredSet,
        cache: &'a RunCache,
        settings: &'a Settings,
        progress: &'a (dyn Fn(&str) + Sync),
    ) -> Self {
        Predictor {
            measured,
            cache,
            settings,
            progress,
            cost: Cost::default(),
            screen_monomers: 0,
            counted_references: Vec::new(),
        }
    }

    /// Whether the screening runs use a sample size other than the config's.
    fn screens_smaller(&self, config: &Config) -> bool {
        self.screen_monomers != 0 && self.screen_monomers != config.sample.monomers
    }

    /// `config` at the screen's sample size.
    fn at_screen_size(&self, config: &Config) -> Config {
        let mut c = config.clone();
        if self.screen_monomers != 0 {
            c.sample.monomers = self.screen_monomers;
        }
        c
    }

    /// The seeds a screening prediction runs: the first `screen_seeds` (all when 0).
    fn screen_seeds(&self) -> &'a [u64] {
        let seeds = &self.settings.seeds;
        match self.settings.screen_seeds {
            0 => seeds,
            k => &seeds[..k.min(seeds.len())],
        }
    }

    /// Whether screening predictions are full ones: every seed screened at the target size,
    /// or no compression curve (a sticking velocity does not depend on the sample).
    pub fn screens_every_seed(&self, config: &Config) -> bool {
        self.measured.compression.is_empty()
            || (self.screen_seeds().len() == self.settings.seeds.len()
                && !self.screens_smaller(config))
    }

    /// The runs predicting every curve; `screen_size` makes the compressions at the screen's
    /// sample size (a sticking velocity does not depend on the sample).
    fn runs_for(&self, config: &Config, seeds: &[u64], screen_size: bool) -> Vec<Run> {
        let mut runs = Vec::new();
        let sample = match screen_size {
            true => self.at_screen_size(config),
            false => config.clone(),
        };
        for c in &self.measured.compression {
            let (_, p_max) = c.pressure_range();
            for &seed in seeds {
                runs.push(Run::Compression(compression_config(
                    &sample,
                    c.geometry,
                    c.wall_speed,
                    seed,
                    p_max,
                )));
            }
        }
        if !self.measured.sticking.is_empty() {
            runs.push(Run::Sticking(sticking_config(config)));
        }
        runs
    }

    /// Every config's raw outputs on `seeds` (at the screen's size with `screen_size`);
    /// `counted` says which runs add to the cost.
    fn simulate(
        &mut self,
        configs: &[Config],
        seeds: &[u64],
        screen_size: bool,
        what: &str,
        counted: Counted,
    ) -> Result<Vec<Vec<Raw>>, String> {
        let quiet = counted == Counted::None;
        let flat: Vec<Run> = configs
            .iter()
            .flat_map(|c| self.runs_for(c, seeds, screen_size))
            .collect();
        if !quiet {
            (self.progress)(&format!(
                "{what}: {} configuration(s), {} run(s)",
                configs.len(),
                flat.len()
            ));
        }
        let progress = self.progress;
        let step = (flat.len() / 10).max(1);
        let outputs = run_all(&flat, self.cache, self.settings.threads, &|k, n| {
            if !quiet && (k % step == 0 || k == n) {
                progress(&format!("  {what}: {k}/{n} runs done"));
            }
        });
        let counted_runs = flat
            .iter()
            .filter(|r| match counted {
                Counted::None => false,
                Counted::All => true,
                Counted::Compressions => matches!(r, Run::Compression(_)),
            })
            .collect::<Vec<_>>();
        let smaller = screen_size && configs.first().is_some_and(|c| self.screens_smaller(c));
        self.count(&counted_runs, smaller);
        let failed = outputs
            .iter()
            .filter(|o| matches!(o, Ok(Output::Envelope(e)) if e.failure.is_some()))
            .count();
        if !quiet && failed > 0 {
            (self.progress)(&format!(
                "  {what}: {failed} compression(s) stopped by a run-time guard; their curves end there"
            ));
        }
        let targets = targets(self.measured);
        let mut outputs = outputs.into_iter();
        let mut all = Vec::new();
        for _ in configs {
            let mut raw = Vec::new();
            for t in &targets {
                let mut per_seed = Vec::new();
                for _ in seeds {
                    match outputs.next().expect("one output per run")? {
                        Output::Envelope(e) => {
                            per_seed.push(t.iter().map(|&p| e.phi_at(p)).collect::<Vec<_>>())
                        }
                        Output::Sticking(_) => unreachable!("run order"),
                    }
                }
                raw.push(Raw::Compression(per_seed));
            }
            if !self.measured.sticking.is_empty() {
                let Output::Sticking(v) = outputs.next().expect("one output per run")? else {
                    unreachable!("run order")
                };
                raw.extend(self.measured.sticking.iter().map(|_| Raw::Sticking(v)));
            }
            all.push(raw);
        }
        Ok(all)
    }

    fn count(&mut self, runs: &[&Run], screen_size: bool) {
        for run in runs {
            match run {
                Run::Compression(_) => {
                    self.cost.compressions += 1;
                    self.cost.screen_size_compressions += usize::from(screen_size);
                }
                Run::Sticking(_) => self.cost.sticking += 1,
            }
            self.cost.cpu_seconds += self.cache.cost(run).unwrap_or(0.0);
        }
    }

    /// Full predictions: every seed.
    pub fn predict(
        &mut self,
        configs: &[Config],
        what: &str,
    ) -> Result<Vec<Vec<Prediction>>, String> {
        let seeds = self.settings.seeds.clone();
        let raw = self.simulate(configs, &seeds, false, what, Counted::All)?;
        Ok(raw
            .into_iter()
            .map(|r| r.into_iter().map(full_prediction).collect())
            .collect())
    }

    /// Screening predictions on common random numbers: `current`'s full predictions moved by
    /// each config's mean per-seed difference from `current` on the screen seeds. With every
    /// seed screened this is the full prediction.
    pub fn predict_screen(
        &mut self,
        configs: &[Config],
        current: &Config,
        current_predictions: &[Prediction],
        what: &str,
    ) -> Result<Vec<Vec<Prediction>>, String> {
        if self.screens_every_seed(current) {
            return self.predict(configs, what);
        }
        self.screened(configs, current, current_predictions, what, Counted::All)
    }

    /// The screening prediction of a config that [`Predictor::predict`] has just run on every
    /// seed: read from those runs (the screen seeds are among them), so it costs nothing and
    /// is not counted — unless the screen runs a smaller sample, whose run is new and counted.
    /// Set beside the full prediction it measures how far the screened response is from the
    /// mean one at the target size ([`super::fidelity`]).
    pub fn screened_view(
        &mut self,
        config: &Config,
        current: &Config,
        current_predictions: &[Prediction],
    ) -> Result<Vec<Prediction>, String> {
        let mut views = self.screened(
            std::slice::from_ref(config),
            current,
            current_predictions,
            "screened view",
            match self.screens_smaller(current) {
                true => Counted::Compressions,
                false => Counted::None,
            },
        )?;
        Ok(views.remove(0))
    }

    fn screened(
        &mut self,
        configs: &[Config],
        current: &Config,
        current_predictions: &[Prediction],
        what: &str,
        counted: Counted,
    ) -> Result<Vec<Vec<Prediction>>, String> {
        let seeds = self.screen_seeds();
        let raw = self.simulate(configs, seeds, true, what, counted)?;
        // At the target size these are cache hits (`current` ran on every seed for its full
        // prediction); on a smaller screen sample they are run, and counted, once per model.
        let new_reference =
            self.screens_smaller(current) && !self.counted_references.contains(current);
        if new_reference {
            self.counted_references.push(current.clone());
        }
        let reference = self
            .simulate(
                std::slice::from_ref(current),
                seeds,
                true,
                &format!("{what} (the current model at the screen's size)"),
                match new_reference {
                    true => Counted::Compressions,
                    false => Counted::None,
                },
            )?
            .remove(0);
        Ok(raw
            .into_iter()
            .map(|r| {
                r.into_iter()
                    .zip(&reference)
                    .zip(current_predictions)
                    .map(|((x, r), full)| shifted(x, r, full))
                    .collect()
            })
            .collect())
    }
}

fn full_prediction(raw: Raw) -> Prediction {
    match raw {
        Raw::Compression(per_seed) => Prediction::from_seeds(&per_seed),
        Raw::Sticking(v) => Prediction::Sticking {
            velocity: v,
            resolution: 0.5 * STICKING_TOLERANCE * v,
        },
    }
}

/// `full` moved by the mean per-seed difference of `screened` from `reference` (same seeds).
fn shifted(screened: Raw, reference: &Raw, full: &Prediction) -> Prediction {
    match (screened, reference, full) {
        (
            Raw::Compression(x),
            Raw::Compression(r),
            Prediction::Compression {
                phi,
                scatter,
                seeds,
            },
        ) => Prediction::Compression {
            phi: common_shift(phi, &x, r),
            scatter: scatter.clone(),
            seeds: *seeds,
        },
        (sticking, _, _) => full_prediction(sticking),
    }
}

/// `base[j]` + mean over seeds of `x[s][j] − r[s][j]` (NaN where any seed missed the target).
fn common_shift(base: &[f64], x: &[Vec<f64>], r: &[Vec<f64>]) -> Vec<f64> {
    let n = x.len() as f64;
    base.iter()
        .enumerate()
        .map(|(j, &b)| b + x.iter().zip(r).map(|(xs, rs)| xs[j] - rs[j]).sum::<f64>() / n)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_common_shift_moves_the_full_mean_by_the_mean_paired_difference() {
        // Seeds (0.20, 0.30) under the screened model, (0.18, 0.24) under the current one:
        // differences 0.02 and 0.06, mean 0.04, added to the full mean 0.25.
        let x = vec![vec![0.20, 0.5], vec![0.30, f64::NAN]];
        let r = vec![vec![0.18, 0.4], vec![0.24, 0.4]];
        let s = common_shift(&[0.25, 0.45], &x, &r);
        assert!((s[0] - 0.29).abs() < 1e-15, "{s:?}");
        assert!(
            s[1].is_nan(),
            "a seed that missed the target leaves it unknown"
        );
    }

    #[test]
    fn each_curve_is_simulated_at_its_own_wall_speed_or_else_the_configs() {
        use super::super::measured::{CompressionCurve, Geometry, Provenance};
        use crate::config::ExperimentKind;
        let curve = |name: &str, geometry, wall_speed| CompressionCurve {
            name: name.into(),
            geometry,
            pressure: vec![1e3, 1e4],
            phi: vec![0.2, 0.3],
            phi_sigma: vec![0.01, 0.01],
            wall_speed,
        };
        let measured = MeasuredSet {
            source: Provenance {
                citation: "test".into(),
                what: String::new(),
                notes: String::new(),
            },
            compression: vec![
                curve("fast", Geometry::Omni, Some(7.5)),
                curve("unstated", Geometry::Uni, None),
            ],
            sticking: Vec::new(),
        };
        let (cache, settings) = (RunCache::new(), Settings::default());
        let predictor = Predictor::new(&measured, &cache, &settings, &|_| {});
        let mut base = Config::default();
        base.experiment.wall_speed_m_s = 0.25;
        let runs = predictor.runs_for(&base, &[4, 5], false);
        let speeds: Vec<(ExperimentKind, u64, f64)> = runs
            .iter()
            .map(|r| match r {
                Run::Compression(c) => (
                    c.experiment.kind,
                    c.sample.seed,
                    c.experiment.wall_speed_m_s,
                ),
                Run::Sticking(_) => panic!("no sticking data"),
            })
            .collect();
        assert_eq!(
            speeds,
            vec![
                (ExperimentKind::Omni, 4, 7.5),
                (ExperimentKind::Omni, 5, 7.5),
                (ExperimentKind::Uni, 4, 0.25),
                (ExperimentKind::Uni, 5, 0.25),
            ]
        );
    }

    #[test]
    fn a_shifted_prediction_keeps_the_full_scatter() {
        let full = Prediction::Compression {
            phi: vec![0.3],
            scatter: vec![0.01],
            seeds: 3,
        };
        let p = shifted(
            Raw::Compression(vec![vec![0.35]]),
            &Raw::Compression(vec![vec![0.31]]),
            &full,
        );
        let Prediction::Compression {
            phi,
            scatter,
            seeds,
        } = p
        else {
            panic!("a compression")
        };
        assert!((phi[0] - 0.34).abs() < 1e-15);
        assert_eq!((scatter, seeds), (vec![0.01], 3));
    }
}
