//! Checkpoint files: a fixed header, then a body whose layout the job defines.
//!
//! ```text
//! bytes 0..12   magic "DUSTDEMCKPT\0"
//! bytes 12..16  0x0A0B0C0D little-endian (an endianness check)
//! bytes 16..20  format version (u32)
//! bytes 20..28  body length (u64)
//! bytes 28..36  FNV-1a 64 of the body
//! bytes 36..    body
//! ```
//! Written atomically (temporary file, fsync, rename), so a crash leaves the previous one.

use super::atomic::write_atomic;
use crate::binary::fnv1a64;
use std::fmt;
use std::path::{Path, PathBuf};

pub const MAGIC: &[u8; 12] = b"DUSTDEMCKPT\0";
/// 1: the first layout; 2: run id, output hashes, output directory relative to the file.
pub const VERSION: u32 = 3;
const ENDIAN_MARK: u32 = 0x0A0B_0C0D;
const HEADER: usize = 36;

#[derive(Clone, Debug, PartialEq)]
pub struct CheckpointError {
    pub path: PathBuf,
    pub problem: String,
}

impl fmt::Display for CheckpointError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "checkpoint {}: {}", self.path.display(), self.problem)
    }
}

impl std::error::Error for CheckpointError {}

pub fn write_checkpoint(path: &Path, body: &[u8]) -> std::io::Result<()> {
    let mut bytes = Vec::with_capacity(HEADER + body.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&ENDIAN_MARK.to_le_bytes());
    bytes.extend_from_slice(&VERSION.to_le_bytes());
    bytes.extend_from_slice(&(body.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&fnv1a64(body).to_le_bytes());
    bytes.extend_from_slice(body);
    write_atomic(path, &bytes)
}

/// Reads and checks a checkpoint; returns its body.
pub fn read_checkpoint(path: &Path) -> Result<Vec<u8>, CheckpointError> {
    let fail = |problem: String| CheckpointError {
        path: path.to_path_buf(),
        problem,
    };
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    if bytes.len() < HEADER {
        return Err(fail(format!(
            "only {} bytes, shorter than the {HEADER}-byte header: truncated or not a checkpoint",
            bytes.len()
        )));
    }
    if &bytes[..12] != MAGIC {
        return Err(fail("not a dustdem checkpoint (wrong magic bytes)".into()));
    }
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let mark = word(12);
    if mark == ENDIAN_MARK.swap_bytes() {
        return Err(fail(
            "written with the other byte order (big-endian); checkpoints are little-endian".into(),
        ));
    }
    if mark != ENDIAN_MARK {
        return Err(fail(format!(
            "corrupt header (endianness mark {mark:#010x})"
        )));
    }
    let version = word(16);
    if version < VERSION {
        return Err(fail(format!(
            "format version {version}, written by an older dustdem; this dustdem reads version \
             {VERSION} only (version 2 added the run id and paths relative to the checkpoint, \
             version 3 the monomers' sample ids). It cannot be resumed: re-run the job with `dustdem run`"
        )));
    }
    if version > VERSION {
        return Err(fail(format!(
            "format version {version}, newer than version {VERSION}, the one this dustdem \
             reads: resume it with the dustdem that wrote it"
        )));
    }
    let length = u64::from_le_bytes(bytes[20..28].try_into().unwrap());
    let checksum = u64::from_le_bytes(bytes[28..36].try_into().unwrap());
    let body = &bytes[HEADER..];
    if body.len() as u64 != length {
        return Err(fail(format!(
            "body has {} bytes, header says {length}: truncated or corrupt",
            body.len()
        )));
    }
    if fnv1a64(body) != checksum {
        return Err(fail("checksum mismatch: the file is corrupt".into()));
    }
    Ok(body.to_vec())
}
