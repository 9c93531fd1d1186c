//! A single-node Slurm on localhost for the tests that run job arrays for real: munged,
//! slurmctld and slurmd in the foreground as children of the test, every file under one
//! directory, on ports free at the time.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A program of the Slurm or MUNGE packages: on PATH or in the system directories daemons
/// are installed in (which a non-root PATH may lack).
pub fn find_program(name: &str) -> Option<PathBuf> {
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
pub struct LocalSlurm {
    conf: PathBuf,
    log_dir: PathBuf,
    /// The daemons, in the order they were started.
    daemons: Vec<(&'static str, Child)>,
    job: Option<String>,
}

impl LocalSlurm {
    pub fn start(dir: &Path) -> LocalSlurm {
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
        // cred_expire also sets how long a requeued job waits before it may start again
        // (120 s by default): 10 s keeps the requeue test short.
        let d = dir.display();
        let conf = format!(
            "ClusterName=dustdemtest\nSlurmctldHost=localhost\nSlurmUser=root\nSlurmdUser=root\n\
             AuthType=auth/munge\nAuthInfo=socket={socket},cred_expire=10\nCredType=cred/munge\n\
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

    /// The cluster's slurm.conf (for SLURM_CONF of programs that call Slurm's clients).
    pub fn conf(&self) -> &Path {
        &self.conf
    }

    /// A Slurm client command talking to this cluster.
    pub fn client(&self, name: &str) -> Command {
        let mut c = Command::new(find_program(name).unwrap());
        c.env("SLURM_CONF", &self.conf);
        c
    }

    /// The daemons' logs, for a failure message.
    pub fn logs(&self) -> String {
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
    pub fn submit(&mut self, script: &Path, cwd: &Path) -> String {
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
    pub fn wait(&self, id: &str, limit: Duration) {
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
pub fn slurm_available() -> bool {
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
