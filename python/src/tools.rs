//! The library's tools besides a single run: CSV tables, RBD samples, the Eq. 13 fit, sweeps
//! and calibrations.

use crate::errors::{check_count, OrConfigError, OrRaise};
use crate::job::thread_pool;
use dustdem::analysis::fit::{fit_eq13 as fit, Eq13, FitOptions};
use dustdem::calibrate::{run_calibration, run_plan, RunCache, Settings};
use dustdem::config::{
    Config, ConfigError, ExperimentKind, FootprintKind, SampleSource, SampleTop,
};
use dustdem::experiment::setup::build_sample;
use dustdem::output::lock::lock_dir;
use dustdem::sample::{interior_filling_factor, Footprint};
use dustdem::sweep::collect::collect;
use dustdem::sweep::{run_cases, write_case_list, RunSettings, Sweep};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// A CSV table as dustdem writes them: its header and its rows as native-endian f64 bytes
/// (row after row), for numpy's `frombuffer`.
#[pyfunction]
pub fn read_csv(py: Python<'_>, path: PathBuf) -> PyResult<(Vec<String>, Py<PyBytes>, usize)> {
    let (header, rows) = dustdem::output::csv::read_csv(&path).or_run_error()?;
    let flat: Vec<u8> = rows
        .iter()
        .flat_map(|r| r.iter().flat_map(|v| v.to_ne_bytes()))
        .collect();
    Ok((header, PyBytes::new(py, &flat).unbind(), rows.len()))
}

fn sample_error(field: &str, value: &str, allowed: &str) -> ConfigError {
    ConfigError {
        file: "rbd_sample".into(),
        field: field.into(),
        value: value.into(),
        allowed: allowed.into(),
    }
}

/// The config an RBD sample is built from: `config` (TOML text) or the defaults, with the
/// sample section set from the arguments.
fn sample_config(
    config: Option<&str>,
    monomers: usize,
    seed: u64,
    footprint: &str,
    top: &str,
    size_um: f64,
) -> Result<Config, ConfigError> {
    let mut c = match config {
        Some(text) => Config::parse(text, "rbd_sample config")?,
        None => Config::default(),
    };
    let s = &mut c.sample;
    s.source = SampleSource::Rbd;
    s.monomers = monomers;
    s.seed = seed;
    s.footprint = match footprint {
        "box" => FootprintKind::Box,
        "cylinder" => FootprintKind::Cylinder,
        _ => {
            return Err(sample_error(
                "[sample] footprint",
                footprint,
                "\"box\" or \"cylinder\"",
            ))
        }
    };
    s.top = match top {
        "rough" => SampleTop::Rough,
        "cut" => SampleTop::Cut,
        _ => return Err(sample_error("[sample] top", top, "\"rough\" or \"cut\"")),
    };
    match s.footprint {
        FootprintKind::Box => s.side_um = size_um,
        FootprintKind::Cylinder => {
            s.cylinder_radius_um = size_um;
            // Only the two-plate compression takes a cylinder; the sample is the same.
            if c.experiment.kind == ExperimentKind::Omni {
                c.experiment.kind = ExperimentKind::Uni;
            }
        }
    }
    c.validate("rbd_sample")?;
    Ok(c)
}

/// A sample by random ballistic deposition, as a run builds it (contacts at the equilibrium
/// distance). `size_um` is the box side or the cylinder radius (0: automatic). Positions are
/// returned in µm as native-endian f64 bytes, x, y, z per monomer in deposition order.
#[pyfunction]
#[pyo3(signature = (monomers, seed=1, footprint="box", top="rough", size_um=0.0, config=None))]
pub fn rbd_sample(
    py: Python<'_>,
    monomers: usize,
    seed: u64,
    footprint: &str,
    top: &str,
    size_um: f64,
    config: Option<&str>,
) -> PyResult<PyObject> {
    let config =
        sample_config(config, monomers, seed, footprint, top, size_um).or_config_error(py)?;
    let law = config.contact_law();
    let sample = py
        .allow_threads(|| build_sample(&config, &law))
        .or_run_error()?;
    let bytes: Vec<u8> = sample
        .positions
        .iter()
        .flat_map(|p| p.iter().flat_map(|v| (v * 1e4).to_ne_bytes()))
        .collect();
    let d = PyDict::new(py);
    d.set_item("positions_um", PyBytes::new(py, &bytes))?;
    d.set_item("monomers", sample.positions.len())?;
    d.set_item("seed", sample.seed)?;
    d.set_item("radius_um", sample.radius * 1e4)?;
    match sample.footprint {
        Footprint::Box { side } => {
            d.set_item("footprint", "box")?;
            d.set_item("size_um", side * 1e4)?;
        }
        Footprint::Cylinder { radius } => {
            d.set_item("footprint", "cylinder")?;
            d.set_item("size_um", radius * 1e4)?;
        }
    }
    d.set_item("height_um", (sample.z_max() + sample.radius) * 1e4)?;
    d.set_item("filling_factor_bulk", sample.filling_factor_bulk())?;
    d.set_item("interior_filling_factor", interior_filling_factor(&sample))?;
    Ok(d.into_any().unbind())
}

fn params_dict<'py>(py: Python<'py>, p: &Eq13) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("phi1", p.phi1)?;
    d.set_item("phi2", p.phi2)?;
    d.set_item("p_m", p.p_m)?;
    d.set_item("delta", p.delta)?;
    Ok(d)
}

/// Fits Eq. 13 of Seizinger et al. (2012) to filling factors `phi` at pressures `p` [Pa].
#[pyfunction]
#[pyo3(signature = (p, phi, sigma=None, fix_phi1=None, fix_phi2=None, max_iterations=200))]
pub fn fit_eq13(
    py: Python<'_>,
    p: Vec<f64>,
    phi: Vec<f64>,
    sigma: Option<Vec<f64>>,
    fix_phi1: Option<f64>,
    fix_phi2: Option<f64>,
    max_iterations: usize,
) -> PyResult<PyObject> {
    let options = FitOptions {
        fix_phi1,
        fix_phi2,
        initial: None,
        max_iterations,
    };
    let r = fit(&p, &phi, sigma.as_deref(), &options).or_value_error()?;
    let d = params_dict(py, &r.params)?;
    d.set_item("std_err", params_dict(py, &r.std_err)?)?;
    d.set_item("std_err_log10_p_m", r.std_err_log10_pm)?;
    d.set_item("correlation", r.correlation)?;
    d.set_item("free", r.free)?;
    d.set_item("rss", r.rss)?;
    d.set_item("chi2_per_dof", r.chi2_per_dof)?;
    d.set_item("dof", r.dof)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("converged", r.converged)?;
    Ok(d.into_any().unbind())
}

/// φ(P) of a compression read as the sweep analysis and the calibration read it: the running
/// maximum of the median-smoothed log₁₀P per row (rows of `phi`, `p` in time order). Returns
/// log₁₀P per row (-10 where no pressure had been held yet).
#[pyfunction]
pub fn envelope_log10_p(phi: Vec<f64>, p: Vec<f64>) -> PyResult<Vec<f64>> {
    if phi.len() != p.len() {
        return Err(PyValueError::new_err(format!(
            "phi has {} rows, p {}",
            phi.len(),
            p.len()
        )));
    }
    let rows: Vec<(f64, f64)> = phi.into_iter().zip(p).collect();
    Ok(dustdem::analysis::envelope::Envelope::from_rows(&rows).log10_p)
}

/// (φ₁, φ₂, p_m [Pa], Δ) of a law.
pub fn law_tuple(law: &Eq13) -> (f64, f64, f64, f64) {
    (law.phi1, law.phi2, law.p_m, law.delta)
}

/// φ(P) of Eq. 13 with the given parameters at each pressure of `p` [Pa].
#[pyfunction]
pub fn eq13_phi(phi1: f64, phi2: f64, p_m: f64, delta: f64, p: Vec<f64>) -> Vec<f64> {
    let law = Eq13 {
        phi1,
        phi2,
        p_m,
        delta,
    };
    p.iter().map(|&x| law.phi(x)).collect()
}

/// Calls `progress` (if any) with `line`, after checking for signals; true if either raised.
fn say_line(progress: &Option<PyObject>, line: &str, error: &std::sync::Mutex<Option<PyErr>>) {
    Python::with_gil(|py| {
        let outcome = py.check_signals().and_then(|()| match progress {
            Some(cb) => cb.call1(py, (line,)).map(drop),
            None => Ok(()),
        });
        if let Err(e) = outcome {
            error.lock().unwrap().get_or_insert(e);
        }
    });
}

/// Runs every case of the sweep file `path` (finished cases skipped, interrupted ones resumed),
/// each as a child process of the command-line program `exe`, `jobs` at once; then writes the
/// sweep table. SIGINT/SIGTERM stop it as they stop `dustdem sweep`.
#[pyfunction]
#[pyo3(signature = (path, exe, out=None, jobs=1, threads=None, backend="cpu", precision="auto", progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    py: Python<'_>,
    path: PathBuf,
    exe: PathBuf,
    out: Option<PathBuf>,
    jobs: usize,
    threads: Option<usize>,
    backend: &str,
    precision: &str,
    progress: Option<PyObject>,
) -> PyResult<PyObject> {
    let precision = crate::job::parse_precision(precision)?;
    let spec = Sweep::load(&path).or_config_error(py)?;
    let out_dir = std::path::absolute(spec.out_dir(out.as_deref()))?;
    let cases = spec.cases(&out_dir).or_config_error(py)?;
    check_count("jobs", jobs)?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = threads.unwrap_or((cores / jobs).max(1));
    let settings = RunSettings {
        jobs,
        threads,
        backend: backend.to_string(),
        precision: precision.as_str().to_string(),
        exe,
    };
    let _lock = lock_dir(&out_dir).or_run_error()?;
    write_case_list(&spec, &out_dir, &cases).or_run_error()?;
    let flag = Arc::new(AtomicBool::new(false));
    let ids = stop_on_signals(&flag);
    let error = std::sync::Mutex::new(None);
    let outcome = py.allow_threads(|| {
        let mut say = |line: &str| say_line(&progress, line, &error);
        run_cases(&cases, cases.len(), &out_dir, &settings, &flag, &mut say)
    });
    for id in ids {
        signal_hook::low_level::unregister(id);
    }
    let outcome = outcome.or_run_error()?;
    let collected = collect(&out_dir).or_run_error()?;
    py.check_signals()?;
    if let Some(e) = error.lock().unwrap().take() {
        return Err(e);
    }
    let d = PyDict::new(py);
    d.set_item("out_dir", out_dir.display().to_string())?;
    d.set_item("table", collected.table.display().to_string())?;
    d.set_item("done", outcome.done)?;
    d.set_item("skipped", outcome.skipped)?;
    d.set_item("failed", outcome.failed)?;
    d.set_item("interrupted", outcome.interrupted)?;
    d.set_item("not_started", outcome.not_started)?;
    Ok(d.into_any().unbind())
}

/// SIGINT and SIGTERM raise `flag` (Python's own handler still runs after ours).
fn stop_on_signals(flag: &Arc<AtomicBool>) -> Vec<signal_hook::SigId> {
    [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM]
        .into_iter()
        .filter_map(|s| signal_hook::flag::register(s, Arc::clone(flag)).ok())
        .collect()
}

/// Calibrates the config's model against measured curves (or, with `plan`, only estimates
/// what they can resolve); writes the report into `out` and returns its lines and files.
#[pyfunction]
#[pyo3(signature = (measured, config, out, seeds=None, rounds=2, threads=None, plan=false, cache=None, progress=None, screen_seeds=1, screen_monomers=0, prune=true, screen_both_ends=true, revisit=false, cache_only=false))]
pub fn calibrate(
    py: Python<'_>,
    measured: Vec<PathBuf>,
    config: PathBuf,
    out: PathBuf,
    seeds: Option<Vec<u64>>,
    rounds: usize,
    threads: Option<usize>,
    plan: bool,
    cache: Option<PathBuf>,
    progress: Option<PyObject>,
    screen_seeds: usize,
    screen_monomers: usize,
    prune: bool,
    screen_both_ends: bool,
    revisit: bool,
    cache_only: bool,
) -> PyResult<(Vec<String>, Vec<String>)> {
    let mut settings = Settings {
        max_rounds: rounds,
        screen_seeds,
        screen_monomers,
        prune,
        both_ends: screen_both_ends,
        revisit,
        ..Settings::default()
    };
    if let Some(s) = seeds {
        settings.seeds = s;
    }
    if let Some(t) = threads {
        thread_pool(Some(t))?;
        settings.threads = t;
    }
    let _lock = lock_dir(&out).or_run_error()?;
    let cache_dir = cache.unwrap_or_else(|| out.join("run_cache"));
    let cache = match cache_only {
        true => RunCache::read_only(&cache_dir),
        false => RunCache::persistent(&cache_dir),
    };
    let error = std::sync::Mutex::new(None);
    let result = py.allow_threads(|| {
        let say = |line: &str| say_line(&progress, line, &error);
        let run = if plan { run_plan } else { run_calibration };
        run(&measured, &config, &out, &settings, &cache, &say)
    });
    if let Some(e) = error.lock().unwrap().take() {
        return Err(e);
    }
    let (lines, files) = result.or_run_error()?;
    Ok((lines, files.iter().map(|f| display(f)).collect()))
}

fn display(path: &Path) -> String {
    path.display().to_string()
}
