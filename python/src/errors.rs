//! The exceptions the bindings raise, and the conversions of the library's errors into them.

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

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
pub fn config_error(py: Python<'_>, e: &dustdem::config::ConfigError) -> PyErr {
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

/// A [`RunError`] with `message`.
pub fn run_error(message: impl Into<String>) -> PyErr {
    RunError::new_err(message.into())
}
