//! Atomic file writes: a temporary file in the same directory, synced, then renamed over the
//! target, so a crash never leaves a half-written result.
//!
//! The one implementation for every result file (checkpoints, run ids, configs, summaries,
//! snapshots, calibration reports). `tempfile` makes the uniquely named temporary file and
//! removes it on every error path; errors carry no target path, callers add it.

use std::ffi::OsString;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Writes through `body` into a hidden temporary file next to `path`, fsyncs it and renames it
/// over `path`, then fsyncs the directory so that the rename itself is durable.
///
/// Same directory, because a rename is only atomic within one file system. The temporary
/// file is `.NAME.XXXXXX.tmp`: the leading dot keeps ParaView's file-series grouping from
/// picking it up while it is being written. It is created with the permissions `File::create`
/// would give (0o666 less the umask), not `tempfile`'s private 0o600, since it becomes the
/// result file. On any error the temporary file is removed and `path` is untouched.
pub fn write_atomic_with<F>(path: &Path, body: F) -> io::Result<()>
where
    F: FnOnce(&mut BufWriter<&mut File>) -> io::Result<()>,
{
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} does not name a file", path.display()),
        )
    })?;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut prefix = OsString::from(".");
    prefix.push(name);
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    // Write through the plain `File`: `NamedTempFile`'s own `Write` would append the
    // temporary path to every error message.
    let mut w = BufWriter::new(tmp.as_file_mut());
    body(&mut w)?;
    w.flush()?;
    drop(w);
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    // Best effort: the new file is already in place and complete, and some file systems
    // refuse to fsync a directory; that is no reason to fail a run.
    #[cfg(unix)]
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Whether `name` is one of [`write_atomic_with`]'s temporary files: `.NAME.XXXXXX.tmp`, with
/// tempfile's six random alphanumerics.
fn is_temporary_name(name: &str) -> bool {
    let Some(inner) = name.strip_prefix('.').and_then(|n| n.strip_suffix(".tmp")) else {
        return false;
    };
    match inner.rsplit_once('.') {
        Some((target, random)) => {
            !target.is_empty()
                && random.len() == 6
                && random.chars().all(|c| c.is_ascii_alphanumeric())
        }
        None => false,
    }
}

/// Removes the temporary files a writer killed outright (SIGKILL, a node failure) left in
/// `dir`; returns what it removed. Only for a directory the caller holds the lock of
/// (`output::lock`): otherwise the file may be another writer's, still being written.
pub fn remove_stale_temporaries(dir: &Path) -> io::Result<Vec<std::path::PathBuf>> {
    let mut removed = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if is_file && is_temporary_name(&entry.file_name().to_string_lossy()) {
            std::fs::remove_file(entry.path())?;
            removed.push(entry.path());
        }
    }
    removed.sort();
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("dustdem-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn replaces_the_target_and_leaves_no_temporary_file() {
        let dir = scratch("replace");
        let path = dir.join("out.txt");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        assert_eq!(entries(&dir), ["out.txt"]);
        #[cfg(unix)]
        {
            // Not tempfile's private 0o600: others may read results where the umask allows.
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
            let created = dir.join("created.txt");
            File::create(&created).unwrap();
            let expected = std::fs::metadata(&created).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, expected);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_failing_body_leaves_the_target_untouched() {
        let dir = scratch("fail");
        let path = dir.join("out.txt");
        write_atomic(&path, b"kept").unwrap();
        let err = write_atomic_with(&path, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("body failed"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "body failed");
        assert_eq!(std::fs::read(&path).unwrap(), b"kept");
        assert_eq!(entries(&dir), ["out.txt"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn only_this_writers_temporary_files_count_as_stale() {
        let dir = scratch("stale");
        for name in [
            ".checkpoint.bin.a1B2c3.tmp",
            ".curve.svg.ZZZZZZ.tmp",
            ".checkpoint.bin.a1B2c.tmp",
            "..abcdef.tmp",
            ".dustdem.lock",
            "notes.tmp",
            "curve.csv",
        ] {
            std::fs::write(dir.join(name), b"x").unwrap();
        }
        let removed = remove_stale_temporaries(&dir).unwrap();
        let names: Vec<String> = removed
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [".checkpoint.bin.a1B2c3.tmp", ".curve.svg.ZZZZZZ.tmp"]
        );
        assert_eq!(
            entries(&dir),
            [
                "..abcdef.tmp",
                ".checkpoint.bin.a1B2c.tmp",
                ".dustdem.lock",
                "curve.csv",
                "notes.tmp"
            ]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_path_without_a_file_name_is_refused() {
        let err = write_atomic(Path::new("/"), b"x").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("does not name a file"), "{err}");
    }

    #[test]
    fn a_missing_directory_is_an_error() {
        let dir = scratch("missing");
        let path = dir.join("no-such-dir").join("out.txt");
        assert!(write_atomic(&path, b"x").is_err());
        assert_eq!(entries(&dir), Vec::<String>::new());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
