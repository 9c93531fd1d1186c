//! The output directory of a compression or collision run: which of its files dustdem writes,
//! the run id that ties them together, and the checks that keep one run from writing over
//! another's results.
//!
//! - A new run refuses a directory that holds results of an earlier run unless asked to
//!   replace them ([`NewRunDir::check`]); replacing removes only files dustdem writes, and only
//!   once the new run has been set up ([`NewRunDir::create`]).
//! - A run first writes `run.id`, a random-looking id; its checkpoints carry the same id and the
//!   length and hash of the curve and profile files they expect. A resume checks both, reading
//!   only, before it changes any file ([`check_resumable`]).
//! - A setup that fails after the directory was created removes what it wrote
//!   ([`RunDir::discard`]).

use super::atomic::write_atomic;
use super::csv::check_prefix;
use crate::binary::Fnv1a;
use crate::output::snapshot::series::{is_snapshot_file, SNAPSHOT_DIR};
use std::fs;
use std::io;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

pub const RUN_ID_FILE: &str = "run.id";
pub const CONFIG_FILE: &str = "config.toml";
pub const CURVE_FILE: &str = "curve.csv";
pub const PROFILE_FILE: &str = "profiles.csv";
pub const PLOT_FILE: &str = "curve.svg";
pub const SUMMARY_FILE: &str = "summary.txt";
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
pub const FAILED_CHECKPOINT_FILE: &str = "checkpoint-failed.bin";

/// Where a checkpoint's outputs are, as the checkpoint stores it: relative to the directory
/// holding the checkpoint file (checkpoints are written into their run's directory), so a
/// moved run directory resumes in its new place.
pub const OUTPUTS_BESIDE_CHECKPOINT: &str = ".";

/// Whether `name`, directly inside an output directory, is a result dustdem writes.
/// `config.toml` is not one: every run rewrites it, and it may be the user's own copy.
fn is_result_file(name: &str) -> bool {
    [
        RUN_ID_FILE,
        CURVE_FILE,
        PROFILE_FILE,
        PLOT_FILE,
        SUMMARY_FILE,
    ]
    .contains(&name)
        || (name.starts_with("checkpoint") && name.ends_with(".bin"))
}

fn at(path: &Path) -> impl Fn(io::Error) -> String + '_ {
    move |e| format!("{}: {e}", path.display())
}

/// The results of earlier runs in `dir` (none if it does not exist): the files dustdem writes,
/// relative to `dir`, sorted. Other files are not listed.
pub fn earlier_results(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut found = Vec::new();
    let entries = match fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(found),
        Err(e) => return Err(at(dir)(e)),
    };
    for entry in entries {
        let entry = entry.map_err(at(dir))?;
        let kind = entry.file_type().map_err(at(dir))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if kind.is_file() && is_result_file(&name) {
            found.push(PathBuf::from(name));
        } else if kind.is_dir() && name == SNAPSHOT_DIR {
            let snapshots = entry.path();
            for inner in fs::read_dir(&snapshots).map_err(at(&snapshots))? {
                let inner = inner.map_err(at(&snapshots))?;
                let file = inner.file_name().to_string_lossy().into_owned();
                if inner.file_type().map_err(at(&snapshots))?.is_file() && is_snapshot_file(&file) {
                    found.push(Path::new(SNAPSHOT_DIR).join(file));
                }
            }
        }
    }
    found.sort();
    Ok(found)
}

/// The files of `found` for a message: top-level names, then the snapshots as one entry.
fn describe(found: &[PathBuf]) -> String {
    let snapshots = found.iter().filter(|f| f.starts_with(SNAPSHOT_DIR)).count();
    let mut names: Vec<String> = found
        .iter()
        .filter(|f| !f.starts_with(SNAPSHOT_DIR))
        .map(|f| f.display().to_string())
        .collect();
    if snapshots > 0 {
        names.push(format!("{SNAPSHOT_DIR}/ ({snapshots} files)"));
    }
    names.join(", ")
}

/// A new run's id: 16 hex digits from the time, the process id, a counter, the effective
/// config and the output directory.
pub fn new_run_id(config_text: &str, dir: &Path) -> String {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let mut h = Fnv1a::default();
    h.update(&nanos.to_le_bytes());
    h.update(&std::process::id().to_le_bytes());
    h.update(&COUNTER.fetch_add(1, Ordering::Relaxed).to_le_bytes());
    h.update(config_text.as_bytes());
    h.update(dir.as_os_str().as_encoded_bytes());
    format!("{:016x}", h.0)
}

/// The run id `dir/run.id` holds.
pub fn read_run_id(dir: &Path) -> Result<String, String> {
    let path = dir.join(RUN_ID_FILE);
    let text = fs::read_to_string(&path).map_err(at(&path))?;
    text.lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
        .map(str::to_string)
        .ok_or_else(|| format!("{}: holds no run id", path.display()))
}

/// An output directory checked for a new run, not yet touched.
pub struct NewRunDir {
    dir: PathBuf,
    /// Results of an earlier run, removed by [`NewRunDir::create`] (only when replacing).
    stale: Vec<PathBuf>,
}

impl NewRunDir {
    /// Checks that `dir` holds no results of an earlier run. With `replace`, such results are
    /// noted for removal instead; they stay until [`NewRunDir::create`], so a setup that fails
    /// before it keeps them. Reads only.
    pub fn check(dir: &Path, replace: bool) -> Result<Self, String> {
        let stale = earlier_results(dir)?;
        if !stale.is_empty() && !replace {
            return Err(format!(
                "{} holds the results of an earlier run ({}); refusing to write over them. \
                 Choose another output directory (--out DIR), or pass --force to remove that \
                 run's results (only files dustdem writes) and run here",
                dir.display(),
                describe(&stale)
            ));
        }
        Ok(NewRunDir {
            dir: dir.to_path_buf(),
            stale,
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Removes the earlier results noted by [`NewRunDir::check`], creates the directory and
    /// writes the run id and the effective config. On failure, whatever it wrote is removed.
    pub fn create(self, run_id: &str, config_text: &str) -> Result<RunDir, String> {
        let dir = self.dir;
        for file in &self.stale {
            let path = dir.join(file);
            match fs::remove_file(&path) {
                Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(at(&path)(e)),
                _ => {}
            }
        }
        // An emptied snapshot directory goes too; one with other files stays.
        let _ = fs::remove_dir(dir.join(SNAPSHOT_DIR));
        let mut created = Vec::new();
        let mut missing = dir.as_path();
        while !missing.as_os_str().is_empty() && !missing.exists() {
            created.push(missing.to_path_buf());
            missing = missing.parent().unwrap_or(Path::new(""));
        }
        let config_path = dir.join(CONFIG_FILE);
        let run_dir = RunDir {
            config_existed: config_path.exists(),
            dir,
            run_id: run_id.to_string(),
            created,
        };
        let written = fs::create_dir_all(&run_dir.dir)
            .map_err(at(&run_dir.dir))
            .and_then(|()| {
                let path = run_dir.dir.join(RUN_ID_FILE);
                let text = format!(
                    "# dustdem run id; the checkpoints of this run carry the same id\n{run_id}\n"
                );
                write_atomic(&path, text.as_bytes()).map_err(at(&path))
            })
            .and_then(|()| {
                write_atomic(&config_path, config_text.as_bytes()).map_err(at(&config_path))
            });
        match written {
            Ok(()) => Ok(run_dir),
            Err(e) => {
                run_dir.discard();
                Err(e)
            }
        }
    }
}

/// The directory of a run being set up, with its id.
pub struct RunDir {
    pub dir: PathBuf,
    pub run_id: String,
    /// Directories that did not exist before, deepest first.
    created: Vec<PathBuf>,
    config_existed: bool,
}

impl RunDir {
    /// After a setup that failed: removes the files this run wrote (every dustdem result in
    /// the directory is this run's, as [`NewRunDir::check`] found or cleared none) and the
    /// directories it created, so nothing is left behind. Best effort: other files stay.
    pub fn discard(self) {
        for file in earlier_results(&self.dir).unwrap_or_default() {
            let _ = fs::remove_file(self.dir.join(file));
        }
        if !self.config_existed {
            let _ = fs::remove_file(self.dir.join(CONFIG_FILE));
        }
        let _ = fs::remove_dir(self.dir.join(SNAPSHOT_DIR));
        for dir in &self.created {
            let _ = fs::remove_dir(dir);
        }
    }
}

/// The output directory of checkpoint `checkpoint`, from what it stores (a path relative to
/// the checkpoint's own directory).
pub fn resolve_outputs(checkpoint: &Path, stored: &str) -> Result<PathBuf, String> {
    let relative = Path::new(stored);
    if relative.is_absolute() || relative.components().any(|c| c == Component::ParentDir) {
        return Err(format!(
            "output directory {stored:?} is not inside the checkpoint's directory: corrupt"
        ));
    }
    let base = match checkpoint.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok(if stored == OUTPUTS_BESIDE_CHECKPOINT {
        base
    } else {
        base.join(relative)
    })
}

/// Checks, reading only, that `dir` holds the outputs of run `run_id` as checkpoint
/// `checkpoint` recorded them: the same `run.id`, and each `(file, length, hash)` at least that
/// long with its first `length` bytes hashing to `hash`. A resume may cut those files back and
/// append to them only after this passed.
pub fn check_resumable(
    dir: &Path,
    checkpoint: &Path,
    run_id: &str,
    files: &[(&str, u64, u64)],
) -> Result<(), String> {
    let refused = "nothing was changed; a checkpoint resumes only in its own run directory";
    let found = read_run_id(dir).map_err(|e| {
        format!(
            "checkpoint {} belongs to run {run_id}, but its directory {} has no run id of that \
             run ({e}); {refused}",
            checkpoint.display(),
            dir.display()
        )
    })?;
    if found != run_id {
        return Err(format!(
            "checkpoint {} belongs to run {run_id}, but {} holds the results of run {found} \
             (see {RUN_ID_FILE}); resuming would overwrite them, so {refused}",
            checkpoint.display(),
            dir.display()
        ));
    }
    for (name, length, hash) in files {
        let path = dir.join(name);
        check_prefix(&path, *length, *hash).map_err(|e| {
            format!(
                "{}: {e}; resuming checkpoint {} would cut it back, so {refused}",
                path.display(),
                checkpoint.display()
            )
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn result_files_are_told_from_other_files() {
        for name in [
            "curve.csv",
            "profiles.csv",
            "curve.svg",
            "summary.txt",
            "run.id",
            "checkpoint.bin",
            "checkpoint-failed.bin",
        ] {
            assert!(is_result_file(name), "{name}");
        }
        for name in [
            "config.toml",
            "notes.txt",
            "curve.csv.bak",
            "my.bin",
            "run.toml",
        ] {
            assert!(!is_result_file(name), "{name}");
        }
    }

    #[test]
    fn snapshot_files_are_told_from_other_files() {
        for name in [
            "snap_0000000100.vtu",
            "snap_0000000100_failed.vtu",
            "snap_0000000100.dump",
            "walls_0000000100.vtp",
            "run.pvd",
            "walls.pvd",
        ] {
            assert!(is_snapshot_file(name), "{name}");
        }
        for name in [
            "view.pvsm",
            "snap_.vtu",
            "snap_x.vtu",
            "walls_1.vtu",
            "other.pvd",
        ] {
            assert!(!is_snapshot_file(name), "{name}");
        }
    }

    #[test]
    fn outputs_resolve_beside_the_checkpoint() {
        let at = |c: &str, s: &str| resolve_outputs(Path::new(c), s);
        assert_eq!(at("a/b/checkpoint.bin", "."), Ok(PathBuf::from("a/b")));
        assert_eq!(at("checkpoint.bin", "."), Ok(PathBuf::from(".")));
        assert_eq!(at("a/checkpoint.bin", "out"), Ok(PathBuf::from("a/out")));
        assert!(at("a/checkpoint.bin", "/abs").is_err());
        assert!(at("a/checkpoint.bin", "../elsewhere").is_err());
    }

    #[test]
    fn run_ids_differ() {
        let a = new_run_id("x", Path::new("d"));
        let b = new_run_id("x", Path::new("d"));
        assert_eq!(a.len(), 16);
        assert_ne!(a, b);
    }
}
