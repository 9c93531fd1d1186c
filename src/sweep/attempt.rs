//! How an attempt at a case ended, read from its exit status, its log and its curve.

use super::{Attempt, Case, CaseStatus, LOG_FILE};
use crate::output::csv::read_csv;
use crate::output::run_dir::{read_run_id, CURVE_FILE};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;
use std::process::ExitStatus;

/// The status an attempt ended in: done (exit 0), interrupted (stopped by a signal it was
/// asked to stop by, or the sweep's) or failed, with the final row of its curve.
pub(super) fn conclude(
    case: &Case,
    dir: &Path,
    attempt: &Attempt,
    status: ExitStatus,
    interrupted: bool,
) -> CaseStatus {
    let printed = read_from(&dir.join(LOG_FILE), attempt.log_offset);
    let stop = printed
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("stopped at step "))
        .and_then(|l| l.split_once("): "))
        .map_or(String::new(), |(_, why)| why.trim().to_string());
    let error = printed
        .lines()
        .filter_map(|l| l.strip_prefix("error: "))
        .next_back()
        .map(str::to_string);
    let (steps, phi, pressure) = last_row(&dir.join(CURVE_FILE));
    let previous_seconds = attempt.previous.as_ref().map_or(0.0, |p| p.wall_clock_s);
    let mut record = CaseStatus {
        case: case.name.clone(),
        status: String::new(),
        run_id: read_run_id(dir).unwrap_or_default(),
        attempts: attempt.previous.as_ref().map_or(0, |p| p.attempts) + 1,
        wall_clock_s: previous_seconds + attempt.started.elapsed().as_secs_f64(),
        resumed_from_step: attempt.resumed_from_step,
        steps,
        final_phi: phi,
        final_pressure_pa: pressure,
        stop: String::new(),
        message: String::new(),
    };
    use std::os::unix::process::ExitStatusExt;
    if status.success() {
        record.status = "done".into();
        record.stop = stop;
    } else if let Some(signal) = status.signal() {
        record.status = "interrupted".into();
        record.message = format!(
            "killed by signal {signal}; run the sweep again to continue from the last checkpoint"
        );
    } else if interrupted
        || error
            .as_deref()
            .is_some_and(|e| e.starts_with("interrupted"))
    {
        record.status = "interrupted".into();
        record.message = "stopped by a signal after writing a checkpoint; run the sweep again \
                          to resume it"
            .into();
    } else {
        record.status = "failed".into();
        record.message = error.unwrap_or_else(|| {
            format!(
                "exit status {}",
                status.code().map_or("?".into(), |c| c.to_string())
            )
        });
    }
    record
}

/// What a file holds from byte `offset` on (lossy UTF-8; empty if it cannot be read).
fn read_from(path: &Path, offset: u64) -> String {
    let mut bytes = Vec::new();
    if let Ok(mut f) = File::open(path) {
        if f.seek(SeekFrom::Start(offset)).is_ok() {
            let _ = f.read_to_end(&mut bytes);
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Step, φ and top-wall pressure of a curve's last row (none where there is no row).
pub fn last_row(curve: &Path) -> (Option<u64>, Option<f64>, Option<f64>) {
    let Ok((header, rows)) = read_csv(curve) else {
        return (None, None, None);
    };
    let Some(last) = rows.last() else {
        return (None, None, None);
    };
    let column = |name: &str| header.iter().position(|h| h == name).map(|k| last[k]);
    (
        column("step").map(|s| s as u64),
        column("phi"),
        column("p_top_pa"),
    )
}

/// Asks a running case to checkpoint and stop, as Ctrl-C or a scheduler's SIGTERM would.
pub(super) fn terminate(pid: u32) {
    if let Ok(pid) = libc::pid_t::try_from(pid) {
        // SAFETY: kill(2) with a child's pid and a signal number has no memory effects.
        unsafe {
            libc::kill(pid, libc::SIGTERM);
        }
    }
}
