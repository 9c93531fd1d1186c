//! The simulations a calibration asks for: compressions (one per sample seed) reduced to a
//! monotone φ(P) envelope, and head-on sticking thresholds. Runs go through a cache keyed by
//! the full effective config, so a run is never repeated (same config → same result: the
//! engine is deterministic), and are spread over threads.

use super::measured::Geometry;
use super::slurm::{run_batch, SlurmRuns};
use super::stored;
use crate::binary::fnv1a64;
use crate::config::{Config, ExperimentKind, FootprintKind, SampleSource};
use crate::experiment::compression::{Compression, Event};
use crate::job::reference_engine;
use crate::output::atomic::write_atomic;
use crate::output::lock::{host_name, try_lock, Lock};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use super::sticking::sticking_threshold_m_s;
pub use super::sticking::{STICKING_CAP, STICKING_TOLERANCE};
pub use crate::analysis::envelope::{Envelope, MEDIAN_ROWS};
/// Compressions stop at this multiple of the highest measured pressure: a single row above it
/// stops the run, and the median-smoothed envelope must still reach the highest pressure.
const PRESSURE_STOP_MARGIN: f64 = 10.0;
/// One simulation.
#[derive(Clone, Debug, PartialEq)]
pub enum Run {
    /// A compression under this (complete) config.
    Compression(Config),
    /// The head-on sticking threshold of two monomers under this config's contact law.
    Sticking(Config),
}

impl Run {
    /// The cache key: the kind of run and its complete config (TOML).
    pub fn key(&self) -> String {
        let (tag, c) = match self {
            Run::Compression(c) => ("compression", c),
            Run::Sticking(c) => ("sticking", c),
        };
        format!("{tag}\n{}", toml::to_string(c).expect("configs serialise"))
    }

    /// The run a key names (the inverse of [`Run::key`]).
    pub fn from_key(key: &str) -> Result<Run, String> {
        let (tag, text) = key.split_once('\n').unwrap_or((key, ""));
        let config = || Config::parse(text, "calibration run request").map_err(|e| e.to_string());
        match tag {
            "compression" => Ok(Run::Compression(config()?)),
            "sticking" => Ok(Run::Sticking(config()?)),
            other => Err(format!(
                "unknown run kind {other:?}; allowed: compression, sticking"
            )),
        }
    }

    /// A short name for logs.
    pub fn describe(&self) -> String {
        match self {
            Run::Compression(c) => format!(
                "compression of {} monomers (seed {}) at {} m/s",
                c.sample.monomers, c.sample.seed, c.experiment.wall_speed_m_s
            ),
            Run::Sticking(_) => "sticking threshold".to_string(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Output {
    Envelope(Envelope),
    /// Sticking threshold [m/s].
    Sticking(f64),
}

/// One run's result, filled once by whichever thread asks first.
type Slot = Arc<OnceLock<Result<Output, String>>>;

/// Results of runs already made, shared by every calibration that holds the cache; with a
/// directory, also kept on disk (one file per run, named by a hash of its config and holding
/// the config itself), so an interrupted or repeated calibration does not repeat a run. Several
/// processes may fill one cache directory at once ([`entry_lock`]).
#[derive(Default)]
pub struct RunCache {
    slots: Mutex<HashMap<String, Slot>>,
    dir: Option<PathBuf>,
    /// Make missing runs as Slurm job arrays ([`super::slurm`]) before reading them here.
    slurm: Option<SlurmRuns>,
    /// Only read the directory: a run it does not hold is an error, never simulated (a
    /// report rebuilt from a committed cache).
    read_only: bool,
    /// Runs this process simulated (not read back from disk or another process).
    made: AtomicUsize,
    /// Seconds each run this process simulated took (on its one thread), by key.
    costs: Mutex<HashMap<String, f64>>,
}

impl RunCache {
    pub fn new() -> Self {
        Self::default()
    }

    /// A cache that also stores every finished run in `dir` and reads it back from there.
    pub fn persistent(dir: &Path) -> Self {
        RunCache {
            dir: Some(dir.to_path_buf()),
            ..Self::default()
        }
    }

    /// A persistent cache that only reads `dir`: a missing run is an error, not a simulation.
    pub fn read_only(dir: &Path) -> Self {
        RunCache {
            read_only: true,
            ..Self::persistent(dir)
        }
    }

    /// A persistent cache whose missing runs are made on Slurm, a job array per batch.
    pub fn on_slurm(dir: &Path, slurm: SlurmRuns) -> Self {
        RunCache {
            slurm: Some(slurm),
            ..Self::persistent(dir)
        }
    }

    /// Where the cache keeps `run` on disk (none for a cache in memory only).
    pub fn entry_path(&self, run: &Run) -> Option<PathBuf> {
        let key = run.key();
        self.dir
            .as_ref()
            .map(|d| d.join(format!("{:016x}.run", fnv1a64(key.as_bytes()))))
    }

    /// Whether `run` is done: in memory or stored.
    fn holds(&self, run: &Run) -> bool {
        let key = run.key();
        let in_memory = self
            .slots
            .lock()
            .map(|s| s.get(&key).is_some_and(|slot| slot.get().is_some()))
            .unwrap_or(false);
        in_memory
            || self
                .entry_path(run)
                .is_some_and(|p| stored::read(&p, &key).is_some())
    }

    /// On Slurm: makes every run of `runs` the cache does not hold as one job array.
    fn make_on_slurm(&self, runs: &[Run]) -> Result<(), String> {
        let (Some(slurm), Some(dir)) = (&self.slurm, &self.dir) else {
            return Ok(());
        };
        let mut missing: Vec<&Run> = Vec::new();
        for run in runs {
            if !self.holds(run) && !missing.contains(&run) {
                missing.push(run);
            }
        }
        if missing.is_empty() {
            return Ok(());
        }
        run_batch(slurm, dir, &missing, &|line| eprintln!("{line}")).map(|_| ())
    }

    /// The output of `run`, simulated on first request. Concurrent requests for the same run
    /// wait for the first instead of repeating it.
    pub fn get(&self, run: &Run) -> Result<Output, String> {
        let key = run.key();
        let slot = {
            let mut slots = self.slots.lock().unwrap_or_else(|e| e.into_inner());
            Arc::clone(slots.entry(key.clone()).or_default())
        };
        slot.get_or_init(|| {
            let Some(dir) = &self.dir else {
                return self.simulate_timed(run, &key);
            };
            let path = dir.join(format!("{:016x}.run", fnv1a64(key.as_bytes())));
            if let Some(out) = stored::read(&path, &key) {
                return Ok(out);
            }
            if self.read_only {
                return Err(format!(
                    "{} is not in the run cache {} (read only: --cache-only)",
                    run.describe(),
                    dir.display()
                ));
            }
            if self.slurm.is_some() {
                // Its array task did not store it: say so rather than make it here.
                return Err(format!(
                    "{} was not made by its Slurm array task (see the task logs under {})",
                    run.describe(),
                    dir.join("slurm").display()
                ));
            }
            let _entry = match entry_lock(&path, &key) {
                Ok(lock) => lock,
                Err(out) => return Ok(out),
            };
            let out = self.simulate_timed(run, &key);
            if let Ok(o) = &out {
                // A cache that cannot be written costs a repeat next time, nothing else.
                let _ = std::fs::create_dir_all(dir)
                    .and_then(|_| write_atomic(&path, stored::write(&key, o).as_bytes()));
            }
            out
        })
        .clone()
    }

    fn simulate_timed(&self, run: &Run, key: &str) -> Result<Output, String> {
        self.made.fetch_add(1, Ordering::Relaxed);
        // Wall-clock: the engine may run a small sample on a pool thread, so the calling
        // thread's CPU time would miss it; with one run per core this is the run's CPU time.
        let start = std::time::Instant::now();
        let out = simulate(run);
        let seconds = start.elapsed().as_secs_f64();
        if let Ok(mut costs) = self.costs.lock() {
            costs.insert(key.to_string(), seconds);
        }
        out
    }

    /// The seconds `run` took, where this process simulated it.
    pub fn cost(&self, run: &Run) -> Option<f64> {
        self.costs.lock().ok()?.get(&run.key()).copied()
    }

    /// How many runs this process simulated itself.
    pub fn made(&self) -> usize {
        self.made.load(Ordering::Relaxed)
    }

    pub fn len(&self) -> usize {
        self.slots.lock().map(|s| s.len()).unwrap_or(0)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Entries are written atomically (renamed into place), so processes sharing a cache never
/// read a partial entry; the lock beside an entry (`<entry>.lock`) only keeps two of them from
/// making the same run. Returns the lock to hold while making the run (none where the cache
/// cannot be locked, or its holder runs on another host and may be gone: then the run is made
/// here too, which costs time but nothing else), or the entry another process finished while
/// this one waited for it.
fn entry_lock(path: &Path, key: &str) -> Result<Option<Lock>, Output> {
    let mut lock_path = path.as_os_str().to_owned();
    lock_path.push(".lock");
    loop {
        match try_lock(Path::new(&lock_path)) {
            Ok(Ok(lock)) => {
                // Finished by another process between the first look and the lock.
                return match stored::read(path, key) {
                    Some(out) => Err(out),
                    None => Ok(Some(lock)),
                };
            }
            Ok(Err(holder)) if holder.host == host_name() => {
                std::thread::sleep(std::time::Duration::from_millis(250));
                if let Some(out) = stored::read(path, key) {
                    return Err(out);
                }
            }
            Ok(Err(_)) | Err(_) => return Ok(None),
        }
    }
}

/// Runs `runs` on `threads` threads (at least one) and returns their outputs in order.
/// `done` is called after each run with (finished, total).
pub fn run_all(
    runs: &[Run],
    cache: &RunCache,
    threads: usize,
    done: &(dyn Fn(usize, usize) + Sync),
) -> Vec<Result<Output, String>> {
    if let Err(e) = cache.make_on_slurm(runs) {
        return runs.iter().map(|_| Err(e.clone())).collect();
    }
    let next = AtomicUsize::new(0);
    let finished = AtomicUsize::new(0);
    let results: Vec<Mutex<Option<Result<Output, String>>>> =
        runs.iter().map(|_| Mutex::new(None)).collect();
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1).min(runs.len().max(1)) {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= runs.len() {
                    break;
                }
                let out = cache.get(&runs[k]);
                *results[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(out);
                done(finished.fetch_add(1, Ordering::Relaxed) + 1, runs.len());
            });
        }
    });
    results
        .into_iter()
        .map(|r| {
            r.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .unwrap_or_else(|| Err("run not made".into()))
        })
        .collect()
}

/// The compression of one sample for a measured curve: geometry and, where the data give it,
/// wall speed from the data (a dynamic curve depends on its speed); sample size, time step,
/// physics and otherwise the wall speed from `base`. It stops once the pressure passes ten
/// times the highest measured one (φ_stop is raised out of the way).
pub fn compression_config(
    base: &Config,
    geometry: Geometry,
    wall_speed: Option<f64>,
    seed: u64,
    p_max: f64,
) -> Config {
    let mut c = base.clone();
    let e = &mut c.experiment;
    if let Some(v) = wall_speed {
        e.wall_speed_m_s = v;
    }
    e.kind = match geometry {
        Geometry::Omni => ExperimentKind::Omni,
        Geometry::Uni => ExperimentKind::Uni,
    };
    e.pressure_stop_pa = PRESSURE_STOP_MARGIN * p_max;
    e.phi_stop = 0.74;
    e.profile_every_rows = 0;
    c.sample.source = SampleSource::Rbd;
    c.sample.file = None;
    c.sample.seed = seed;
    c.sample.footprint = match geometry {
        Geometry::Omni => FootprintKind::Box,
        Geometry::Uni => FootprintKind::Cylinder,
    };
    c
}

/// The head-on collision run for `base`'s contact law.
pub fn sticking_config(base: &Config) -> Config {
    let mut c = base.clone();
    c.experiment.kind = ExperimentKind::Collision;
    c
}

fn simulate(run: &Run) -> Result<Output, String> {
    match run {
        Run::Compression(config) => {
            let mut compression =
                Compression::with_engine(config, reference_engine).map_err(|e| e.to_string())?;
            let mut rows = Vec::new();
            let result = compression.run(&mut |event| {
                if let Event::Row(r) = event {
                    if r.p_top.is_finite() {
                        rows.push((r.phi, r.p_top));
                    }
                }
                Ok(())
            });
            // A guard firing deep in the compression (a monomer squeezed through a wall)
            // keeps the curve measured until then; pressures not reached count as uncovered.
            let failure = match result {
                Ok(_) => None,
                Err(e) if rows.len() > MEDIAN_ROWS => Some(e.to_string()),
                Err(e) => return Err(e.to_string()),
            };
            let mut envelope = Envelope::from_rows(&rows);
            envelope.failure = failure;
            Ok(Output::Envelope(envelope))
        }
        Run::Sticking(config) => sticking_threshold_m_s(config).map(Output::Sticking),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_is_monotone_and_ignores_single_spikes() {
        // φ rises linearly; P rises by a decade per 0.1 in φ with one spike of 10⁶ Pa.
        let rows: Vec<(f64, f64)> = (0..60)
            .map(|k| {
                let phi = 0.1 + 0.005 * k as f64;
                let p = if k == 10 {
                    1e6
                } else {
                    10f64.powf(2.0 + (phi - 0.1) * 10.0)
                };
                (phi, p)
            })
            .collect();
        let env = Envelope::from_rows(&rows);
        assert!(env.log10_p.windows(2).all(|w| w[1] >= w[0]));
        // The spike does not count: 1e3 Pa is first held at φ ≈ 0.2.
        assert!((env.phi_at(1e3) - 0.2).abs() < 0.006, "{}", env.phi_at(1e3));
        assert!(env.phi_at(1e9).is_nan());
        assert_eq!(env.phi_at(1.0), 0.1);
    }

    #[test]
    fn stored_runs_read_back_exactly_and_only_for_their_own_config() {
        let dir = std::env::temp_dir().join(format!("dustdem-run-cache-{}", std::process::id()));
        let e = Envelope {
            phi: vec![0.15, 0.1 + 0.2],
            log10_p: vec![2.0, f64::from_bits(0x4010_0000_0000_0001)],
            failure: Some("wall\nguard".into()),
        };
        for (k, out) in [Output::Envelope(e), Output::Sticking(1.2345678901234567)]
            .into_iter()
            .enumerate()
        {
            let path = dir.join(format!("{k}.run"));
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, stored::write("key\nwith lines", &out)).unwrap();
            let back = stored::read(&path, "key\nwith lines").unwrap();
            match (&back, &out) {
                (Output::Envelope(a), Output::Envelope(b)) => {
                    assert_eq!(a.phi, b.phi);
                    assert_eq!(a.log10_p, b.log10_p);
                    assert_eq!(a.failure.as_deref(), Some("wall guard"));
                }
                _ => assert_eq!(back, out),
            }
            assert!(stored::read(&path, "another key").is_none());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_read_only_cache_reads_what_it_holds_and_refuses_the_rest() {
        let dir = std::env::temp_dir().join(format!("dustdem-read-only-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let held = Run::Sticking(Config::default());
        let mut other = Config::default();
        other.sample.seed = 2;
        let missing = Run::Sticking(other);
        let path = RunCache::persistent(&dir).entry_path(&held).unwrap();
        std::fs::write(&path, stored::write(&held.key(), &Output::Sticking(1.5))).unwrap();
        let cache = RunCache::read_only(&dir);
        assert_eq!(cache.get(&held), Ok(Output::Sticking(1.5)));
        let err = cache.get(&missing).unwrap_err();
        assert!(err.contains("not in the run cache"), "{err}");
        // Nothing was simulated or written.
        assert_eq!(cache.made(), 0);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
