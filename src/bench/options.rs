//! What `dustdem bench` measures: sizes, time per measurement, rounds, thread counts, engines,
//! and whether LAMMPS runs beside them. Every argument is checked here, so a bad value stops
//! the command before anything runs, with a message naming the argument, the value and the
//! allowed range.

use crate::backend::gpu::shader::Precision;
use std::path::PathBuf;

/// Smallest and largest N: below 10 an RBD sample has hardly any contacts to measure; above
/// 10⁷ the CPU state alone passes 10 GB.
pub const SIZE_RANGE: (usize, usize) = (10, 10_000_000);
/// Seconds per measurement.
pub const SECONDS_RANGE: (f64, f64) = (0.05, 3600.0);
pub const ROUNDS_RANGE: (usize, usize) = (1, 100);
pub const THREADS_MAX: usize = 1024;
/// MPI ranks of the LAMMPS runs: the ratios compare one rank with one thread and two ranks
/// with all threads.
pub const LAMMPS_RANKS: [usize; 2] = [1, 2];
/// Filling factors a compressed benchmark sample may be brought to: above every fresh RBD
/// sample's (≈ 0.12–0.15), and no denser than the omni curves reach at 1 m/s in reasonable time.
pub const PHI_RANGE: (f64, f64) = (0.16, 0.6);
/// Top wall speeds [m/s] that compress a benchmark sample to its filling factor: from the
/// paper's quasi-static 1 cm/s to its fastest dynamic compression.
pub const PREPARE_SPEED_RANGE: (f64, f64) = (0.01, 25.0);

/// The state a benchmark starts from: the fresh RBD sample, or that sample compressed by the
/// engine itself until the wall gap's filling factor reaches `phi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleState {
    Fresh,
    Compressed { phi: f64 },
}

impl SampleState {
    /// Table cell: `fresh` or `compressed to 0.30`.
    pub fn label(&self) -> String {
        match self {
            SampleState::Fresh => "fresh".into(),
            SampleState::Compressed { phi } => format!("compressed to {phi:.2}"),
        }
    }

    /// File-name and csv key: `fresh` or `phi0.300`.
    pub fn key(&self) -> String {
        match self {
            SampleState::Fresh => "fresh".into(),
            SampleState::Compressed { phi } => format!("phi{phi:.3}"),
        }
    }
}

/// A thread count of the CPU engine: a number, or every core the machine offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Threads {
    Count(usize),
    All,
}

impl Threads {
    /// The number of threads this stands for on this machine.
    pub fn resolve(self) -> usize {
        match self {
            Threads::Count(t) => t,
            Threads::All => std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// The benchmark's plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub sizes: Vec<usize>,
    /// Target wall-clock seconds of one measurement (one engine, one round).
    pub seconds: f64,
    pub rounds: usize,
    /// CPU engine thread counts, in the order a round runs them (empty: no CPU columns).
    pub threads: Vec<Threads>,
    /// GPU sides, by precision (`--backends gpu,gpu-mixed`; empty: no GPU columns).
    pub gpu: Vec<Precision>,
    pub lammps: bool,
    /// Also time the CPU engine on all threads with the monomers in the sample's order, to
    /// show what the space-filling storage order gains.
    pub sample_order: bool,
    /// Also time the CPU engine on all threads without booking the corrections' dissipation
    /// (`[output] tally_corrections = false`; LAMMPS keeps no such tally).
    pub untallied: bool,
    /// The starting states measured at every N, in order.
    pub samples: Vec<SampleState>,
    /// Top wall speed [m/s] that compresses the compressed states and goes on while they are
    /// measured (the fresh sample's measurement runs at 1 m/s).
    pub prepare_speed_m_s: f64,
    pub out: PathBuf,
    /// The dustdem executable `--lammps`'s whole runs start (the command line sets its own);
    /// `None`: no whole runs.
    pub dustdem_exe: Option<PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            sizes: vec![1_000, 10_000, 100_000, 1_000_000],
            seconds: 20.0,
            rounds: 3,
            threads: vec![Threads::Count(1), Threads::All],
            gpu: vec![Precision::Exact],
            lammps: false,
            sample_order: false,
            untallied: false,
            samples: vec![SampleState::Fresh],
            prepare_speed_m_s: 1.0,
            out: PathBuf::from("bench"),
            dustdem_exe: None,
        }
    }
}

impl Options {
    /// Options from the command line's strings (`--sizes 1000,10000`, `--threads 1,all`,
    /// `--backends cpu,gpu`).
    pub fn parse(
        sizes: &str,
        seconds: f64,
        rounds: usize,
        threads: &str,
        backends: &str,
        lammps: bool,
        out: PathBuf,
    ) -> Result<Options, String> {
        let sizes = parse_sizes(sizes)?;
        if !(seconds.is_finite() && (SECONDS_RANGE.0..=SECONDS_RANGE.1).contains(&seconds)) {
            return Err(format!(
                "--seconds {seconds}: out of range; allowed {} to {}",
                SECONDS_RANGE.0, SECONDS_RANGE.1
            ));
        }
        if !(ROUNDS_RANGE.0..=ROUNDS_RANGE.1).contains(&rounds) {
            return Err(format!(
                "--rounds {rounds}: out of range; allowed {} to {}",
                ROUNDS_RANGE.0, ROUNDS_RANGE.1
            ));
        }
        let (cpu, gpu) = parse_backends(backends)?;
        let threads = if cpu {
            parse_threads(threads)?
        } else {
            Vec::new()
        };
        Ok(Options {
            sizes,
            seconds,
            rounds,
            threads,
            gpu,
            lammps,
            sample_order: false,
            untallied: false,
            samples: vec![SampleState::Fresh],
            prepare_speed_m_s: 1.0,
            out,
            dustdem_exe: None,
        })
    }

    /// Sets the starting states (`--samples fresh,0.3,0.45`) and the speed that prepares the
    /// compressed ones (`--prepare-speed`, m/s), checking both.
    pub fn with_samples(mut self, samples: &str, prepare_speed_m_s: f64) -> Result<Self, String> {
        self.samples = parse_samples(samples)?;
        let (lo, hi) = PREPARE_SPEED_RANGE;
        if !(prepare_speed_m_s.is_finite() && (lo..=hi).contains(&prepare_speed_m_s)) {
            return Err(format!(
                "--prepare-speed {prepare_speed_m_s}: out of range; allowed {lo} to {hi} m/s"
            ));
        }
        self.prepare_speed_m_s = prepare_speed_m_s;
        Ok(self)
    }
}

fn parse_samples(text: &str) -> Result<Vec<SampleState>, String> {
    let (lo, hi) = PHI_RANGE;
    let mut samples = Vec::new();
    for item in list(text) {
        let state = match item {
            "fresh" => SampleState::Fresh,
            _ => match item.parse::<f64>() {
                Ok(phi) if phi.is_finite() && (lo..=hi).contains(&phi) => {
                    SampleState::Compressed { phi }
                }
                _ => {
                    return Err(format!(
                        "--samples {text}: `{item}` is not allowed; each entry is `fresh` or a \
                         filling factor from {lo} to {hi}"
                    ))
                }
            },
        };
        if samples.iter().any(|s: &SampleState| s.key() == state.key()) {
            return Err(format!("--samples {text}: `{item}` is listed twice"));
        }
        samples.push(state);
    }
    Ok(samples)
}

fn list(text: &str) -> impl Iterator<Item = &str> {
    text.split(',').map(str::trim)
}

fn parse_sizes(text: &str) -> Result<Vec<usize>, String> {
    let mut sizes = Vec::new();
    for item in list(text) {
        let n: usize = item.parse().map_err(|_| {
            format!(
                "--sizes {text}: `{item}` is not a whole number; allowed {} to {}, comma-separated",
                SIZE_RANGE.0, SIZE_RANGE.1
            )
        })?;
        if !(SIZE_RANGE.0..=SIZE_RANGE.1).contains(&n) {
            return Err(format!(
                "--sizes {text}: {n} is out of range; allowed {} to {}",
                SIZE_RANGE.0, SIZE_RANGE.1
            ));
        }
        if sizes.contains(&n) {
            return Err(format!("--sizes {text}: {n} is listed twice"));
        }
        sizes.push(n);
    }
    Ok(sizes)
}

fn parse_threads(text: &str) -> Result<Vec<Threads>, String> {
    let mut threads = Vec::new();
    for item in list(text) {
        let t = if item == "all" {
            Threads::All
        } else {
            match item.parse::<usize>() {
                Ok(t) if (1..=THREADS_MAX).contains(&t) => Threads::Count(t),
                _ => {
                    return Err(format!(
                        "--threads {text}: `{item}` is not allowed; each entry is `all` or a \
                         number from 1 to {THREADS_MAX}"
                    ))
                }
            }
        };
        if threads.contains(&t) {
            return Err(format!("--threads {text}: `{item}` is listed twice"));
        }
        threads.push(t);
    }
    Ok(threads)
}

/// (cpu, GPU precisions) from `--backends`.
fn parse_backends(text: &str) -> Result<(bool, Vec<Precision>), String> {
    let (mut cpu, mut gpu) = (false, Vec::new());
    for item in list(text) {
        match item {
            "cpu" => cpu = true,
            "gpu" => gpu.push(Precision::Exact),
            "gpu-mixed" => gpu.push(Precision::Mixed),
            other => {
                return Err(format!(
                    "--backends {text}: `{other}` is not an engine; allowed cpu, gpu (exact \
                     precision) and gpu-mixed, comma-separated"
                ))
            }
        }
    }
    gpu.dedup();
    Ok((cpu, gpu))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(sizes: &str, threads: &str, backends: &str) -> Result<Options, String> {
        Options::parse(sizes, 1.0, 1, threads, backends, false, "b".into())
    }

    #[test]
    fn lists_are_parsed_in_order() {
        let o = parse("1000, 200", "all,1,4", "gpu,cpu").unwrap();
        assert_eq!(o.sizes, [1000, 200]);
        assert_eq!(
            o.threads,
            [Threads::All, Threads::Count(1), Threads::Count(4)]
        );
        assert_eq!(o.gpu, [Precision::Exact]);
        let both = parse("1000", "1", "cpu,gpu-mixed,gpu").unwrap();
        assert_eq!(both.gpu, [Precision::Mixed, Precision::Exact]);
        assert!(parse("200", "1", "gpu").unwrap().threads.is_empty());
    }

    #[test]
    fn bad_values_name_the_argument_value_and_range() {
        let e = parse("5", "1", "cpu").unwrap_err();
        assert!(
            e.contains("--sizes 5") && e.contains("10 to 10000000"),
            "{e}"
        );
        let e = parse("1e3", "1", "cpu").unwrap_err();
        assert!(e.contains("`1e3`"), "{e}");
        let e = parse("100", "0", "cpu").unwrap_err();
        assert!(e.contains("--threads 0") && e.contains("1 to 1024"), "{e}");
        let e = parse("100", "1", "tpu").unwrap_err();
        assert!(
            e.contains("--backends tpu") && e.contains("cpu, gpu"),
            "{e}"
        );
        let e = Options::parse("100", 0.0, 1, "1", "cpu", false, "b".into()).unwrap_err();
        assert!(
            e.contains("--seconds 0") && e.contains("0.05 to 3600"),
            "{e}"
        );
        let e = Options::parse("100", 1.0, 0, "1", "cpu", false, "b".into()).unwrap_err();
        assert!(e.contains("--rounds 0") && e.contains("1 to 100"), "{e}");
    }

    #[test]
    fn sample_states_are_checked_and_kept_in_order() {
        let o = parse("100", "1", "cpu").unwrap();
        let o = o.with_samples("0.45, fresh,0.3", 5.0).unwrap();
        assert_eq!(
            o.samples,
            [
                SampleState::Compressed { phi: 0.45 },
                SampleState::Fresh,
                SampleState::Compressed { phi: 0.3 }
            ]
        );
        assert_eq!(o.prepare_speed_m_s, 5.0);
        assert_eq!(o.samples[0].key(), "phi0.450");
        assert_eq!(o.samples[2].label(), "compressed to 0.30");
        let o = parse("100", "1", "cpu").unwrap();
        for (samples, speed, words) in [
            ("0.15", 1.0, ["--samples 0.15", "0.16 to 0.6"]),
            ("0.61", 1.0, ["`0.61`", "0.16 to 0.6"]),
            ("loose", 1.0, ["`loose`", "`fresh`"]),
            ("0.3,0.30", 1.0, ["`0.30`", "twice"]),
            ("0.3", 0.005, ["--prepare-speed 0.005", "0.01 to 25 m/s"]),
            ("0.3", f64::NAN, ["--prepare-speed NaN", "0.01 to 25 m/s"]),
        ] {
            let e = o.clone().with_samples(samples, speed).unwrap_err();
            assert!(e.contains(words[0]) && e.contains(words[1]), "{e}");
        }
    }
}
