//! `dustdem sweep`: cases skipped when finished, resumed from their checkpoint when killed, and
//! identical to a run of the case's own config by hand; bad sweep files named by field; and the
//! Slurm job array run for real on a single-node Slurm started on localhost, collected into the
//! same table a local sweep writes. Tiny CPU runs (200 monomers up to φ = 0.32) of the built
//! binary.

mod common;

use common::slurm::{slurm_available, LocalSlurm};
use common::Scratch;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant, SystemTime};

fn dustdem() -> Command {
    Command::new(env!("CARGO_BIN_EXE_dustdem"))
}

fn run(args: &[&str]) -> Output {
    dustdem().args(args).output().expect("dustdem runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// 200 RBD monomers pushed at 3 m/s up to φ = 0.32 (about 12 000 steps, 250 rows, a second of
/// CPU time), a checkpoint every 5 rows, no snapshots.
const BASE: &str = "[sample]\nmonomers = 200\nseed = 1\n[experiment]\nwall_speed_m_s = 3.0\n\
                    phi_stop = 0.32\naverage_steps = 50\n[output]\ncheckpoint_every_rows = 5\n\
                    snapshot_format = \"none\"\n";

/// Four cases: seeds 1 and 2, the paper's unmodified and modified models.
const SWEEP: &str = "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [3.0]\nseed = [1, 2]\n\
                     monomers = [200]\n[variants]\nunmodified = {}\n\
                     modified = { rolling_modifier = 8, sliding_modifier = 2.5 }\n";

const NAMES: [&str; 4] = [
    "v3.0_seed1_unmodified_n200",
    "v3.0_seed1_modified_n200",
    "v3.0_seed2_unmodified_n200",
    "v3.0_seed2_modified_n200",
];

/// Writes the base config and the sweep file into `dir`; returns the sweep file.
fn sweep_files(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    let sweep = dir.join("sweep.toml");
    std::fs::write(&sweep, SWEEP).unwrap();
    sweep
}

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

/// Each bad sweep file is refused (exit 2) with a message naming the file's field, and
/// nothing is written.
#[test]
fn bad_sweep_files_are_refused_naming_the_field() {
    let dir = Scratch::new("sweep-bad");
    std::fs::write(dir.join("base.toml"), BASE).unwrap();
    let good_axes = "[axes]\nseed = [1]\n";
    let cases: &[(&str, &str)] = &[
        ("[axes]\nseed = [1]\n", "base = (missing) is not allowed"),
        (
            "base = \"nope.toml\"\n",
            "base = \"nope.toml\" is not allowed: no config file",
        ),
        ("base = 3\n", "base = 3 is not allowed"),
        (
            "base = \"base.toml\"\nspeed = 1\n",
            "speed = 1 is not allowed: unknown key",
        ),
        (
            "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [1.0, 0.0]\n",
            "[axes] wall_speed_m_s = 0.0 is not allowed: each speed must be > 0",
        ),
        (
            "base = \"base.toml\"\n[axes]\nwall_speed_m_s = [1, 1.0]\n",
            "[axes] wall_speed_m_s = 1.0 is not allowed: appears twice",
        ),
        (
            "base = \"base.toml\"\n[axes]\nseed = [-1]\n",
            "[axes] seed = -1 is not allowed: each seed must be an integer ≥ 0",
        ),
        (
            "base = \"base.toml\"\n[axes]\nmonomers = [0]\n",
            "[axes] monomers = 0 is not allowed",
        ),
        (
            "base = \"base.toml\"\n[axes]\nmonomers = []\n",
            "[axes] monomers = [] is not allowed: must list at least one value",
        ),
        (
            "base = \"base.toml\"\n[axes]\ntemperature = [10]\n",
            "[axes] temperature = [10] is not allowed: unknown axis",
        ),
        (
            "base = \"base.toml\"\n[variants]\nmodified = { rolling_modifer = 8 }\n",
            "[variants] modified.rolling_modifer = 8 is not allowed: unknown config key",
        ),
        (
            "base = \"base.toml\"\n[variants]\nmodified = { model = { rolling = 8 } }\n",
            "[variants] modified.model.rolling = 8 is not allowed: unknown key of [model]",
        ),
        (
            "base = \"base.toml\"\n[variants]\nreseeded = { seed = 3 }\n",
            "[variants] reseeded.seed = 3 is not allowed: [sample] seed is set by [axes] seed",
        ),
        (
            "base = \"base.toml\"\n[variants]\n\"a b\" = {}\n",
            "[variants] a b = {} is not allowed: a variant's name",
        ),
        (
            "base = \"base.toml\"\n[variants]\nsoft = 3\n",
            "[variants] soft = 3 is not allowed: must be a table",
        ),
        (
            "base = \"base.toml\"\n[variants]\nnegative = { rolling_modifier = -1 }\n",
            "[model] rolling_modifier = -1 is not allowed",
        ),
        (
            "base = \"base.toml\"\n[variants]\nstiff = { sliding_modifier = 20 }\n",
            "(case v3.0_seed1_stiff_n200: base",
        ),
        (
            "base = \"base.toml\"\n[slurm]\ntime = \"1h\"\n",
            "[slurm] time = \"1h\" is not allowed",
        ),
        (
            "base = \"base.toml\"\n[slurm]\nnodes = 2\n",
            "[slurm] nodes = 2 is not allowed: unknown key",
        ),
        (
            "base = \"base.toml\"\n[slurm]\nsignal_lead_s = 5\n",
            "[slurm] signal_lead_s = 5 is not allowed: must be an integer between 10 and 65535",
        ),
        (
            "base = \"base.toml\"\n[slurm]\nrequeue = \"yes\"\n",
            "[slurm] requeue = \"yes\" is not allowed: must be true or false",
        ),
        ("base = \"base.toml\"\n[axes\n", "invalid sweep file"),
    ];
    for (k, (body, expected)) in cases.iter().enumerate() {
        let file = dir.join(format!("bad{k}.toml"));
        std::fs::write(&file, body).unwrap();
        let out = dir.join(format!("out{k}"));
        let result = run(&[
            "sweep",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--backend",
            "cpu",
        ]);
        let stderr = text(&result.stderr);
        assert_eq!(result.status.code(), Some(2), "{body}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{body}\nexpected: {expected}\ngot: {stderr}"
        );
        assert!(
            stderr.contains(&format!("bad{k}.toml")),
            "names the file: {stderr}"
        );
        assert!(!out.exists(), "{body}: nothing is written");
    }
    // Command-line values out of range.
    let good = dir.join("good.toml");
    std::fs::write(&good, format!("base = \"base.toml\"\n{good_axes}")).unwrap();
    let out = dir.join("out-good");
    for (args, expected) in [
        (
            &["--case", "1"][..],
            "--case 1: out of range; this sweep has 1 cases, 0 to 0",
        ),
        (&["--jobs", "0"][..], "--jobs 0: out of range"),
        (
            &["--slurm", "--time", "1h"][..],
            "--time 1h: not a Slurm time limit",
        ),
    ] {
        let result = run(&[
            &[
                "sweep",
                good.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ][..],
            args,
        ]
        .concat());
        assert_eq!(result.status.code(), Some(2));
        assert!(
            text(&result.stderr).contains(expected),
            "{}",
            text(&result.stderr)
        );
        assert!(!out.exists());
    }
    let missing = run(&["sweep", "collect", dir.join("nowhere").to_str().unwrap()]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(text(&missing.stderr).contains("cases.csv"));
}

/// sweep.csv without its wall-clock column.
fn without_wall_clock(table: &str) -> Vec<Vec<String>> {
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == "wall_clock_s").unwrap();
    std::iter::once(header.join(","))
        .chain(lines.map(str::to_string))
        .map(|l| {
            l.split(',')
                .enumerate()
                .filter(|(i, _)| *i != k)
                .map(|(_, f)| f.to_string())
                .collect()
        })
        .collect()
}

#[test]
fn a_slurm_job_array_runs_the_sweep_as_a_local_sweep_does() {
    if !slurm_available() {
        return;
    }
    let dir = Scratch::new("sweep-slurm");
    let sweep = sweep_files(&dir);
    let (on_slurm, local) = (dir.join("on_slurm"), dir.join("local"));
    let export = run(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        on_slurm.to_str().unwrap(),
        "--backend",
        "cpu",
        "--slurm",
        "--time",
        "00:05:00",
        "--mem-mb",
        "500",
    ]);
    assert!(export.status.success(), "{}", text(&export.stderr));
    let script_path = on_slurm.join("sweep.sbatch");
    let script = std::fs::read_to_string(&script_path).unwrap();
    for line in [
        "#SBATCH --array=0-3\n",
        "#SBATCH --cpus-per-task=1\n",
        "#SBATCH --time=00:05:00\n",
        "#SBATCH --mem=500M\n",
    ] {
        assert!(script.contains(line), "{line} in:\n{script}");
    }
    assert!(script.contains(env!("CARGO_BIN_EXE_dustdem")), "{script}");
    let cases = std::fs::read_to_string(on_slurm.join("cases.csv")).unwrap();
    assert_eq!(
        cases
            .lines()
            .filter(|l| l.starts_with(char::is_numeric))
            .count(),
        4
    );

    let slurm_dir = dir.join("slurm");
    let started = Instant::now();
    let mut slurm = LocalSlurm::start(&slurm_dir);
    let ready = started.elapsed();
    let job = slurm.submit(&script_path, &dir);
    slurm.wait(&job, Duration::from_secs(180));
    let finished = started.elapsed();
    drop(slurm);
    eprintln!(
        "slurm: daemons up in {:.1} s, array done {:.1} s after start, stopped after {:.1} s",
        ready.as_secs_f64(),
        finished.as_secs_f64(),
        started.elapsed().as_secs_f64()
    );
    let task_logs = std::fs::read_dir(on_slurm.join("slurm")).unwrap().count();
    assert_eq!(task_logs, 4, "one output file per array task");

    let collected = run(&["sweep", "collect", on_slurm.to_str().unwrap()]);
    assert!(
        collected.status.success(),
        "{}{}",
        text(&collected.stdout),
        text(&collected.stderr)
    );

    let local_run = run(&[
        "sweep",
        sweep.to_str().unwrap(),
        "--out",
        local.to_str().unwrap(),
        "--backend",
        "cpu",
        "--threads",
        "1",
        "--jobs",
        "2",
    ]);
    assert!(local_run.status.success(), "{}", text(&local_run.stderr));
    for name in NAMES {
        assert!(
            std::fs::read(on_slurm.join(name).join("curve.csv")).unwrap()
                == std::fs::read(local.join(name).join("curve.csv")).unwrap(),
            "curve.csv of {name} differs between the job array and the local sweep"
        );
    }
    let table = |d: &Path| std::fs::read_to_string(d.join("sweep.csv")).unwrap();
    assert_eq!(
        without_wall_clock(&table(&on_slurm)),
        without_wall_clock(&table(&local))
    );
}
