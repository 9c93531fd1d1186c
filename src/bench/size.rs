//! One benchmark size: the warm-up every side starts from, each side's probe for its step
//! count, the timed rounds that alternate the sides, and the GPU's times per pass.

use super::measure::{self, add_passes, probe, steps_for, Side, SideKind};
use super::{
    benchmark_config, benchmark_engine, memory, prepare, whole_run, Options, Report, SampleState,
    Setup, SideResult, SizeResult,
};
use crate::backend::cpu::CpuEngine;
use crate::backend::gpu::engine::GpuEngine;
use crate::backend::gpu::shader::Precision;
use crate::config::Config;
use std::path::PathBuf;

/// What every step of one size's measurement shares.
struct Plan<'a> {
    n: usize,
    sample: SampleState,
    options: &'a Options,
    sides: &'a [Side],
    setup: &'a Setup,
    lammps_dir: PathBuf,
    progress: &'a dyn Fn(&str),
}

/// The warmed-up states the sides start from, and the step budget they share.
struct Starts {
    start: CpuEngine,
    /// The same run with the monomers in the sample's order (fresh samples, when asked for).
    sample_order: Option<CpuEngine>,
    /// `start` not booking the corrections' dissipation.
    untallied: CpuEngine,
    warmup_steps: u64,
    /// Seconds per step of the warm-up on all threads.
    per_step: f64,
    /// The shortest probe [s].
    at_least: f64,
    /// Steps before the top wall has travelled a quarter of the gap.
    room: u64,
}

impl Starts {
    fn of(&self, kind: &SideKind) -> &CpuEngine {
        match kind {
            SideKind::CpuSampleOrder(_) => self.sample_order.as_ref().expect("checked by probe"),
            SideKind::CpuUntallied(_) => &self.untallied,
            _ => &self.start,
        }
    }
}

/// Measures every side at `n` monomers from `sample`: one warm-up, a probe per side, then
/// `options.rounds` rounds of every side in turn.
pub(super) fn measure_size(
    n: usize,
    sample: SampleState,
    options: &Options,
    sides: &[Side],
    setup: &Setup,
    report: &mut Report,
    progress: &dyn Fn(&str),
) -> Result<SizeResult, String> {
    let peak_rss_per_size = memory::reset_peak();
    let config = benchmark_config(n)?;
    let lammps_dir = options.out.join("lammps").join(match sample {
        SampleState::Fresh => format!("n{n}"),
        SampleState::Compressed { .. } => format!("n{n}_{}", sample.key()),
    });
    let plan = Plan {
        n,
        sample,
        options,
        sides,
        setup,
        lammps_dir,
        progress,
    };
    let starts = plan.warm_up(&config, report)?;
    let contacts_per_monomer = 2.0 * starts.start.contacts.pair_contact_count() as f64 / n as f64;
    let phi = prepare::gap_filling_factor(&starts.start);
    progress(&format!(
        "N = {n}, {}: warmed up {} steps, φ {phi:.3}, {contacts_per_monomer:.2} contacts per \
         monomer",
        sample.label(),
        starts.warmup_steps
    ));
    let mut results: Vec<SideResult> = vec![SideResult::default(); sides.len()];
    plan.probe_steps(&starts, &mut results, report);
    let lammps_contacts = plan.timed_rounds(&starts, &mut results, report);
    let whole_run = whole_run::for_size(
        n,
        sample == SampleState::Fresh,
        options,
        sides,
        &results,
        &setup.lammps,
        starts.warmup_steps,
        &plan.lammps_dir,
        progress,
    );
    Ok(SizeResult {
        n,
        sample,
        phi,
        warmup_steps: starts.warmup_steps,
        contacts_per_monomer,
        sides: results,
        peak_rss_bytes: memory::peak_rss_bytes(),
        peak_rss_per_size,
        lammps_contacts_per_monomer: lammps_contacts,
        whole_run,
    })
}

impl Plan<'_> {
    /// Warms up past the first contact changes (the top wall meeting the sample, the first
    /// contacts breaking), on all threads: a tenth of a measurement, at least 20 steps.
    fn warm_up(&self, config: &Config, report: &mut Report) -> Result<Starts, String> {
        let pool = &self.setup.warm_pool;
        let mut engine = prepare::starting_engine(
            config,
            self.sample,
            self.options,
            pool,
            &self.lammps_dir,
            &mut report.notes,
            self.progress,
        )?;
        let at_least = (self.options.seconds / 10.0).clamp(0.02, 2.0);
        let (probed, per_step) =
            probe(|k| measure::time_cpu(pool, &mut engine, k), at_least, 2000)?;
        let warm_total = steps_for(0.1 * self.options.seconds, per_step).clamp(20, 2000);
        let rest = warm_total.saturating_sub(probed);
        measure::time_cpu(pool, &mut engine, rest)?;
        let warmup_steps = probed + rest;
        let sample_order = if self.options.sample_order && self.sample == SampleState::Fresh {
            let mut config = config.clone();
            config.integration.space_filling_order = false;
            let (mut engine, _, _) = benchmark_engine(&config)?;
            measure::time_cpu(pool, &mut engine, warmup_steps)?;
            Some(engine)
        } else {
            None
        };
        let mut untallied = engine.clone();
        crate::engine::Engine::stop_tallying_corrections(&mut untallied);
        // Each side's probe and measurement stop before the top wall has travelled a quarter
        // of the gap: a small sample would otherwise be crushed within a long measurement.
        let room = prepare::steps_to_travel(&engine, 0.25);
        Ok(Starts {
            start: engine,
            sample_order,
            untallied,
            warmup_steps,
            per_step,
            at_least,
            room,
        })
    }

    /// Sets each side's step count from its own probe, or says why it is skipped.
    fn probe_steps(&self, starts: &Starts, results: &mut [SideResult], report: &mut Report) {
        for (i, side) in self.sides.iter().enumerate() {
            let r = &mut results[i];
            if matches!(side.kind, SideKind::CpuSampleOrder(_)) && starts.sample_order.is_none() {
                r.skipped = Some("measured on the fresh sample only".into());
                continue;
            }
            match self.probe_side(i, side, starts, r, report) {
                Ok((_, per_step)) => {
                    r.steps = steps_for(self.options.seconds, per_step).min(starts.room)
                }
                Err(why) => {
                    let note = format!("N = {}: {} not measured: {why}", self.n, side.label);
                    (self.progress)(&note);
                    r.skipped = Some(why);
                    // A missing GPU or LAMMPS is noted once, by the setup.
                    let setup = self.setup;
                    if !matches!(side.kind, SideKind::Gpu(p) if setup.gpu_ready(p).is_err())
                        && !matches!(side.kind, SideKind::Lammps { .. } if setup.lammps.is_err())
                    {
                        report.notes.push(note);
                    }
                }
            }
        }
    }

    /// One side's probe: (steps, seconds per step).
    fn probe_side(
        &self,
        i: usize,
        side: &Side,
        starts: &Starts,
        r: &mut SideResult,
        report: &mut Report,
    ) -> Result<(u64, f64), String> {
        let (at_least, room) = (starts.at_least, starts.room);
        match side.kind {
            SideKind::Cpu(_) | SideKind::CpuSampleOrder(_) | SideKind::CpuUntallied(_) => {
                let pool = self.setup.pools[i].as_ref().expect("a pool per cpu side");
                let mut e = starts.of(&side.kind).clone();
                probe(|k| measure::time_cpu(pool, &mut e, k), at_least, room)
            }
            SideKind::Gpu(precision) => {
                self.setup.gpu_ready(precision).clone()?;
                let mut e = measure::gpu_engine(&starts.start.state, precision)?;
                r.memory_mib = Some(e.device_bytes() as f64 / f64::from(1u32 << 20));
                probe(|k| measure::time_gpu(&mut e, k), at_least, room)
            }
            SideKind::Lammps { ranks } => {
                let lmp = self.setup.lammps.as_ref().map_err(Clone::clone)?;
                let steps = steps_for(at_least, starts.per_step).min(1_000_000);
                let tag = format!("probe.r{ranks}");
                let run = lmp.run(&self.lammps_dir, ranks, starts.warmup_steps, steps, &tag)?;
                report.lammps_version = Some(run.version.clone());
                Ok((steps, run.loop_seconds / steps as f64))
            }
        }
    }

    /// Runs the rounds, each side once per round from its start; then the exact GPU engine's
    /// times per pass. Returns LAMMPS's contacts per monomer from its one-rank runs.
    fn timed_rounds(
        &self,
        starts: &Starts,
        results: &mut [SideResult],
        report: &mut Report,
    ) -> Option<f64> {
        let mut gpu_engine: Option<GpuEngine> = None;
        let mut lammps_contacts = None;
        for round in 1..=self.options.rounds {
            for (i, side) in self.sides.iter().enumerate() {
                let r = &mut results[i];
                if r.skipped.is_some() {
                    continue;
                }
                let kept = (&mut gpu_engine, &mut lammps_contacts);
                match self.time_side(i, side, round, starts, r, kept) {
                    Ok(seconds) => {
                        let (n, steps) = (self.n, r.steps);
                        let rate = n as f64 * steps as f64 / seconds;
                        (self.progress)(&format!(
                            "N = {n}, round {round}: {} {rate:.3e} particle-steps/s ({steps} \
                             steps, {seconds:.2} s)",
                            side.label
                        ));
                        r.rates.push(rate);
                    }
                    Err(why) => {
                        let note = format!(
                            "N = {}, round {round}: {} stopped: {why}",
                            self.n, side.label
                        );
                        (self.progress)(&note);
                        report.notes.push(note);
                        r.skipped = Some(why);
                    }
                }
            }
        }
        // The sums of the per-step pass times become means over the rounds that ran.
        for r in results.iter_mut() {
            let rounds = r.rates.len().max(1) as f64;
            r.passes.iter_mut().for_each(|p| *p /= rounds);
        }
        self.gpu_pass_times(gpu_engine, results, report);
        lammps_contacts
    }

    /// One side's timed run in one round [s]. Keeps the exact GPU engine for the times per
    /// pass, and LAMMPS's contacts per monomer from its one-rank run.
    fn time_side(
        &self,
        i: usize,
        side: &Side,
        round: usize,
        starts: &Starts,
        r: &mut SideResult,
        (gpu_engine, lammps_contacts): (&mut Option<GpuEngine>, &mut Option<f64>),
    ) -> Result<f64, String> {
        let steps = r.steps;
        match side.kind {
            SideKind::Cpu(_) | SideKind::CpuSampleOrder(_) | SideKind::CpuUntallied(_) => {
                let pool = self.setup.pools[i].as_ref().expect("a pool per cpu side");
                let mut e = starts.of(&side.kind).clone();
                e.pass_seconds = [0.0; 5];
                let seconds = measure::time_cpu(pool, &mut e, steps)?;
                add_passes(&mut r.passes, &e.pass_seconds, steps);
                Ok(seconds)
            }
            SideKind::Gpu(precision) => {
                let mut e = measure::gpu_engine(&starts.start.state, precision)?;
                let seconds = measure::time_gpu(&mut e, steps)?;
                // Pass times are those of the exact precision's engine.
                if precision == Precision::Exact {
                    *gpu_engine = Some(e);
                }
                Ok(seconds)
            }
            SideKind::Lammps { ranks } => {
                let lmp = self.setup.lammps.as_ref().expect("checked by the probe");
                let tag = format!("round{round}.r{ranks}");
                let run = lmp.run(&self.lammps_dir, ranks, starts.warmup_steps, steps, &tag)?;
                let times: Vec<f64> = measure::LAMMPS_SECTIONS
                    .iter()
                    .map(|name| {
                        let section = run.sections.iter().find(|(s, _)| s == name);
                        section.map_or(0.0, |(_, t)| *t)
                    })
                    .collect();
                add_passes(&mut r.passes, &times, steps);
                r.memory_mib = run.memory_mib;
                if ranks == 1 {
                    *lammps_contacts = run.contacts_per_monomer;
                }
                Ok(run.loop_seconds)
            }
        }
    }

    /// Timestamps around every dispatch of 20 ordinary steps, where the device has them.
    fn gpu_pass_times(
        &self,
        gpu_engine: Option<GpuEngine>,
        results: &mut [SideResult],
        report: &mut Report,
    ) {
        let exact = self
            .sides
            .iter()
            .position(|s| s.kind == SideKind::Gpu(Precision::Exact));
        let (Some(i), Some(mut e)) = (exact, gpu_engine) else {
            return;
        };
        match e.profile_passes(20) {
            Ok(Some(times)) => results[i].passes = times.iter().map(|(_, s)| *s).collect(),
            Ok(None) => report
                .notes
                .push("gpu: the adapter has no timestamps inside passes; no times per pass".into()),
            Err(why) => report
                .notes
                .push(format!("N = {}: gpu pass times: {why}", self.n)),
        }
    }
}
