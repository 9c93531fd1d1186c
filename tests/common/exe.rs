//! The built `dustdem` binary, run to its end as a child process of a test.

use std::ffi::{OsStr, OsString};
use std::process::{Command, Output};

/// The binary Cargo builds for the integration tests.
pub const EXE: &str = env!("CARGO_BIN_EXE_dustdem");

/// Runs `dustdem ARGS`; its exit status and what it printed.
pub fn dustdem<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    Command::new(EXE).args(args).output().expect("dustdem runs")
}

/// Runs `dustdem ARGS` and asserts that it succeeded; the failure message holds the arguments
/// and what the binary wrote to stderr.
pub fn dustdem_ok<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let args: Vec<OsString> = args.into_iter().map(|a| a.as_ref().to_owned()).collect();
    let out = dustdem(&args);
    assert!(
        out.status.success(),
        "dustdem {args:?} failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}
