//! `dustdem._dustdem`: the compiled half of the `dustdem` Python package.
//!
//! Thin bindings over the simulator's library: `job` runs and resumes compressions (the
//! engine runs with the GIL released; Ctrl-C stops it at the next row with a checkpoint
//! written), `tools` wraps the sample generator, the Eq. 13 fit, CSV reading, sweeps and
//! calibrations. The Python package (`python/dustdem/`) turns what these return into numpy
//! arrays and result objects.

// Each Python function takes its keyword arguments one by one, as Python callers see them.
#![allow(clippy::too_many_arguments)]

mod errors;
mod job;
mod tools;

use pyo3::prelude::*;

#[pymodule]
fn _dustdem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ConfigError", py.get_type::<errors::ConfigError>())?;
    m.add("RunError", py.get_type::<errors::RunError>())?;
    m.add("VERSION", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULT_CONFIG", dustdem::job::DEFAULT_CONFIG.to_string())?;
    m.add("RESUMABLE_EXIT", dustdem::RESUMABLE_EXIT)?;
    m.add(
        "GUETTLER_2009_OMNI",
        tools::law_tuple(&dustdem::job::GUETTLER_2009_OMNI),
    )?;
    m.add(
        "BLUM_SCHRAEPLER_2004_UNI",
        tools::law_tuple(&dustdem::job::BLUM_SCHRAEPLER_2004_UNI),
    )?;
    m.add_function(wrap_pyfunction!(job::run_config, m)?)?;
    m.add_function(wrap_pyfunction!(job::resume_checkpoint, m)?)?;
    m.add_function(wrap_pyfunction!(job::check_config, m)?)?;
    m.add_function(wrap_pyfunction!(tools::read_csv, m)?)?;
    m.add_function(wrap_pyfunction!(tools::rbd_sample, m)?)?;
    m.add_function(wrap_pyfunction!(tools::fit_eq13, m)?)?;
    m.add_function(wrap_pyfunction!(tools::eq13_phi, m)?)?;
    m.add_function(wrap_pyfunction!(tools::envelope_log10_p, m)?)?;
    m.add_function(wrap_pyfunction!(tools::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(tools::calibrate, m)?)?;
    Ok(())
}
