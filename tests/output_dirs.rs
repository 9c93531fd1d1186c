//! Output directories: no run destroys another run's results. A used directory is refused
//! unless `--force`, a checkpoint resumes only in its own run directory (wherever that was
//! moved) and is refused before any file changes otherwise, and a failed setup leaves nothing.
//! Tiny CPU runs through the built binary, a few seconds each.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dustdem(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
        .args(args)
        .output()
        .expect("dustdem runs")
}

/// A temporary directory, removed when the guard is dropped (also when a test fails).
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("dustdem-outdirs-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Run A: 11 rows (steps 0 to 1000), a checkpoint every 4 rows (the last at step 700), a
/// snapshot every 2 rows.
const RUN_A: &str = "[sample]\nmonomers = 60\nseed = 1\n[experiment]\nmax_steps = 1000\n\
                     [output]\ncheckpoint_every_rows = 4\nsnapshot_every_rows = 2\n";
/// Run B: another sample, 31 rows (a longer curve than A's), no checkpoints.
const RUN_B: &str = "[sample]\nmonomers = 60\nseed = 2\n[experiment]\nmax_steps = 3000\n\
                     [output]\ncheckpoint_every_rows = 0\ncheckpoint_minutes = 0\n";
/// Run C: like B, but with a checkpoint every 5 rows.
const RUN_C: &str = "[sample]\nmonomers = 60\nseed = 2\n[experiment]\nmax_steps = 3000\n\
                     [output]\ncheckpoint_every_rows = 5\n";

fn config(scratch: &Scratch, name: &str, text: &str) -> PathBuf {
    let path = scratch.join(&format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn run(config: &Path, out: &Path, extra: &[&str]) -> Output {
    let args = [
        &[
            "run",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--backend",
            "cpu",
            "--quiet",
        ][..],
        extra,
    ]
    .concat();
    dustdem(&args)
}

fn resume(checkpoint: &Path) -> Output {
    dustdem(&[
        "resume",
        checkpoint.to_str().unwrap(),
        "--backend",
        "cpu",
        "--quiet",
    ])
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn assert_ok(out: &Output, what: &str) {
    assert!(out.status.success(), "{what}: {}", stderr(out));
}

/// Exit code 2, no panic, and each needle in the message.
fn assert_refused(out: &Output, what: &str, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{what} must be refused: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
    for n in needles {
        assert!(err.contains(n), "{what}: expected {n:?} in: {err}");
    }
}

/// Every file under `dir` (relative path → bytes); empty when `dir` does not exist.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, files: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, files);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                files.insert(path.strip_prefix(root).unwrap().to_path_buf(), bytes);
            }
        }
    }
    let mut files = BTreeMap::new();
    if dir.exists() {
        walk(dir, dir, &mut files);
    }
    files
}

fn names(files: &BTreeMap<PathBuf, Vec<u8>>) -> Vec<String> {
    files.keys().map(|p| p.display().to_string()).collect()
}

fn assert_unchanged(dir: &Path, before: &BTreeMap<PathBuf, Vec<u8>>, what: &str) {
    let after = tree(dir);
    assert_eq!(names(&after), names(before), "{what}: files of {dir:?}");
    for (file, bytes) in before {
        assert!(
            after[file] == *bytes,
            "{what}: {} changed ({} → {} bytes)",
            file.display(),
            bytes.len(),
            after[file].len()
        );
    }
}

/// The sequence that once cut a newer run's curve.csv back to an older run's length and
/// appended the older run's rows: run A (checkpoints) into a directory, run B into the same
/// directory, resume the checkpoint A left there. Now the second run is refused; and where a
/// stale checkpoint of A does sit beside B's results (as older versions left it, or copied
/// back), resuming it is refused with B's files byte for byte intact.
#[test]
fn a_stale_checkpoint_cannot_cut_back_a_newer_run() {
    let s = Scratch::new("stale");
    let (a, b) = (config(&s, "a", RUN_A), config(&s, "b", RUN_B));
    let dir = s.join("out");
    assert_ok(&run(&a, &dir, &[]), "run A");
    let stale = std::fs::read(dir.join("checkpoint.bin")).unwrap();

    let after_a = tree(&dir);
    let second = run(&b, &dir, &[]);
    assert_refused(
        &second,
        "run B into A's directory",
        &[
            dir.to_str().unwrap(),
            "--force",
            "earlier run",
            "checkpoint.bin",
        ],
    );
    assert_unchanged(&dir, &after_a, "refused run B");

    assert_ok(&run(&b, &dir, &["--force"]), "run B --force");
    assert!(
        !dir.join("checkpoint.bin").exists(),
        "A's checkpoint removed"
    );
    std::fs::write(dir.join("checkpoint.bin"), &stale).unwrap();
    let with_stale = tree(&dir);
    let curve_b = &with_stale[Path::new("curve.csv")];
    assert!(curve_b.len() > after_a[Path::new("curve.csv")].len());

    let resumed = resume(&dir.join("checkpoint.bin"));
    assert_refused(
        &resumed,
        "resume A's stale checkpoint over B",
        &[
            "belongs to run",
            "holds the results of run",
            "nothing was changed",
        ],
    );
    assert_unchanged(&dir, &with_stale, "refused resume");
}

/// A directory holding only other files is used as it is. One holding a run's results is
/// refused without --force and left unchanged; with --force the old checkpoints, snapshots and
/// results are gone, the user's own files stay, and the new run's files are those it writes
/// into an empty directory.
#[test]
fn a_used_directory_is_refused_and_replaced_only_with_force() {
    let s = Scratch::new("force");
    let (a, b) = (config(&s, "a", RUN_A), config(&s, "b", RUN_B));
    let dir = s.join("out");
    std::fs::create_dir_all(dir.join("snapshots")).unwrap();
    std::fs::write(dir.join("notes.txt"), "my notes\n").unwrap();
    std::fs::write(dir.join("snapshots/view.pvsm"), "<ParaView state/>\n").unwrap();
    std::fs::write(dir.join("config.toml"), RUN_A).unwrap();
    assert_ok(&run(&a, &dir, &[]), "run A beside other files");
    assert!(dir.join("checkpoint.bin").is_file());
    assert!(dir.join("snapshots/snap_0000000300.vtu").is_file());

    let before = tree(&dir);
    let refused = run(&b, &dir, &[]);
    assert_refused(
        &refused,
        "run B without --force",
        &[dir.to_str().unwrap(), "--force", "curve.csv", "snapshots/"],
    );
    assert_unchanged(&dir, &before, "refused run");
    let run_a = std::fs::read_to_string(dir.join("run.id")).unwrap();

    assert_ok(&run(&b, &dir, &["--force"]), "run B --force");
    assert_ne!(std::fs::read_to_string(dir.join("run.id")).unwrap(), run_a);
    let fresh = s.join("fresh");
    assert_ok(&run(&b, &fresh, &[]), "run B into an empty directory");
    let (replaced, reference) = (tree(&dir), tree(&fresh));
    let own = |f: &PathBuf| f != Path::new("notes.txt") && f != Path::new("snapshots/view.pvsm");
    let replaced_names: Vec<_> = replaced.keys().filter(|f| own(f)).cloned().collect();
    let reference_names: Vec<_> = reference.keys().cloned().collect();
    assert_eq!(
        replaced_names, reference_names,
        "after --force: B's files and nothing of A's"
    );
    assert!(!dir.join("checkpoint.bin").exists());
    assert!(!dir.join("snapshots/snap_0000000300.vtu").exists());
    for file in [
        "curve.csv",
        "profiles.csv",
        "snapshots/run.pvd",
        "config.toml",
    ] {
        assert!(
            replaced[Path::new(file)] == reference[Path::new(file)],
            "{file} after --force differs from a run into an empty directory"
        );
    }
    assert_eq!(replaced[Path::new("notes.txt")], b"my notes\n");
    assert_eq!(
        replaced[Path::new("snapshots/view.pvsm")],
        b"<ParaView state/>\n"
    );
}

/// A run directory renamed after its run resumes from its checkpoint in the new place (the
/// old one is not recreated) and ends byte-identical to an uninterrupted run.
#[test]
fn a_moved_run_directory_resumes_in_its_new_place() {
    let s = Scratch::new("moved");
    let a = config(&s, "a", RUN_A);
    let (straight, first, moved) = (s.join("straight"), s.join("first"), s.join("moved"));
    assert_ok(&run(&a, &straight, &[]), "straight run");
    assert_ok(&run(&a, &first, &[]), "run to be moved");
    std::fs::rename(&first, &moved).unwrap();
    // The checkpoint is the one of step 700: resuming cuts the rows of steps 800 to 1000 and
    // runs them again.
    let out = resume(&moved.join("checkpoint.bin"));
    assert_ok(&out, "resume in the moved directory");
    assert!(
        String::from_utf8_lossy(&out.stdout).contains(moved.to_str().unwrap()),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(!first.exists(), "the old place is not recreated");
    let (a_files, b_files) = (tree(&straight), tree(&moved));
    assert_eq!(names(&a_files), names(&b_files));
    for (file, bytes) in &a_files {
        if file == Path::new("run.id") || file == Path::new("checkpoint.bin") {
            continue; // each run has its own id
        }
        assert!(
            b_files[file] == *bytes,
            "{} differs between the straight and the moved + resumed run",
            file.display()
        );
    }
}

/// A checkpoint copied from another run's directory, and a checkpoint whose run's curve was
/// changed since, are refused before any file in either directory changes.
#[test]
fn a_checkpoint_of_another_run_is_refused_before_any_file_changes() {
    let s = Scratch::new("foreign");
    let (a, c) = (config(&s, "a", RUN_A), config(&s, "c", RUN_C));
    let (dir_a, dir_c) = (s.join("a"), s.join("c"));
    assert_ok(&run(&a, &dir_a, &[]), "run A");
    assert_ok(&run(&c, &dir_c, &[]), "run C");
    std::fs::copy(dir_a.join("checkpoint.bin"), dir_c.join("checkpoint.bin")).unwrap();
    let (before_a, before_c) = (tree(&dir_a), tree(&dir_c));
    let out = resume(&dir_c.join("checkpoint.bin"));
    assert_refused(
        &out,
        "A's checkpoint in C's directory",
        &["belongs to run", "nothing was changed"],
    );
    assert_unchanged(&dir_a, &before_a, "A after the refused resume");
    assert_unchanged(&dir_c, &before_c, "C after the refused resume");

    // Same run, but a row before the checkpoint edited: not the file the checkpoint recorded.
    let curve = dir_a.join("curve.csv");
    let text = std::fs::read_to_string(&curve).unwrap();
    let first_row = text.lines().position(|l| l.starts_with("100,")).unwrap();
    let edited: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k == first_row {
                l.replacen("100,", "101,", 1)
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(&curve, edited.join("\n") + "\n").unwrap();
    let before = tree(&dir_a);
    let out = resume(&dir_a.join("checkpoint.bin"));
    assert_refused(
        &out,
        "edited curve.csv",
        &["curve.csv", "differ", "nothing was changed"],
    );
    assert_unchanged(
        &dir_a,
        &before,
        "A after the refused resume of an edited curve",
    );

    // A curve shorter than the checkpoint recorded.
    std::fs::write(&curve, &text[..text.len() / 3]).unwrap();
    let before = tree(&dir_a);
    let out = resume(&dir_a.join("checkpoint.bin"));
    assert_refused(
        &out,
        "truncated curve.csv",
        &["curve.csv", "fewer than", "nothing was changed"],
    );
    assert_unchanged(
        &dir_a,
        &before,
        "A after the refused resume of a short curve",
    );
}

/// Setups that fail late (a sample footprint only the wall builder refuses, sample files that are
/// missing or unreadable) create no directory, leave an existing one as it was, and with --force
/// keep the earlier run's results.
#[test]
fn a_failed_setup_leaves_nothing_behind() {
    let s = Scratch::new("setup");
    let cases = [
        (
            "cylinder_sample_omni",
            "[sample]\nsource = \"file\"\nfile = \"cylinder.sample\"\n[experiment]\nkind = \"omni\"\n",
            "cylinder",
        ),
        (
            "missing_sample",
            "[sample]\nsource = \"file\"\nfile = \"no_such.sample\"\n",
            "no_such.sample",
        ),
        (
            "unreadable_sample",
            "[sample]\nsource = \"file\"\nfile = \"bad.sample\"\n",
            "bad.sample",
        ),
    ];
    std::fs::write(s.join("bad.sample"), "dustdem-sample 9\n").unwrap();
    // A valid sample with a cylinder footprint: only the wall builder finds it unfit for omni.
    let uni = config(
        &s,
        "uni",
        "[sample]\nmonomers = 30\nfootprint = \"cylinder\"\n[experiment]\nkind = \"uni\"\n",
    );
    let sample = s.join("cylinder.sample");
    assert_ok(
        &dustdem(&[
            "generate",
            uni.to_str().unwrap(),
            "--out",
            sample.to_str().unwrap(),
        ]),
        "generate",
    );
    let a = config(&s, "a", RUN_A);
    let used = s.join("used");
    assert_ok(&run(&a, &used, &[]), "run A");
    let existing = s.join("existing");
    std::fs::create_dir_all(&existing).unwrap();
    std::fs::write(existing.join("notes.txt"), "mine\n").unwrap();
    for (name, text, needle) in cases {
        let bad = config(&s, name, text);
        let nested = s.join(&format!("{name}-new")).join("deeper");
        assert_refused(&run(&bad, &nested, &[]), name, &[needle]);
        assert!(
            !s.join(&format!("{name}-new")).exists(),
            "{name}: a failed setup created {:?}",
            names(&tree(&s.join(&format!("{name}-new"))))
        );
        let before = tree(&existing);
        assert_refused(&run(&bad, &existing, &[]), name, &[needle]);
        assert_unchanged(&existing, &before, name);
        let before = tree(&used);
        assert_refused(&run(&bad, &used, &["--force"]), name, &[needle]);
        assert_unchanged(&used, &before, name);
    }
}
