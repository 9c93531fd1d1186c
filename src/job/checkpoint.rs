//! The job's checkpoints: the body written into the run directory (run id, config, output
//! extents, the run's state), reading one back with every check, and the checkpoint and
//! snapshot of a failed state kept for inspection.

use crate::binary::{DecodeError, Decoder, Encoder};
use crate::config::Config;
use crate::engine::{Engine, EngineError};
use crate::experiment::compression::{Compression, RunError};
use crate::output::checkpoint::{read_checkpoint, write_checkpoint};
use crate::output::csv::CsvWriter;
use crate::output::run_dir::{
    resolve_outputs, CHECKPOINT_FILE, FAILED_CHECKPOINT_FILE, OUTPUTS_BESIDE_CHECKPOINT,
};
use crate::output::snapshot::series::write_failed_snapshot;
use crate::state::State;
use std::path::{Path, PathBuf};

/// A checkpoint read back: the run, its config and id, and where its outputs are with the
/// length and FNV-1a hash each had when the checkpoint was written.
pub struct LoadedCheckpoint {
    pub run_id: String,
    pub config: Config,
    /// The directory holding the checkpoint (checkpoints store it relative to themselves).
    pub out_dir: PathBuf,
    pub curve_len: u64,
    pub curve_hash: u64,
    pub profile_len: u64,
    pub profile_hash: u64,
    /// The run as stored, on no engine yet.
    pub run: Compression<State>,
}

/// Reads and checks a checkpoint file completely (header, checksum, config, state).
///
/// Body (format version 3, whose state carries the monomers' sample ids): run id, effective config,
/// output directory relative to the checkpoint's directory (each as u64 length + UTF-8), curve.csv
/// length and hash, profiles.csv length and hash (u64 each), then the run's state.
pub fn load_checkpoint(checkpoint: &Path) -> Result<LoadedCheckpoint, RunError> {
    let body = read_checkpoint(checkpoint).map_err(|e| RunError::Output(e.to_string()))?;
    let bad =
        |e: DecodeError| RunError::Output(format!("checkpoint {}: {e}", checkpoint.display()));
    let mut d = Decoder::new(&body);
    let run_id = String::from_utf8_lossy(d.bytes_with_len("run id").map_err(bad)?).into_owned();
    let text = String::from_utf8_lossy(d.bytes_with_len("config").map_err(bad)?).into_owned();
    let origin = format!("config inside checkpoint {}", checkpoint.display());
    let config = Config::parse(&text, &origin).map_err(|e| RunError::Output(e.to_string()))?;
    let stored = d.bytes_with_len("output directory").map_err(bad)?;
    let out_dir = resolve_outputs(checkpoint, &String::from_utf8_lossy(stored))
        .map_err(|e| RunError::Output(format!("checkpoint {}: {e}", checkpoint.display())))?;
    let curve_len = d.u64("curve length").map_err(bad)?;
    let curve_hash = d.u64("curve hash").map_err(bad)?;
    let profile_len = d.u64("profile length").map_err(bad)?;
    let profile_hash = d.u64("profile hash").map_err(bad)?;
    let run = Compression::decode_state(&config, &mut d).map_err(bad)?;
    if d.remaining() != 0 {
        return Err(RunError::Output(format!(
            "checkpoint {}: {} unexpected bytes after the state",
            checkpoint.display(),
            d.remaining()
        )));
    }
    Ok(LoadedCheckpoint {
        run_id,
        config,
        out_dir,
        curve_len,
        curve_hash,
        profile_len,
        profile_hash,
        run,
    })
}

/// The body of a checkpoint written into the run's directory (layout: [`load_checkpoint`]).
pub(super) fn checkpoint_body<E: Engine>(
    config: &Config,
    run_id: &str,
    run: &Compression<E>,
    curve: &CsvWriter,
    profiles: &CsvWriter,
) -> Result<Vec<u8>, RunError> {
    let mut e = Encoder::default();
    e.bytes_with_len(run_id.as_bytes());
    let text = toml::to_string(config).map_err(|e| RunError::Output(e.to_string()))?;
    e.bytes_with_len(text.as_bytes());
    e.bytes_with_len(OUTPUTS_BESIDE_CHECKPOINT.as_bytes());
    for (length, hash) in [curve.extent(), profiles.extent()] {
        e.u64(length);
        e.u64(hash);
    }
    run.encode_state(&mut e);
    Ok(e.bytes)
}

/// After a run-time guard fired: a checkpoint and a snapshot of the failed state for
/// inspection (beside, not over, the last good checkpoint), and a message naming them.
pub(super) fn keep_failed_state<E: Engine>(
    config: &Config,
    out_dir: &Path,
    run_id: &str,
    run: &Compression<E>,
    curve: &CsvWriter,
    profiles: &CsvWriter,
    error: EngineError,
) -> RunError {
    let mut kept = Vec::new();
    let checkpoint = out_dir.join(FAILED_CHECKPOINT_FILE);
    let body = checkpoint_body(config, run_id, run, curve, profiles);
    if let Ok(body) = body {
        if write_checkpoint(&checkpoint, &body).is_ok() {
            kept.push(checkpoint);
        }
    }
    // A VTU whatever the run's snapshot format: it keeps NaN and inf as they are.
    let snapshot = write_failed_snapshot(out_dir, &run.engine.state());
    if let Ok(files) = &snapshot {
        kept.extend(files.iter().cloned());
    }
    let last_good = out_dir.join(CHECKPOINT_FILE);
    let mut message = format!("{error}; the failed state is kept in:");
    for f in &kept {
        message.push_str(&format!(" {}", f.display()));
    }
    if let Err(e) = snapshot {
        message.push_str(&format!(" (no snapshot: {e})"));
    }
    if last_good.exists() {
        message.push_str(&format!("; last good checkpoint: {}", last_good.display()));
    }
    RunError::Output(message)
}
