//! `dustdem sweep`: cases skipped when finished, resumed from their checkpoint when killed, and
//! identical to a run of the case's own config by hand; bad sweep files named by field; and the
//! Slurm job array run for real on a single-node Slurm started on localhost, collected into the
//! same table a local sweep writes. Tiny CPU runs (200 monomers up to φ = 0.32) of the built
//! binary.

mod common;

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
    assert_eq!(output.status.code(), Some(2), "{stderr}");
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

/// A program of the Slurm or MUNGE packages: on PATH or in the system directories daemons
/// are installed in (which a non-root PATH may lack).
fn find_program(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(
            [
                "/usr/sbin",
                "/sbin",
                "/usr/bin",
                "/usr/local/sbin",
                "/usr/local/bin",
            ]
            .map(PathBuf::from),
        )
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// Two TCP ports free on 127.0.0.1 now, for slurmctld and slurmd (so a Slurm already
/// running here, or another test's, is not disturbed).
fn free_ports() -> (u16, u16) {
    let a = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let b = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    (
        a.local_addr().unwrap().port(),
        b.local_addr().unwrap().port(),
    )
}

/// A single-node Slurm on localhost (munged, slurmctld, slurmd, all in the foreground as
/// children of this test, every file under one directory). Dropping it cancels the job it
/// ran, if any, and stops the daemons it started (also when the test fails).
struct LocalSlurm {
    conf: PathBuf,
    log_dir: PathBuf,
    /// The daemons, in the order they were started.
    daemons: Vec<(&'static str, Child)>,
    job: Option<String>,
}

impl LocalSlurm {
    fn start(dir: &Path) -> LocalSlurm {
        let program = |name: &str| find_program(name).unwrap();
        for sub in ["munge", "state", "spool", "log", "run"] {
            std::fs::create_dir_all(dir.join(sub)).unwrap();
        }
        let log_dir = dir.join("log");
        let munge = dir.join("munge");
        use std::os::unix::fs::PermissionsExt;
        // The socket's directory must be searchable by everyone; the key readable by its owner
        // only.
        std::fs::set_permissions(&munge, std::fs::Permissions::from_mode(0o755)).unwrap();
        let key = munge.join("munge.key");
        let mut bytes = vec![0u8; 1024];
        use std::io::Read;
        std::fs::File::open("/dev/urandom")
            .unwrap()
            .read_exact(&mut bytes)
            .unwrap();
        std::fs::write(&key, &bytes).unwrap();
        std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o400)).unwrap();
        let socket = munge.join("munge.socket.2");
        let mut slurm = LocalSlurm {
            conf: dir.join("slurm.conf"),
            log_dir: log_dir.clone(),
            daemons: Vec::new(),
            job: None,
        };
        let log = |name: &str| std::fs::File::create(log_dir.join(name)).unwrap();
        let munged = Command::new(program("munged"))
            .arg("--foreground")
            .arg(format!("--socket={}", socket.display()))
            .arg(format!("--key-file={}", key.display()))
            .arg(format!("--pid-file={}", munge.join("munged.pid").display()))
            .arg(format!(
                "--log-file={}",
                log_dir.join("munged.log").display()
            ))
            .arg(format!(
                "--seed-file={}",
                munge.join("munged.seed").display()
            ))
            .stdin(Stdio::null())
            .stdout(log("munged.stdout"))
            .stderr(log("munged.stderr"))
            .spawn()
            .unwrap();
        slurm.daemons.push(("munged", munged));
        let start = Instant::now();
        while !socket.exists() {
            assert!(
                start.elapsed() < Duration::from_secs(10),
                "munged did not open its socket; {}",
                slurm.logs()
            );
            std::thread::sleep(Duration::from_millis(50));
        }

        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let mem_mb = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|t| {
                t.lines()
                    .find_map(|l| l.strip_prefix("MemTotal:"))
                    .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            })
            .map_or(4096, |kb| (kb / 1024).saturating_sub(512).max(1024));
        let (ctld_port, slurmd_port) = free_ports();
        let d = dir.display();
        let conf = format!(
            "ClusterName=dustdemtest\nSlurmctldHost=localhost\nSlurmUser=root\nSlurmdUser=root\n\
             AuthType=auth/munge\nAuthInfo=socket={socket}\nCredType=cred/munge\n\
             SlurmctldPort={ctld_port}\nSlurmdPort={slurmd_port}\n\
             StateSaveLocation={d}/state\nSlurmdSpoolDir={d}/spool\n\
             SlurmctldPidFile={d}/run/slurmctld.pid\nSlurmdPidFile={d}/run/slurmd.pid\n\
             SlurmctldLogFile={d}/log/slurmctld.log\nSlurmdLogFile={d}/log/slurmd.log\n\
             SlurmctldDebug=info\nSlurmdDebug=info\nMpiDefault=none\n\
             ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
             JobAcctGatherType=jobacct_gather/none\nAccountingStorageType=accounting_storage/none\n\
             JobCompType=jobcomp/none\nSchedulerType=sched/backfill\nSelectType=select/cons_tres\n\
             SelectTypeParameters=CR_Core\nReturnToService=2\nMailProg=/bin/true\nMinJobAge=5\n\
             SchedulerParameters=batch_sched_delay=0\n\
             NodeName=localhost NodeAddr=127.0.0.1 CPUs={cpus} RealMemory={mem_mb} State=UNKNOWN\n\
             PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP\n",
            socket = socket.display()
        );
        std::fs::write(&slurm.conf, conf).unwrap();
        let ctld = Command::new(program("slurmctld"))
            .args(["-D", "-i", "-f"])
            .arg(&slurm.conf)
            .env("SLURM_CONF", &slurm.conf)
            .stdin(Stdio::null())
            .stdout(log("slurmctld.stdout"))
            .stderr(log("slurmctld.stderr"))
            .spawn()
            .unwrap();
        slurm.daemons.push(("slurmctld", ctld));
        let slurmd = Command::new(program("slurmd"))
            .args(["-D", "-N", "localhost", "-f"])
            .arg(&slurm.conf)
            .env("SLURM_CONF", &slurm.conf)
            .stdin(Stdio::null())
            .stdout(log("slurmd.stdout"))
            .stderr(log("slurmd.stderr"))
            .spawn()
            .unwrap();
        slurm.daemons.push(("slurmd", slurmd));
        // The node takes about a second to register.
        let start = Instant::now();
        loop {
            let state = slurm
                .client("sinfo")
                .args(["-h", "-N", "-o", "%t"])
                .output();
            if state.is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle") {
                break;
            }
            let exited = slurm
                .daemons
                .iter_mut()
                .find_map(|(name, child)| child.try_wait().unwrap().map(|s| (*name, s)));
            if let Some((name, status)) = exited {
                panic!("{name} exited ({status}); {}", slurm.logs());
            }
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "the node did not become idle in 30 s; {}",
                slurm.logs()
            );
            std::thread::sleep(Duration::from_millis(200));
        }
        slurm
    }

    /// A Slurm client command talking to this cluster.
    fn client(&self, name: &str) -> Command {
        let mut c = Command::new(find_program(name).unwrap());
        c.env("SLURM_CONF", &self.conf);
        c
    }

    /// The daemons' logs, for a failure message.
    fn logs(&self) -> String {
        let mut all = String::new();
        for entry in std::fs::read_dir(&self.log_dir).into_iter().flatten() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            let tail: Vec<&str> = text.lines().rev().take(15).collect();
            all.push_str(&format!("\n--- {} (last lines)\n", path.display()));
            for line in tail.iter().rev() {
                all.push_str(line);
                all.push('\n');
            }
        }
        all
    }

    /// Submits a batch script; returns the job id.
    fn submit(&mut self, script: &Path, cwd: &Path) -> String {
        let out = self
            .client("sbatch")
            .arg("--parsable")
            .arg(script)
            .current_dir(cwd)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "sbatch failed: {}{}",
            text(&out.stderr),
            self.logs()
        );
        let id = text(&out.stdout)
            .trim()
            .split(';')
            .next()
            .unwrap()
            .to_string();
        self.job = Some(id.clone());
        id
    }

    /// Waits until no task of job `id` is pending or running (squeue lists none).
    fn wait(&self, id: &str, limit: Duration) {
        let start = Instant::now();
        loop {
            let out = self
                .client("squeue")
                .args(["-h", "-j", id, "-o", "%i %T"])
                .output()
                .unwrap();
            let listed = text(&out.stdout);
            // Once the job has left the controller's memory squeue calls the id invalid.
            if listed.trim().is_empty() {
                return;
            }
            assert!(
                start.elapsed() < limit,
                "job {id} still listed after {limit:?}:\n{listed}{}",
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(250));
        }
    }
}

impl Drop for LocalSlurm {
    fn drop(&mut self) {
        if let Some(id) = &self.job {
            let _ = self.client("scancel").arg(id).output();
        }
        // slurmd and slurmctld first, then munged; SIGTERM, and SIGKILL after 10 s.
        while let Some((_, mut child)) = self.daemons.pop() {
            // SAFETY: kill(2) on a child of this test.
            unsafe {
                libc::kill(child.id() as libc::pid_t, libc::SIGTERM);
            }
            let start = Instant::now();
            while child.try_wait().ok().flatten().is_none() {
                if start.elapsed() > Duration::from_secs(10) {
                    let _ = child.kill();
                    let _ = child.wait();
                    break;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
        }
    }
}

/// Whether this machine can run a single-node Slurm: its programs are installed and we are
/// root (the daemons run as root). Without them the test is skipped with a note, unless `CI`
/// is set: there it fails (scripts/test.sh installs the packages).
fn slurm_available() -> bool {
    let missing: Vec<&str> = [
        "munged",
        "slurmctld",
        "slurmd",
        "sbatch",
        "squeue",
        "sinfo",
        "scancel",
    ]
    .into_iter()
    .filter(|p| find_program(p).is_none())
    .collect();
    // SAFETY: geteuid(2) has no preconditions.
    let root = unsafe { libc::geteuid() } == 0;
    let why = if !missing.is_empty() {
        format!(
            "Slurm/MUNGE programs not found: {} (packages slurmctld, slurmd, slurm-client, \
             munge; scripts/test.sh installs them)",
            missing.join(", ")
        )
    } else if !root {
        "the single-node Slurm of this test runs its daemons as root".to_string()
    } else {
        return true;
    };
    if std::env::var_os("CI").is_some() {
        panic!("CI is set, so the Slurm test may not be skipped: {why}");
    }
    eprintln!("note: skipping the Slurm job-array test: {why}");
    false
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
