//! A case directory's state: its status file (`sweep-status.toml`) and where the case stands
//! (done, to resume from its checkpoint, or to run from the start).

use super::{Case, STATUS_FILE};
use crate::output::atomic::write_atomic;
use crate::output::run_dir::{earlier_results, read_run_id, CHECKPOINT_FILE, CONFIG_FILE};
use serde::{Deserialize, Serialize};
use std::fs;
use std::path::{Path, PathBuf};

/// What a case's status file records.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CaseStatus {
    pub case: String,
    /// `running`, `done`, `failed` or `interrupted`.
    pub status: String,
    /// The run id of the directory's run when the status was written.
    pub run_id: String,
    /// Attempts made at the case (a resume is an attempt).
    pub attempts: u32,
    /// Wall-clock seconds of the attempts whose end the sweep saw, summed.
    pub wall_clock_s: f64,
    /// The step the last attempt resumed from (none: it started at step 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resumed_from_step: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub steps: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_phi: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_pressure_pa: Option<f64>,
    /// Why the run stopped (`filling factor reached phi_stop`, ...), for a finished case.
    pub stop: String,
    /// What went wrong, for a failed or interrupted case.
    pub message: String,
}

impl CaseStatus {
    pub fn read(dir: &Path) -> Option<CaseStatus> {
        let text = fs::read_to_string(dir.join(STATUS_FILE)).ok()?;
        toml::from_str(&text).ok()
    }

    pub(super) fn write(&self, dir: &Path) -> Result<(), String> {
        let path = dir.join(STATUS_FILE);
        let text = format!(
            "# dustdem sweep: status of this case (written by the sweep)\n{}",
            toml::to_string(self).map_err(|e| e.to_string())?
        );
        write_atomic(&path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Done, for the run the directory holds now.
    pub fn is_done_in(&self, dir: &Path) -> bool {
        self.status == "done" && read_run_id(dir).is_ok_and(|id| id == self.run_id)
    }
}

/// Where a case stands, read from its directory.
#[derive(Debug)]
pub enum CaseState {
    /// Finished: skipped.
    Done(CaseStatus),
    /// A checkpoint and no finished run: resumed from the checkpoint.
    Resume(PathBuf),
    /// Nothing to continue from: run from the start; `replace` when the directory holds the
    /// results of an attempt that ended before its first checkpoint.
    Fresh { replace: bool },
}

/// Reads where `case` stands in `dir`. A directory that is not this case's (no `config.toml`
/// but results, or a `config.toml` other than the case's) is an error: the sweep file or the
/// base config changed since, and the sweep does not overwrite results it did not make.
pub fn case_state(case: &Case, dir: &Path) -> Result<CaseState, String> {
    if !dir.exists() {
        return Ok(CaseState::Fresh { replace: false });
    }
    let results = earlier_results(dir)?;
    match fs::read_to_string(dir.join(CONFIG_FILE)) {
        Ok(text) if text == case.config_text || case.moved_here(&text) => {}
        Ok(_) => {
            return Err(format!(
                "case {}: {} differs from the config the sweep file gives this case now (the \
                 sweep file or its base config changed since the case was started); run the \
                 sweep into another --out, or remove {} to run the case again",
                case.name,
                dir.join(CONFIG_FILE).display(),
                dir.display()
            ))
        }
        Err(_) if results.is_empty() => return Ok(CaseState::Fresh { replace: false }),
        Err(_) => {
            return Err(format!(
                "case {}: {} holds run results but no {CONFIG_FILE}: not a case of this sweep; \
                 run the sweep into another --out, or move the directory away",
                case.name,
                dir.display()
            ))
        }
    }
    if let Some(status) = CaseStatus::read(dir) {
        if status.is_done_in(dir) {
            return Ok(CaseState::Done(status));
        }
    }
    let checkpoint = dir.join(CHECKPOINT_FILE);
    if checkpoint.is_file() {
        return Ok(CaseState::Resume(checkpoint));
    }
    Ok(CaseState::Fresh {
        replace: !results.is_empty(),
    })
}
