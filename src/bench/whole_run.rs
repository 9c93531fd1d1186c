//! Whole runs beside the timed loops (`bench --lammps`, fresh samples): `dustdem run` of a
//! full config and `lmp` on the same sample for the same steps, each process timed from its
//! start to its exit, as a harness that times whole commands measures the two programs. The
//! loops the other columns time leave out what these include: building the RBD sample and
//! the engine, the rows' wall-force readings, the curve, profiles, snapshots and plot
//! (dustdem); the data file, the neighbour lists' set-up and the thermo output (LAMMPS).

use super::lammps::Lammps;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// One N's whole runs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WholeRun {
    /// Steps of every run (a whole number of the config's 100-step rows).
    pub steps: u64,
    pub threads: usize,
    pub ranks: usize,
    /// Particle-steps per second of each round's process (N × steps / wall-clock seconds).
    pub dustdem: Vec<f64>,
    pub lammps: Vec<f64>,
    /// Why the whole runs stopped, if they did.
    pub skipped: Option<String>,
}

/// Steps of a whole run: `at_least` rounded up to whole rows of 100 steps.
pub fn whole_steps(at_least: u64) -> u64 {
    at_least.max(1).div_ceil(100) * 100
}

/// The whole runs of a fresh sample where `bench --lammps` found LAMMPS: as many steps as the
/// CPU engine's measurement on the most threads and its warm-up, the most threads against the
/// most ranks; `None` for compressed samples (`dustdem run` starts from a sample, not from a
/// stored state), without LAMMPS and without [`super::Options::dustdem_exe`].
#[allow(clippy::too_many_arguments)]
pub fn for_size(
    n: usize,
    fresh: bool,
    options: &super::Options,
    sides: &[super::measure::Side],
    results: &[super::SideResult],
    lammps: &Result<Lammps, String>,
    warmup_steps: u64,
    lammps_dir: &Path,
    progress: &dyn Fn(&str),
) -> Option<WholeRun> {
    use super::measure::SideKind;
    let lammps = lammps.as_ref().ok().filter(|_| options.lammps && fresh)?;
    let exe = options.dustdem_exe.as_deref()?;
    let most = |key: fn(&SideKind) -> Option<usize>| {
        sides
            .iter()
            .zip(results)
            .filter_map(|(s, r)| key(&s.kind).map(|k| (k, r.steps)))
            .max()
    };
    let (threads, steps) = most(|k| match k {
        SideKind::Cpu(t) => Some(t.resolve()),
        _ => None,
    })?;
    let (ranks, _) = most(|k| match k {
        SideKind::Lammps { ranks } => Some(*ranks),
        _ => None,
    })?;
    let dir = options.out.join("whole_run").join(format!("n{n}"));
    let plan = Plan {
        n,
        steps: whole_steps(warmup_steps + steps),
        threads,
        ranks,
        lammps_dir,
        dir: &dir,
        rounds: options.rounds,
    };
    Some(measure(&plan, exe, lammps, progress))
}

/// What the whole runs of one N are made of.
pub struct Plan<'a> {
    pub n: usize,
    pub steps: u64,
    pub threads: usize,
    pub ranks: usize,
    /// The folder holding `in.compress` and `sample.data` of this N's fresh sample.
    pub lammps_dir: &'a Path,
    /// Where the dustdem config and its run go.
    pub dir: &'a Path,
    pub rounds: usize,
}

/// The whole runs of `plan`, the two programs alternating in each round.
pub fn measure(plan: &Plan, exe: &Path, lammps: &Lammps, progress: &dyn Fn(&str)) -> WholeRun {
    let mut result = WholeRun {
        steps: plan.steps,
        threads: plan.threads,
        ranks: plan.ranks,
        ..WholeRun::default()
    };
    let particle_steps = plan.n as f64 * plan.steps as f64;
    for round in 1..=plan.rounds {
        let dustdem = run_dustdem(exe, plan);
        let lmp = timed(|| {
            let tag = format!("whole{round}.r{}", plan.ranks);
            lammps.run(plan.lammps_dir, plan.ranks, 0, plan.steps, &tag)
        });
        match (dustdem, lmp) {
            (Ok(a), Ok(b)) => {
                let (a, b) = (particle_steps / a, particle_steps / b);
                progress(&format!(
                    "N = {}, whole runs, round {round}: dustdem run {a:.3e}, LAMMPS {b:.3e} \
                     particle-steps/s ({} steps)",
                    plan.n, plan.steps
                ));
                result.dustdem.push(a);
                result.lammps.push(b);
            }
            (Err(why), _) | (_, Err(why)) => {
                progress(&format!("N = {}: whole runs stopped: {why}", plan.n));
                result.skipped = Some(why);
                break;
            }
        }
    }
    result
}

/// The config of a whole run: [`super::benchmark_config`]'s compression, stopped after
/// `steps` steps.
pub fn config_text(n: usize, steps: u64) -> String {
    format!("{}max_steps = {steps}\n", super::benchmark_config_text(n))
}

/// Seconds `f` took, or its error.
fn timed<T>(f: impl FnOnce() -> Result<T, String>) -> Result<f64, String> {
    let clock = Instant::now();
    f()?;
    Ok(clock.elapsed().as_secs_f64())
}

/// One `dustdem run` of the plan's config on the CPU engine, timed; its curve must end at the
/// plan's step.
fn run_dustdem(exe: &Path, plan: &Plan) -> Result<f64, String> {
    std::fs::create_dir_all(plan.dir).map_err(|e| format!("{}: {e}", plan.dir.display()))?;
    let config = plan.dir.join("config.toml");
    crate::output::atomic::write_atomic(&config, config_text(plan.n, plan.steps).as_bytes())
        .map_err(|e| format!("{}: {e}", config.display()))?;
    let out = plan.dir.join("run");
    let mut command = Command::new(exe);
    command
        .arg("run")
        .arg(&config)
        .args(["--backend", "cpu", "--quiet", "--force"])
        .args(["--threads", &plan.threads.to_string()])
        .arg("--out")
        .arg(&out);
    let seconds = timed(|| {
        let output = command
            .output()
            .map_err(|e| format!("{}: could not start: {e}", exe.display()))?;
        if output.status.success() {
            Ok(())
        } else {
            let stderr = String::from_utf8_lossy(&output.stderr);
            Err(format!(
                "dustdem run {} failed ({}): {}",
                config.display(),
                output.status,
                stderr.lines().last().unwrap_or("")
            ))
        }
    })?;
    let curve = std::fs::read_to_string(out.join("curve.csv"))
        .map_err(|e| format!("{}: {e}", out.join("curve.csv").display()))?;
    let last_step = curve
        .lines()
        .rev()
        .find(|l| !l.starts_with('#'))
        .and_then(|l| l.split(',').next())
        .and_then(|s| s.parse::<u64>().ok());
    if last_step != Some(plan.steps) {
        return Err(format!(
            "{}: the run ended at step {last_step:?}, {} were asked for",
            out.display(),
            plan.steps
        ));
    }
    Ok(seconds)
}

/// bench.md's section on the whole runs; empty where none ran.
pub fn markdown(sizes: &[super::SizeResult]) -> String {
    use super::stats::{median, round_ratios};
    let runs: Vec<(usize, &WholeRun)> = sizes
        .iter()
        .filter_map(|s| s.whole_run.as_ref().map(|w| (s.n, w)))
        .collect();
    let Some((_, first)) = runs.first() else {
        return String::new();
    };
    let mut s = format!(
        "\n### Whole runs: `dustdem run` against `lmp`, each process timed from start to exit\n\n\
         The fresh sample's compression as a user runs it, for the same steps in both programs, \
         the two alternating in each round: `dustdem run` of the benchmark's config with \
         `max_steps` (whole_run/n<N>/config.toml; `--backend cpu`, {} threads), which builds the \
         RBD sample and writes its curve, profiles, snapshots and plot, against `mpirun -np {} lmp -in \
         in.compress -var warm 0` on the exported sample. This is the measure of a harness \
         that times whole commands; the table above times the step loops alone.\n\n\
         | N | steps | dustdem run | LAMMPS | dustdem run / LAMMPS |\n|---|---|---|---|---|\n",
        first.threads, first.ranks
    );
    for (n, w) in runs {
        let rate = |r: &[f64]| median(r).map_or("–".into(), |v| format!("{v:.3e}"));
        let ratios = round_ratios(&w.dustdem, &w.lammps);
        let ratio = match (&w.skipped, ratios.is_empty()) {
            (Some(why), true) => why.clone(),
            _ => super::table::ratio_cell(&ratios),
        };
        s.push_str(&format!(
            "| {n} | {} | {} | {} | {ratio} |\n",
            w.steps,
            rate(&w.dustdem),
            rate(&w.lammps)
        ));
    }
    s
}

/// bench.csv's whole-run columns.
pub const CSV_COLUMNS: [&str; 4] = [
    "whole_run_steps",
    "whole_run_dustdem_rate",
    "whole_run_lammps_rate",
    "whole_run_ratio_median",
];

/// One row's cells under [`CSV_COLUMNS`]; empty where no whole run was made.
pub fn csv_cells(w: Option<&WholeRun>) -> Vec<String> {
    use super::stats::{median, round_ratios};
    let cell = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6e}"));
    match w {
        None => vec![String::new(); CSV_COLUMNS.len()],
        Some(w) => vec![
            w.steps.to_string(),
            cell(median(&w.dustdem)),
            cell(median(&w.lammps)),
            cell(median(&round_ratios(&w.dustdem, &w.lammps))),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_steps_are_whole_rows() {
        assert_eq!(whole_steps(0), 100);
        assert_eq!(whole_steps(100), 100);
        assert_eq!(whole_steps(101), 200);
        assert_eq!(whole_steps(2345), 2400);
    }

    #[test]
    fn compressed_samples_get_no_whole_runs() {
        let dir = std::env::temp_dir().join(format!("dustdem-whole-run-{}", std::process::id()));
        let options = crate::bench::Options {
            lammps: true,
            rounds: 1,
            out: dir.clone(),
            dustdem_exe: Some("/nonexistent/dustdem".into()),
            ..Default::default()
        };
        let sides = crate::bench::measure::sides(&options);
        let result = crate::bench::SideResult {
            steps: 100,
            ..Default::default()
        };
        let results = vec![result; sides.len()];
        let lammps = Ok(Lammps {
            lmp: "/nonexistent/lmp".into(),
            mpirun: None,
        });
        let quiet = |_: &str| {};
        let run = |fresh| {
            for_size(
                200, fresh, &options, &sides, &results, &lammps, 10, &dir, &quiet,
            )
        };
        assert_eq!(run(false), None);
        // A fresh sample's whole runs are tried (and stop here: no such executable).
        let fresh = run(true).expect("whole runs on a fresh sample");
        assert_eq!(fresh.steps, 200);
        assert!(fresh.skipped.unwrap().contains("/nonexistent/dustdem"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_config_is_the_benchmark_compression_with_a_step_limit() {
        let config = crate::config::Config::parse(&config_text(300, 1200), "test").unwrap();
        let bench = super::super::benchmark_config(300).unwrap();
        assert_eq!(config.experiment.max_steps, 1200);
        assert_eq!(config.sample, bench.sample);
        assert_eq!(
            config.experiment.wall_speed_m_s,
            bench.experiment.wall_speed_m_s
        );
        assert_eq!(config.experiment.kind, bench.experiment.kind);
    }
}
