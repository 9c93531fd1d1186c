//! The exceptions the bindings raise, and the conversions of the library's errors into them:
//! every binding converts through here, so one failure raises one kind everywhere.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::fmt::Display;

create_exception!(
    _dustdem,
    ConfigError,
    PyValueError,
    "A configuration problem: the message names the file, the field, the value and what is \
     allowed (the attributes `file`, `field`, `value` and `allowed` hold them one by one)."
);

create_exception!(
    _dustdem,
    RunError,
    PyRuntimeError,
    "A run that could not be set up or continued (sample, engine, output files)."
);

/// A [`ConfigError`] carrying the same message as the command line, with its parts attached.
fn config_error(py: Python<'_>, e: &dustdem::config::ConfigError) -> PyErr {
    let err = ConfigError::new_err(e.to_string());
    let value = err.value(py);
    for (name, text) in [
        ("file", &e.file),
        ("field", &e.field),
        ("value", &e.value),
        ("allowed", &e.allowed),
    ] {
        // Attributes are a convenience: the message already holds them.
        let _ = value.setattr(name, text);
    }
    err
}

/// The library's errors (messages, or types that print one) as Python exceptions.
pub trait OrRaise<T> {
    /// A [`RunError`]: a run, a file or a tool that failed.
    fn or_run_error(self) -> PyResult<T>;
    /// A `ValueError`: an argument the library refused.
    fn or_value_error(self) -> PyResult<T>;
}

impl<T, E: Display> OrRaise<T> for Result<T, E> {
    fn or_run_error(self) -> PyResult<T> {
        self.map_err(|e| RunError::new_err(e.to_string()))
    }

    fn or_value_error(self) -> PyResult<T> {
        self.map_err(|e| PyValueError::new_err(e.to_string()))
    }
}

/// A config problem as a [`ConfigError`] with its parts attached (they need the GIL).
pub trait OrConfigError<T> {
    fn or_config_error(self, py: Python<'_>) -> PyResult<T>;
}

impl<T> OrConfigError<T> for Result<T, dustdem::config::ConfigError> {
    fn or_config_error(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| config_error(py, &e))
    }
}

/// A count argument (`threads`, `jobs`) must lie in 1..=1024; else a `ValueError` naming it.
pub fn check_count(name: &str, n: usize) -> PyResult<()> {
    if (1..=1024).contains(&n) {
        Ok(())
    } else {
        Err(PyValueError::new_err(format!(
            "{name} {n}: out of range; allowed 1 to 1024"
        )))
    }
}
