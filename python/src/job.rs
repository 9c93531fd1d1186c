//! Running and resuming a compression from Python.
//!
//! The job runs with the GIL released. Once per row the GIL is taken back for a moment: pending
//! signals are checked (Ctrl-C raises KeyboardInterrupt there) and the progress callback is
//! called. Either raising sets the job's stop flag, so the run writes its checkpoint at that row
//! and stops, as the command line does on SIGINT; the exception is then raised in Python with
//! the checkpoint's path as its `checkpoint` attribute.

use crate::errors::{check_count, OrConfigError, OrRaise};
use dustdem::config::Config;
use dustdem::experiment::compression::RunError;
use dustdem::job::{
    resume_job, run_job, Backend, JobOptions, JobSummary, PrecisionChoice, PrivateRuntimeDir,
    Progress,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// Reads and validates a config: from the file `path`, or from TOML `text` (named `name` in
/// messages). A problem raises `ConfigError`.
fn load(py: Python<'_>, text: Option<&str>, path: Option<&str>, name: &str) -> PyResult<Config> {
    let loaded = match (text, path) {
        (Some(text), None) => Config::parse(text, name),
        (None, Some(path)) => Config::load(Path::new(path)),
        _ => return Err(PyValueError::new_err("give exactly one of text and path")),
    };
    loaded.or_config_error(py)
}

/// Validates a config (TOML `text` or the file `path`); raises ConfigError on a problem and
/// returns the output directory the config names.
#[pyfunction]
#[pyo3(signature = (text=None, path=None, name="<config>"))]
pub fn check_config(text: Option<&str>, path: Option<&str>, name: &str) -> PyResult<String> {
    Python::with_gil(|py| load(py, text, path, name)).map(|c| c.output.dir.display().to_string())
}

/// Runs a config into `out` (default: the config's `[output] dir`); returns the job summary as
/// a dict (`out_dir`, `files`, `lines`).
#[pyfunction]
#[pyo3(signature = (text=None, path=None, name="<config>", out=None, backend="cpu", threads=None, force=false, progress=None, precision="auto"))]
pub fn run_config(
    py: Python<'_>,
    text: Option<&str>,
    path: Option<&str>,
    name: &str,
    out: Option<PathBuf>,
    backend: &str,
    threads: Option<usize>,
    force: bool,
    progress: Option<PyObject>,
    precision: &str,
) -> PyResult<PyObject> {
    let config = load(py, text, path, name)?;
    let out_dir = out.unwrap_or_else(|| config.output.dir.clone());
    let engine = (backend, precision);
    drive(py, engine, threads, progress, |options| {
        run_job(&config, &out_dir, force, options)
    })
}

/// Continues the run a checkpoint belongs to, in its directory; returns the job summary.
#[pyfunction]
#[pyo3(signature = (checkpoint, backend="cpu", threads=None, progress=None, precision="auto"))]
pub fn resume_checkpoint(
    py: Python<'_>,
    checkpoint: PathBuf,
    backend: &str,
    threads: Option<usize>,
    progress: Option<PyObject>,
    precision: &str,
) -> PyResult<PyObject> {
    drive(py, (backend, precision), threads, progress, |options| {
        resume_job(&checkpoint, options)
    })
}

/// What the hooks share with the job: the stop flag and the first Python error raised.
struct Hooks {
    progress: Option<PyObject>,
    stop: AtomicBool,
    error: Mutex<Option<PyErr>>,
}

impl Hooks {
    /// Checks for signals, then hands `event` to the callback; an exception stops the job.
    fn call(&self, event: impl FnOnce(Python<'_>) -> PyResult<PyObject>) {
        Python::with_gil(|py| {
            let outcome = py.check_signals().and_then(|()| match &self.progress {
                Some(callback) => callback.call1(py, (event(py)?,)).map(drop),
                None => Ok(()),
            });
            if let Err(e) = outcome {
                self.error.lock().unwrap().get_or_insert(e);
                self.stop.store(true, Ordering::SeqCst);
            }
        });
    }
}

/// One row as the progress callback receives it.
fn row_event(py: Python<'_>, p: &Progress) -> PyResult<PyObject> {
    let d = PyDict::new(py);
    let r = p.row;
    d.set_item("step", r.step)?;
    d.set_item("time_s", r.time)?;
    d.set_item("phi", r.phi)?;
    d.set_item("p_top_pa", r.p_top)?;
    d.set_item("p_bottom_pa", r.p_bottom)?;
    d.set_item("contacts", r.contacts)?;
    d.set_item("wall_contacts", r.wall_contacts)?;
    d.set_item("fraction", p.fraction)?;
    d.set_item("steps_per_second", p.steps_per_second)?;
    Ok(d.into_any().unbind())
}

fn parse_backend(backend: &str) -> PyResult<Backend> {
    backend.parse::<Backend>().or_value_error()
}

/// `precision`: "exact", "mixed" or "auto" (ValueError otherwise).
pub fn parse_precision(precision: &str) -> PyResult<PrecisionChoice> {
    precision.parse::<PrecisionChoice>().or_value_error()
}

/// A thread pool of `threads` for the CPU engine (none: rayon's global pool).
pub fn thread_pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    let Some(t) = threads else {
        return Ok(None);
    };
    check_count("threads", t)?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(t)
        .build()
        .map(Some)
        .map_err(|e| format!("threads {t}: {e}"))
        .or_value_error()
}

/// Runs `job` without the GIL on the engine (backend, GPU precision), with the progress and
/// stop hooks, and converts its outcome.
fn drive(
    py: Python<'_>,
    (backend, precision): (&str, &str),
    threads: Option<usize>,
    progress: Option<PyObject>,
    job: impl FnOnce(&mut JobOptions) -> Result<JobSummary, RunError> + Send,
) -> PyResult<PyObject> {
    let backend = parse_backend(backend)?;
    let precision = parse_precision(precision)?;
    let pool = thread_pool(threads)?;
    let hooks = Hooks {
        progress,
        stop: AtomicBool::new(false),
        error: Mutex::new(None),
    };
    let work = || {
        // Keeps the GPU probe's libwayland complaints out of the output, as the CLI does.
        let _runtime = (backend != Backend::Cpu)
            .then(PrivateRuntimeDir::ensure)
            .flatten();
        let mut on_row = |p: &Progress| hooks.call(|py| row_event(py, p));
        let mut on_notice =
            |line: &str| hooks.call(|py| Ok(line.into_pyobject(py)?.into_any().unbind()));
        let mut options = JobOptions {
            progress: &mut on_row,
            interrupt: Some(&hooks.stop),
            backend,
            precision,
            notice: &mut on_notice,
        };
        job(&mut options)
    };
    let result = py.allow_threads(|| match &pool {
        Some(pool) => pool.install(work),
        None => work(),
    });
    if let Some(err) = hooks.error.lock().unwrap().take() {
        if let Err(RunError::Interrupted { checkpoint }) = &result {
            let _ = err
                .value(py)
                .setattr("checkpoint", checkpoint.display().to_string());
        }
        return Err(err);
    }
    let summary = result.or_run_error()?;
    summary_dict(py, &summary)
}

fn summary_dict(py: Python<'_>, s: &JobSummary) -> PyResult<PyObject> {
    let d = PyDict::new(py);
    d.set_item("out_dir", s.out_dir.display().to_string())?;
    let files: Vec<String> = s.files.iter().map(|f| f.display().to_string()).collect();
    d.set_item("files", files)?;
    d.set_item("lines", s.lines.clone())?;
    Ok(d.into_any().unbind())
}
