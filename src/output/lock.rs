//! One owner per output directory: `DIR/.dustdem.lock`, created with O_EXCL (`create_new`)
//! before a command writes into DIR and removed when it ends ([`Lock`]'s `Drop`, so on errors
//! too). It names the holder (host, pid, start time, command line) for the refusal a second
//! writer gets. A lock whose process is gone on this host (SIGKILL, a crash) is taken over with
//! a note; one from another host never is, since its process cannot be seen from here. A sweep
//! hands a case directory's lock to the child that runs the case ([`HANDED_LOCK_ENV`]); the
//! lock then names the child too and stays live while either runs. See DESIGN.md, "One owner
//! per output directory".

use serde::{Deserialize, Serialize};
use std::fs::{self, OpenOptions};
use std::io::{self, Read, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// The lock file inside a locked directory.
pub const LOCK_FILE: &str = ".dustdem.lock";
/// Set by a process for a child that works under its lock: the lock's token.
pub const HANDED_LOCK_ENV: &str = "DUSTDEM_HANDED_LOCK";

/// The locks this process holds (path, token), for [`remove_held`].
static HELD: Mutex<Vec<(PathBuf, String)>> = Mutex::new(Vec::new());

/// Who holds a lock: what the lock file says. `child` (0: none) is a child working under the
/// lock, as a sweep's case does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Holder {
    pub host: String,
    pub pid: u32,
    /// When the lock was taken (unix seconds), for people: liveness uses no clock.
    pub started: u64,
    pub command: String,
    pub token: String,
    #[serde(default)]
    pub child: u32,
}

fn now() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

impl Holder {
    fn this_process(path: &Path) -> Holder {
        let args: Vec<String> = std::env::args_os()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        let pid = std::process::id();
        Holder {
            host: host_name(),
            pid,
            started: now(),
            command: args.join(" "),
            token: super::run_dir::new_run_id(LOCK_FILE, path),
            child: 0,
        }
    }

    /// The holder for a message: process, host, start and command.
    pub fn describe(&self) -> String {
        let child = match self.child {
            0 => String::new(),
            c => format!(" (and its child {c})"),
        };
        let (pid, host, at, cmd) = (self.pid, &self.host, self.started, &self.command);
        let ago = now().saturating_sub(at);
        format!(
            "process {pid}{child} on host {host}, started {ago} s ago (unix {at}), running `{cmd}`"
        )
    }

    /// Whether this host can tell that the holder's processes are gone.
    pub fn is_gone(&self) -> bool {
        let child_gone = self.child == 0 || !alive(self.child);
        self.host == host_name() && !alive(self.pid) && child_gone
    }

    fn text(&self) -> String {
        let body = toml::to_string(self).expect("a lock serialises");
        format!("# dustdem: this process writes here; removed when it ends\n{body}")
    }
}

/// Whether process `pid` runs (a zombie does not): its `/proc/<pid>/stat` exists and its state,
/// the first field after the command's closing parenthesis, is not `Z` or `X`. Without /proc
/// (not Linux) every process counts as running: such locks are never taken over. A pid reused
/// by another process also counts; the message then names a process that is not dustdem.
fn alive(pid: u32) -> bool {
    match fs::read_to_string(format!("/proc/{pid}/stat")) {
        Ok(stat) => {
            let state = stat
                .rsplit_once(')')
                .and_then(|(_, r)| r.split_whitespace().next());
            !matches!(state, Some("Z" | "X"))
        }
        Err(_) => !Path::new("/proc/self/stat").exists(),
    }
}

pub fn host_name() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: gethostname writes at most `buf.len()` bytes into `buf`.
    let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    if r == 0 && end > 0 {
        String::from_utf8_lossy(&buf[..end]).into_owned()
    } else {
        "unknown-host".into()
    }
}

/// The holder a lock file names; `None` if there is no lock file.
fn read_holder(path: &Path) -> Result<Option<Holder>, String> {
    match fs::read_to_string(path) {
        Ok(text) => toml::from_str(&text).map(Some).map_err(|e| e.to_string()),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e.to_string()),
    }
}

/// Whether `path` holds the lock with `token`.
fn holds(path: &Path, token: &str) -> bool {
    read_holder(path).is_ok_and(|h| h.is_some_and(|h| h.token == token))
}

fn at(path: &Path, e: io::Error) -> String {
    format!("{}: {e}", path.display())
}

/// A lock this process holds (or works under, when handed to it); released when dropped.
pub struct Lock {
    path: PathBuf,
    holder: Holder,
    /// False for a lock handed over by the parent, which removes it.
    owned: bool,
    /// The outermost directory created to hold the lock file: up to it, the directories are
    /// removed again if empty.
    created: Option<PathBuf>,
}

/// Takes the lock of directory `dir` (created if missing), or says who holds it.
pub fn lock_dir(dir: &Path) -> Result<Lock, String> {
    let path = dir.join(LOCK_FILE);
    let h = match try_lock(&path)? {
        Ok(lock) => return Ok(lock),
        Err(holder) => holder,
    };
    let here = host_name();
    let what = if h.host == here {
        "wait for it to end or stop it (Ctrl-C or SIGTERM: a run checkpoints and stops); --force \
         does not take a directory from a running process"
            .to_string()
    } else {
        format!("whether it still runs cannot be seen from host {here}; if not, remove the file")
    };
    let (dir, file, holder) = (dir.display(), path.display(), h.describe());
    Err(format!(
        "{dir} is in use by {holder}; lock file {file}: {what}"
    ))
}

/// Creates lock file `path` (and its directory), or returns `Ok(Err(holder))` if another live
/// process holds it; a lock whose process is gone on this host is taken over, and a lock handed
/// to this process (its token in [`HANDED_LOCK_ENV`]) is worked under.
pub fn try_lock(path: &Path) -> Result<Result<Lock, Holder>, String> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    let dir = dir.unwrap_or(Path::new("."));
    let handed = std::env::var(HANDED_LOCK_ENV).unwrap_or_default();
    let mut created = None;
    for attempt in 0..40 {
        let missing = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists());
        created = created.or(missing.last().map(Path::to_path_buf));
        fs::create_dir_all(dir).map_err(|e| at(dir, e))?;
        let (holder, owned) = match OpenOptions::new().write(true).create_new(true).open(path) {
            Ok(mut file) => {
                let holder = Holder::this_process(path);
                if let Err(e) = file.write_all(holder.text().as_bytes()) {
                    let _ = fs::remove_file(path);
                    return Err(at(path, e));
                }
                let entry = (path.to_path_buf(), holder.token.clone());
                HELD.lock().unwrap_or_else(|e| e.into_inner()).push(entry);
                (holder, true)
            }
            // The directory went away with its last owner's lock: make it again.
            Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
            Err(e) if e.kind() != io::ErrorKind::AlreadyExists => return Err(at(path, e)),
            Err(_) => match read_holder(path) {
                Ok(None) => continue,
                Ok(Some(h)) if h.token == handed => (h, false),
                Ok(Some(h)) if !h.is_gone() => return Ok(Err(h)),
                Ok(Some(h)) => {
                    if break_stale(path, &h)? {
                        let (file, gone) = (path.display(), h.describe());
                        eprintln!("note: taking over {file}: its {gone} is gone");
                    }
                    continue;
                }
                // Created but not yet written: look again.
                Err(_) if attempt < 30 => {
                    std::thread::sleep(Duration::from_millis(20));
                    continue;
                }
                Err(e) => return Err(format!("{}: not a dustdem lock ({e})", path.display())),
            },
        };
        let path = path.to_path_buf();
        return Ok(Ok(Lock {
            path,
            holder,
            owned,
            created,
        }));
    }
    Err(format!("{}: the lock keeps changing hands", path.display()))
}

/// Removes lock file `path` if it still is the one of `stale` (found gone). Takers serialise on
/// flock(2) of the stale file itself and check that `path` still names that very file, so two
/// takers cannot both remove it, nor one remove a new owner's lock. Only processes on the stale
/// holder's host take over, so host-local flock semantics are enough.
fn break_stale(path: &Path, stale: &Holder) -> Result<bool, String> {
    let file = match OpenOptions::new().read(true).write(true).open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(at(path, e)),
    };
    let why = "its process is gone, but the file cannot be locked to take it over";
    file.lock()
        .map_err(|e| format!("{}: {why} ({e}); remove it by hand", path.display()))?;
    let (Ok(named), Ok(opened)) = (fs::metadata(path), file.metadata()) else {
        return Ok(false);
    };
    let mut text = String::new();
    let same_file = (named.dev(), named.ino()) == (opened.dev(), opened.ino());
    if !same_file || (&file).read_to_string(&mut text).is_err() {
        return Ok(false);
    }
    if toml::from_str::<Holder>(&text).ok().as_ref() != Some(stale) {
        return Ok(false);
    }
    fs::remove_file(path).map_err(|e| at(path, e))?;
    Ok(true)
}

impl Lock {
    pub fn token(&self) -> &str {
        &self.holder.token
    }

    /// Records `child` as working under this lock, which then counts as live while either
    /// process runs.
    pub fn hand_to(&mut self, child: u32) -> Result<(), String> {
        self.holder.child = child;
        let text = self.holder.text();
        super::atomic::write_atomic(&self.path, text.as_bytes()).map_err(|e| at(&self.path, e))
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        let (path, h) = (&self.path, &self.holder);
        if !self.owned {
            return;
        }
        HELD.lock()
            .unwrap_or_else(|e| e.into_inner())
            .retain(|(p, _)| p != path);
        // A child still writing keeps the lock; once it is gone, the lock is stale.
        if h.child != 0 && alive(h.child) {
            return;
        }
        if holds(path, &h.token) {
            let _ = fs::remove_file(path);
        }
        if let Some(top) = &self.created {
            for d in path.ancestors().skip(1) {
                if fs::remove_dir(d).is_err() || d == top {
                    break;
                }
            }
        }
    }
}

/// Removes the locks this process holds, for a process about to end without unwinding (on a
/// signal, for commands that have no stop of their own).
pub fn remove_held() {
    for (path, token) in HELD.lock().unwrap_or_else(|e| e.into_inner()).iter() {
        if holds(path, token) {
            let _ = fs::remove_file(path);
        }
    }
}
