//! A killed case resumes from its checkpoint and finished cases are skipped, giving what an
//! uninterrupted run writes; SIGTERM stops a sweep at a checkpoint and collect names what is
//! left.

use super::*;
use std::collections::BTreeMap;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant, SystemTime};

/// Every file below `dir` with its bytes and modification time.
fn files(dir: &Path) -> BTreeMap<PathBuf, (Vec<u8>, SystemTime)> {
    let mut found = BTreeMap::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else {
                let modified = std::fs::metadata(&path).unwrap().modified().unwrap();
                found.insert(path.clone(), (std::fs::read(&path).unwrap(), modified));
            }
        }
    }
    found
}

/// A child in a process group of its own, so that it and the run it started can be killed
/// together.
fn spawn_in_own_group(args: &[&str]) -> Child {
    use std::os::unix::process::CommandExt;
    dustdem()
        .args(args)
        .process_group(0)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

fn signal_group(child: &Child, signal: i32) {
    let pgid = child.id() as libc::pid_t;
    // SAFETY: kill(2) on a process group this test created.
    assert_eq!(unsafe { libc::kill(-pgid, signal) }, 0);
}

/// Waits until `curve` has more than `rows` lines and `checkpoint` exists; the child must
/// still be running.
fn wait_for_rows(child: &mut Child, curve: &Path, checkpoint: &Path, rows: usize) {
    let start = Instant::now();
    loop {
        std::thread::sleep(Duration::from_millis(20));
        let n = std::fs::read_to_string(curve).map_or(0, |t| t.lines().count());
        if checkpoint.exists() && n > rows {
            return;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "the case finished before it could be killed"
        );
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no rows appeared"
        );
    }
}

fn status_field(dir: &Path, key: &str) -> String {
    let text = std::fs::read_to_string(dir.join("sweep-status.toml")).unwrap();
    let table: toml::Table = toml::from_str(&text).unwrap();
    table.get(key).map_or(String::new(), |v| v.to_string())
}

#[test]
fn a_killed_case_resumes_from_its_checkpoint_and_finished_cases_are_skipped() {
    let dir = Scratch::new("sweep-resume");
    let sweep = sweep_files(&dir);
    let out = dir.join("out");
    let (sweep_s, out_s) = (sweep.to_str().unwrap(), out.to_str().unwrap());
    let common = ["--out", out_s, "--backend", "cpu", "--threads", "1"];

    // Every case once.
    let first = run(&[&["sweep", sweep_s, "--jobs", "2"][..], &common].concat());
    assert!(first.status.success(), "{}", text(&first.stderr));
    assert!(text(&first.stderr).contains("sweep [4/4] done"));

    // Case 1 again from scratch, killed with SIGKILL (the sweep process and its run) once a
    // checkpoint exists and rows were written after it: a crash, not a clean stop.
    let victim = out.join(NAMES[1]);
    std::fs::remove_dir_all(&victim).unwrap();
    let mut child = spawn_in_own_group(&[&["sweep", sweep_s, "--case", "1"][..], &common].concat());
    wait_for_rows(
        &mut child,
        &victim.join("curve.csv"),
        &victim.join("checkpoint.bin"),
        40,
    );
    signal_group(&child, libc::SIGKILL);
    child.wait().unwrap();
    let killed_curve = std::fs::read(victim.join("curve.csv")).unwrap();
    let killed_run_id = std::fs::read_to_string(victim.join("run.id")).unwrap();
    assert_eq!(status_field(&victim, "status"), "\"running\"");

    // collect names the unfinished case and fails.
    let collected = run(&["sweep", "collect", out_s]);
    assert_eq!(collected.status.code(), Some(2));
    assert!(
        text(&collected.stderr).contains(&format!("{} (case 1): running", NAMES[1])),
        "{}",
        text(&collected.stderr)
    );

    // The sweep directory moves, as one copied back from a cluster or a lent machine does: its
    // cases' configs name the old output directory, and the sweep carries on with them here.
    let moved = dir.join("moved");
    std::fs::rename(&out, &moved).unwrap();
    let (out, out_s) = (moved.clone(), moved.to_str().unwrap());
    let common = ["--out", out_s, "--backend", "cpu", "--threads", "1"];
    let victim = out.join(NAMES[1]);

    // Again: the three finished cases are skipped, the killed one resumes.
    let before: BTreeMap<_, _> = NAMES
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 1)
        .flat_map(|(_, n)| files(&out.join(n)))
        .collect();
    let again = run(&[&["sweep", sweep_s, "--jobs", "2"][..], &common].concat());
    let stderr = text(&again.stderr);
    assert!(again.status.success(), "{stderr}");
    assert!(
        stderr.contains("3 finished (skipped), 1 to resume, 0 to run"),
        "{stderr}"
    );
    let resumed_line = stderr
        .lines()
        .find(|l| l.contains(&format!("resuming {} from step ", NAMES[1])))
        .unwrap_or_else(|| panic!("no resume line: {stderr}"));
    let from_step: u64 = resumed_line.rsplit(' ').next().unwrap().parse().unwrap();
    assert!(from_step > 0, "{resumed_line}");
    let after: BTreeMap<_, _> = NAMES
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 1)
        .flat_map(|(_, n)| files(&out.join(n)))
        .collect();
    assert!(
        before == after,
        "a finished case's files changed on the second sweep"
    );

    // It continued the same run: same run id, the rows up to the checkpoint kept, the step
    // count continued from the checkpoint, and its status says so.
    let curve = std::fs::read(victim.join("curve.csv")).unwrap();
    assert_eq!(
        std::fs::read_to_string(victim.join("run.id")).unwrap(),
        killed_run_id
    );
    let first_rows = |bytes: &[u8], k: usize| -> String {
        text(bytes).lines().take(k).collect::<Vec<_>>().join("\n")
    };
    assert_eq!(first_rows(&curve, 20), first_rows(&killed_curve, 20));
    assert_eq!(status_field(&victim, "status"), "\"done\"");
    assert_eq!(status_field(&victim, "attempts"), "2");
    assert_eq!(
        status_field(&victim, "resumed_from_step"),
        from_step.to_string()
    );
    let log = std::fs::read_to_string(victim.join("sweep.log")).unwrap();
    assert!(
        log.contains("## attempt 2:") && log.contains(" resume "),
        "{log}"
    );

    // The result is what an uninterrupted run of the case's own config.toml writes.
    let by_hand = dir.join("by_hand");
    let straight = run(&[
        "run",
        victim.join("config.toml").to_str().unwrap(),
        "--out",
        by_hand.to_str().unwrap(),
        "--backend",
        "cpu",
        "--quiet",
    ]);
    assert!(straight.status.success(), "{}", text(&straight.stderr));
    for file in ["curve.csv", "profiles.csv"] {
        assert!(
            std::fs::read(by_hand.join(file)).unwrap() == std::fs::read(victim.join(file)).unwrap(),
            "{file} of the resumed case differs from an uninterrupted run"
        );
    }

    // The table: every case done, with its parameters and final values.
    let table = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(
        lines[0],
        "index,case,wall_speed_m_s,seed,variant,monomers,status,attempts,resumed_from_step,\
         steps,final_phi,final_pressure_pa,wall_clock_s,curve"
    );
    assert_eq!(lines.len(), 5);
    for (i, name) in NAMES.iter().enumerate() {
        let f: Vec<&str> = lines[i + 1].split(',').collect();
        assert_eq!(f[0], i.to_string());
        assert_eq!(f[1], *name);
        assert_eq!(f[6], "done", "{}", lines[i + 1]);
        assert!(f[10].parse::<f64>().unwrap() >= 0.32, "{}", lines[i + 1]);
        assert_eq!(f[13], format!("{name}/curve.csv"));
    }
    assert_eq!(&lines[2].split(',').nth(3).unwrap(), &"1");
    assert_eq!(&lines[2].split(',').nth(4).unwrap(), &"modified");
    let collected = run(&["sweep", "collect", out_s]);
    assert!(collected.status.success(), "{}", text(&collected.stderr));
}

#[test]
fn sigterm_stops_a_sweep_at_a_checkpoint_and_collect_names_what_is_left() {
    let dir = Scratch::new("sweep-sigterm");
    let sweep = sweep_files(&dir);
    let out = dir.join("out");
    let mut child = dustdem()
        .args([
            "sweep",
            sweep.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--backend",
            "cpu",
            "--threads",
            "1",
            "--jobs",
            "1",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let first = out.join(NAMES[0]);
    wait_for_rows(
        &mut child,
        &first.join("curve.csv"),
        &first.join("checkpoint.bin"),
        20,
    );
    // Only the sweep process: it passes the signal on to the case it runs.
    // SAFETY: kill(2) on a child of this test.
    assert_eq!(
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) },
        0
    );
    let output = child.wait_with_output().unwrap();
    let stderr = text(&output.stderr);
    // 75: stopped at a checkpoint, resumable (what a job script requeues on).
    assert_eq!(output.status.code(), Some(75), "{stderr}");
    assert!(
        stderr.contains(&format!("interrupted {}", NAMES[0])),
        "{stderr}"
    );
    assert!(stderr.contains("run the same command again"), "{stderr}");
    assert_eq!(status_field(&first, "status"), "\"interrupted\"");
    assert!(
        !out.join(NAMES[1]).exists(),
        "no case starts after the signal"
    );
    let collected = run(&["sweep", "collect", out.to_str().unwrap()]);
    let report = text(&collected.stderr);
    assert_eq!(collected.status.code(), Some(2));
    assert!(
        report.contains(&format!("{} (case 0): interrupted", NAMES[0])),
        "{report}"
    );
    for (i, name) in NAMES.iter().enumerate().skip(1) {
        assert!(
            report.contains(&format!("{name} (case {i}): missing")),
            "{report}"
        );
    }
    assert!(report.contains("4 of 4 cases are not done"), "{report}");
    let table = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert!(
        table.lines().nth(1).unwrap().contains(",interrupted,1,"),
        "{table}"
    );
    assert!(
        table.lines().nth(2).unwrap().contains(",missing,"),
        "{table}"
    );
}
