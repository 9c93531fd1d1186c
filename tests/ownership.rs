//! One owner per output directory: processes started at the same instant into one directory
//! (runs, whole sweeps, array tasks of one case) leave exactly one winner, the others exit
//! with status 2 naming it, and the directory holds the winner's files only; array tasks of
//! different cases do not refuse each other; a lock left by a killed run is taken over, a live
//! one is never broken (`--force` included), and one from another host is not guessed at;
//! writers racing into one calibration run cache make each run once.
//! Tiny CPU runs of the built binary.

mod common;

use common::Scratch;
use dustdem::output::lock::{host_name, lock_dir, LOCK_FILE};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const EXE: &str = env!("CARGO_BIN_EXE_dustdem");

/// 30 monomers, 40 000 steps at 0.1 m/s (a few tenths of a second), no checkpoints: long
/// enough that every process of a race reaches the lock while the winner still runs.
fn config(seed: u64) -> String {
    format!(
        "[sample]\nmonomers = 30\nseed = {seed}\n[experiment]\nwall_speed_m_s = 0.1\n\
         max_steps = 40000\n\
         average_steps = 1000\n[output]\ncheckpoint_every_rows = 0\ncheckpoint_minutes = 0\n\
         snapshot_format = \"none\"\n"
    )
}

/// Starts `dustdem ARGS` so that it begins at `at`: a shell sleeps until then and execs it
/// (same pid), so processes started one after the other are released together.
fn start_at(at: Instant, args: &[String]) -> Child {
    let delay = at.saturating_duration_since(Instant::now()).as_secs_f64();
    Command::new("sh")
        .arg("-c")
        .arg(r#"sleep "$0"; exec "$@""#)
        .arg(format!("{delay:.3}"))
        .arg(EXE)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh starts")
}

/// Starts every command together and waits for them all: (pid, output) each.
fn race(commands: &[Vec<String>]) -> Vec<(u32, Output)> {
    let at = Instant::now() + Duration::from_millis(300);
    let children: Vec<Child> = commands.iter().map(|c| start_at(at, c)).collect();
    children
        .into_iter()
        .map(|c| (c.id(), c.wait_with_output().expect("dustdem ends")))
        .collect()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|a| a.to_string()).collect()
}

/// Every file below `dir`, relative, sorted.
fn names(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else {
                found.push(path.strip_prefix(dir).unwrap().to_path_buf());
            }
        }
    }
    found.sort();
    found
}

/// Splits a race into its winner (exit 0) and losers (exit 2, the winner's pid, host and
/// command and the lock file named); panics otherwise.
fn one_winner(results: &[(u32, Output)], lock: &Path, what: &str) -> usize {
    let winners: Vec<usize> = (0..results.len())
        .filter(|&k| results[k].1.status.success())
        .collect();
    let all = || {
        results
            .iter()
            .map(|(pid, o)| format!("\n[{pid}] {}: {}", o.status, text(&o.stderr)))
            .collect::<String>()
    };
    assert_eq!(winners.len(), 1, "{what}: one winner expected{}", all());
    let (winner_pid, _) = &results[winners[0]];
    for (pid, out) in results.iter().filter(|(p, _)| p != winner_pid) {
        let err = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{what}: loser {pid}: {err}");
        for needle in [
            format!("in use by process {winner_pid}"),
            format!("on host {}", host_name()),
            lock.display().to_string(),
            " running `".to_string(),
        ] {
            assert!(err.contains(&needle), "{what}: {needle:?} not in: {err}");
        }
        assert!(!err.contains("panicked"), "{what}: {err}");
    }
    winners[0]
}

#[test]
fn racing_runs_leave_one_winner_and_only_its_files() {
    let s = Scratch::new("own-runs");
    let configs: Vec<PathBuf> = (1..=4)
        .map(|seed| {
            let path = s.join(format!("seed{seed}.toml"));
            std::fs::write(&path, config(seed)).unwrap();
            path
        })
        .collect();
    let reference = s.join("reference");
    let one = Command::new(EXE)
        .args(["run", configs[0].to_str().unwrap(), "--out"])
        .arg(&reference)
        .args(["--backend", "cpu", "--threads", "1", "--quiet"])
        .output()
        .unwrap();
    assert!(one.status.success(), "{}", text(&one.stderr));
    let expected = names(&reference);
    let (tries, mut clean_losers) = (10, 0);
    let started = Instant::now();
    for round in 0..tries {
        // Half the rounds into a directory that exists, half with --force: neither changes
        // who wins, and --force never breaks a live lock.
        let out = s.join(format!("round{round}")).join("out");
        if round % 2 == 1 {
            std::fs::create_dir_all(&out).unwrap();
        }
        let commands: Vec<Vec<String>> = configs
            .iter()
            .map(|c| {
                let mut args = strings(&["run", c.to_str().unwrap(), "--out"]);
                args.push(out.display().to_string());
                args.extend(strings(&["--backend", "cpu", "--threads", "1", "--quiet"]));
                if round % 4 >= 2 {
                    args.push("--force".into());
                }
                args
            })
            .collect();
        let results = race(&commands);
        let what = format!("round {round}");
        let w = one_winner(&results, &out.join(LOCK_FILE), &what);
        clean_losers += results.len() - 1;
        // Only the winner's files: its effective config, its curve, no lock left behind.
        assert_eq!(names(&out), expected, "{what}");
        let effective: toml::Table =
            toml::from_str(&std::fs::read_to_string(out.join("config.toml")).unwrap()).unwrap();
        assert_eq!(
            effective["sample"]["seed"].as_integer(),
            Some(w as i64 + 1),
            "{what}: config.toml is not the winner's"
        );
        let curve = std::fs::read_to_string(out.join("curve.csv")).unwrap();
        let comment = curve.lines().find(|l| l.starts_with('#')).unwrap();
        assert!(
            comment.ends_with(&format!("seed {}", w + 1)),
            "{what}: curve.csv is not the winner's: {comment}"
        );
        assert!(
            text(&results[w].1.stderr).is_empty(),
            "{what}: {}",
            text(&results[w].1.stderr)
        );
    }
    eprintln!(
        "{tries} tries of 4 runs: {tries} winners, {clean_losers} clean losers, {:.1} s",
        started.elapsed().as_secs_f64()
    );
}

/// 30 monomers per case, two seeds: two cases.
fn sweep_tree(s: &Scratch) -> PathBuf {
    std::fs::write(s.join("base.toml"), config(1)).unwrap();
    let sweep = s.join("sweep.toml");
    std::fs::write(
        &sweep,
        "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [0.1]\nseed = [1, 2]\nmonomers = [30]\n",
    )
    .unwrap();
    sweep
}

fn sweep_args(sweep: &Path, out: &Path, extra: &[&str]) -> Vec<String> {
    let mut args = strings(&["sweep", sweep.to_str().unwrap(), "--out"]);
    args.push(out.display().to_string());
    args.extend(strings(&["--backend", "cpu", "--threads", "1"]));
    args.extend(strings(extra));
    args
}

/// The case directories below `out` (those holding a config.toml).
fn cases(out: &Path) -> Vec<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("config.toml").is_file())
        .collect();
    found.sort();
    found
}

/// Each case ran once: one attempt in its status and its log.
fn assert_ran_once(case: &Path, what: &str) {
    let status = std::fs::read_to_string(case.join("sweep-status.toml")).unwrap();
    assert!(status.contains("status = \"done\""), "{what}: {status}");
    assert!(status.contains("attempts = 1\n"), "{what}: {status}");
    let log = std::fs::read_to_string(case.join("sweep.log")).unwrap();
    assert_eq!(log.matches("## attempt").count(), 1, "{what}: {log}");
}

#[test]
fn racing_sweeps_leave_one_winner() {
    let started = Instant::now();
    for round in 0..3 {
        let s = Scratch::new("own-sweeps");
        let sweep = sweep_tree(&s);
        let out = s.join("out");
        let args = sweep_args(&sweep, &out, &["--jobs", "2"]);
        let results = race(&[args.clone(), args]);
        let what = format!("sweep round {round}");
        one_winner(&results, &out.join(LOCK_FILE), &what);
        let found = cases(&out);
        assert_eq!(found.len(), 2, "{what}: {:?}", names(&out));
        for case in &found {
            assert_ran_once(case, &what);
        }
        assert!(
            !names(&out).iter().any(|f| f.ends_with(LOCK_FILE)),
            "{what}: a lock was left: {:?}",
            names(&out)
        );
    }
    eprintln!(
        "3 tries of 2 sweeps: 3 winners, 3 clean losers, {:.1} s",
        started.elapsed().as_secs_f64()
    );
}

#[test]
fn array_tasks_lock_only_their_own_case() {
    let s = Scratch::new("own-tasks");
    let sweep = sweep_tree(&s);
    let out = s.join("out");
    // Tasks of different cases run side by side.
    let results = race(&[
        sweep_args(&sweep, &out, &["--case", "0"]),
        sweep_args(&sweep, &out, &["--case", "1"]),
    ]);
    for (pid, o) in &results {
        assert!(o.status.success(), "task {pid}: {}", text(&o.stderr));
    }
    for case in cases(&out) {
        assert_ran_once(&case, "two tasks");
    }
    // Two tasks of one case: one runs it, the other is refused naming it.
    let out = s.join("again");
    let task = sweep_args(&sweep, &out, &["--case", "1"]);
    let results = race(&[task.clone(), task]);
    let winners: Vec<_> = results.iter().filter(|(_, o)| o.status.success()).collect();
    assert_eq!(winners.len(), 1, "one task of case 1 runs it");
    let case = &cases(&out)[0];
    for (pid, o) in results.iter().filter(|(p, _)| *p != winners[0].0) {
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{pid}: {err}");
        let needle = format!("is in use by process {}", winners[0].0);
        assert!(err.contains(&needle), "{needle:?} not in {err}");
        assert!(
            err.contains(&case.join(LOCK_FILE).display().to_string()),
            "{err}"
        );
    }
    assert_ran_once(case, "two tasks of one case");
}

#[test]
fn a_killed_runs_lock_is_taken_over_and_a_live_one_never() {
    let s = Scratch::new("own-stale");
    let long = s.join("long.toml");
    std::fs::write(
        &long,
        "[sample]\nmonomers = 30\nseed = 1\n[experiment]\nwall_speed_m_s = 0.01\n\
         max_steps = 100000000\n\
         [output]\ncheckpoint_every_rows = 5\nsnapshot_format = \"none\"\n",
    )
    .unwrap();
    let out = s.join("out");
    let lock = out.join(LOCK_FILE);
    let mut child = Command::new(EXE)
        .args(["run", long.to_str().unwrap(), "--out"])
        .arg(&out)
        .args(["--backend", "cpu", "--threads", "1", "--quiet"])
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !out.join("checkpoint.bin").exists() {
        assert!(t0.elapsed() < Duration::from_secs(30), "no checkpoint");
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = child.id();
    child.kill().unwrap(); // SIGKILL: no chance to remove the lock
    child.wait().unwrap();
    assert!(lock.is_file(), "a killed run leaves its lock");
    let checkpoint = out.join("checkpoint.bin");
    let resume = || {
        let mut c = Command::new(EXE);
        c.arg("resume")
            .arg(&checkpoint)
            .args(["--backend", "cpu", "--quiet"])
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        c
    };

    // Its process is gone: a resume takes the lock over with a note, runs under its own lock
    // and, stopped by SIGTERM, checkpoints and removes it.
    let mut resumed = resume().spawn().unwrap();
    let own = format!("pid = {}\n", resumed.id());
    let t0 = Instant::now();
    while !std::fs::read_to_string(&lock).is_ok_and(|l| l.contains(&own)) {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "the stale lock stays"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    terminate(resumed.id());
    let status = resumed.wait().unwrap();
    let mut err = String::new();
    std::io::Read::read_to_string(resumed.stderr.as_mut().unwrap(), &mut err).unwrap();
    // 75: stopped at a checkpoint, resumable.
    assert_eq!(status.code(), Some(75), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    assert!(
        err.contains("note: taking over") && err.contains(&format!("process {killed} ")),
        "{err}"
    );
    assert!(!lock.exists(), "a run stopped by SIGTERM removes its lock");

    // A live holder (this test process) is never broken, not with --force either.
    let held = lock_dir(&out).unwrap();
    let before = std::fs::read(&lock).unwrap();
    let refused = Command::new(EXE)
        .args(["run", long.to_str().unwrap(), "--out"])
        .arg(&out)
        .args(["--backend", "cpu", "--quiet", "--force"])
        .output()
        .unwrap();
    let err = text(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{err}");
    let needle = format!("in use by process {}", std::process::id());
    assert!(err.contains(&needle), "{err}");
    assert_eq!(
        std::fs::read(&lock).unwrap(),
        before,
        "the live lock was touched"
    );
    drop(held);
    assert!(!lock.exists(), "a dropped lock is removed");

    // A lock of another host: its process cannot be seen from here, so it stays.
    let foreign = "host = \"elsewhere.invalid\"\npid = 1\nstarted = 1700000000\n\
                   command = \"dustdem run a.toml\"\ntoken = \"00000000000000aa\"\n";
    std::fs::write(&lock, foreign).unwrap();
    let refused = resume().output().unwrap();
    let err = text(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{err}");
    for needle in [
        "process 1 on host elsewhere.invalid, started ",
        " s ago (unix 1700000000), running `dustdem run a.toml`",
        "cannot be seen from host",
    ] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
    assert_eq!(std::fs::read_to_string(&lock).unwrap(), foreign);
}

fn terminate(pid: u32) {
    // SAFETY: kill(2) with a child's pid and a signal number has no memory effects.
    unsafe {
        libc::kill(pid as libc::pid_t, libc::SIGTERM);
    }
}

/// Concurrent writers of one run cache (the array tasks of `calibrate --slurm`, several
/// calibrations sharing a cache): four `calibrate-run` processes released together on the same
/// request, five rounds with a new run each. Exactly one makes the run (its entry lock), the
/// others wait and read it; all exit 0, the cache holds one entry per run, and no entry lock
/// is left.
#[test]
fn racing_writers_of_one_run_cache_make_each_run_once() {
    use dustdem::calibrate::measured::Geometry;
    use dustdem::calibrate::simulate::{compression_config, Run};
    use dustdem::config::Config;
    let s = Scratch::new("race-cache");
    let cache = s.join("cache");
    let (rounds, writers) = (5, 4);
    for round in 0..rounds {
        let base = Config::parse(&config(round + 1), "race").unwrap();
        let run = Run::Compression(compression_config(
            &base,
            Geometry::Omni,
            None,
            round + 1,
            1e4,
        ));
        let request = s.join(format!("request-{round}.key"));
        std::fs::write(&request, run.key()).unwrap();
        let args = strings(&[
            "calibrate-run",
            "--cache",
            cache.to_str().unwrap(),
            "--request",
            request.to_str().unwrap(),
        ]);
        let results = race(&vec![args; writers]);
        let made = results
            .iter()
            .filter(|(_, o)| text(&o.stdout).contains(" made and stored in "))
            .count();
        let found = results
            .iter()
            .filter(|(_, o)| text(&o.stdout).contains(" found in "))
            .count();
        for (pid, o) in &results {
            assert!(
                o.status.success(),
                "round {round}, {pid}: {}",
                text(&o.stderr)
            );
        }
        assert_eq!((made, found), (1, writers - 1), "round {round}");
        let entries: Vec<String> = std::fs::read_dir(&cache)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            entries.iter().filter(|n| n.ends_with(".run")).count(),
            round as usize + 1,
            "{entries:?}"
        );
        assert!(
            !entries
                .iter()
                .any(|n| n.ends_with(".lock") || n.ends_with(".tmp")),
            "{entries:?}"
        );
    }
    eprintln!("run cache: {rounds} rounds of {writers} writers: {rounds} runs made once each");
}
