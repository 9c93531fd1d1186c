//! Runs the deck with `lmp` (under `mpirun` for the rank count) and reads what its log
//! reports: the loop time and steps of the timed run, the atoms left, the memory per rank,
//! the time per section and the contacts at the end.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The LAMMPS executables found on PATH.
#[derive(Clone, Debug)]
pub struct Lammps {
    pub lmp: PathBuf,
    /// Without it only one rank runs (lmp alone).
    pub mpirun: Option<PathBuf>,
}

/// One run's log, as far as the benchmark reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct LammpsRun {
    /// `LAMMPS (29 Sep 2021 - Update 2)`: the version in the log's first line.
    pub version: String,
    /// The last run's loop time [s], steps, ranks and atoms.
    pub loop_seconds: f64,
    pub steps: u64,
    pub procs: usize,
    pub atoms: usize,
    /// The largest per-rank memory LAMMPS reports [MiB].
    pub memory_mib: Option<f64>,
    /// The last run's timing breakdown: section (Pair, Neigh, Comm, Output, Modify, Other) and
    /// its time averaged over ranks [s].
    pub sections: Vec<(String, f64)>,
    /// Overlapping pairs per monomer (each pair counted at both) at the last step.
    pub contacts_per_monomer: Option<f64>,
}

impl LammpsRun {
    /// Particle-steps per second of the timed run.
    pub fn rate(&self) -> f64 {
        self.atoms as f64 * self.steps as f64 / self.loop_seconds
    }
}

/// The first executable file `name` in PATH.
pub fn on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| is_executable(p))
}

fn is_executable(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    }
    #[cfg(not(unix))]
    {
        path.is_file()
    }
}

impl Lammps {
    /// `lmp` and `mpirun` from PATH; `Err` says why LAMMPS cannot run.
    pub fn find() -> Result<Lammps, String> {
        let lmp = on_path("lmp").ok_or(
            "LAMMPS not run: `lmp` is not on PATH (Debian/Ubuntu: apt-get install lammps)",
        )?;
        Ok(Lammps {
            lmp,
            mpirun: on_path("mpirun"),
        })
    }

    /// Runs `in.compress` in `dir` on `ranks` MPI ranks: `warm` steps, then `steps` timed
    /// steps; the log goes to `dir/log.<tag>.lammps`.
    pub fn run(
        &self,
        dir: &Path,
        ranks: usize,
        warm: u64,
        steps: u64,
        tag: &str,
    ) -> Result<LammpsRun, String> {
        let log_name = format!("log.{tag}.lammps");
        let log = dir.join(&log_name);
        let mut command = match (&self.mpirun, ranks) {
            (Some(mpirun), _) => {
                let mut c = Command::new(mpirun);
                c.arg("-np").arg(ranks.to_string()).arg(&self.lmp);
                c
            }
            (None, 1) => Command::new(&self.lmp),
            (None, _) => {
                return Err(format!(
                    "LAMMPS on {ranks} ranks not run: `mpirun` is not on PATH"
                ))
            }
        };
        command
            // LAMMPS runs in `dir`, so the log is named relative to it: `log` itself is
            // relative to our working directory when `--out` is.
            .args(["-in", "in.compress", "-screen", "none", "-nocite", "-log"])
            .arg(&log_name)
            .args(["-var", "warm", &warm.to_string()])
            .args(["-var", "steps", &steps.to_string()])
            .current_dir(dir)
            // Open MPI refuses root and more ranks than cores unless told; these are its
            // environment forms of --allow-run-as-root and --oversubscribe, which other MPIs
            // ignore.
            .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
            .env("OMP_NUM_THREADS", "1");
        let output = command
            .output()
            .map_err(|e| format!("{}: could not start: {e}", self.lmp.display()))?;
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        if !output.status.success() {
            let why = text
                .lines()
                .rev()
                .find(|l| l.starts_with("ERROR"))
                .map(str::to_string)
                .unwrap_or_else(|| {
                    let stderr = String::from_utf8_lossy(&output.stderr);
                    stderr.lines().rev().take(5).collect::<Vec<_>>().join(" / ")
                });
            return Err(format!(
                "LAMMPS on {ranks} rank(s) failed ({}): {why}; log: {}",
                output.status,
                log.display()
            ));
        }
        let run = parse_log(&text).map_err(|e| format!("{}: {e}", log.display()))?;
        if run.steps != steps {
            return Err(format!(
                "{}: the timed run did {} steps, {steps} were asked for",
                log.display(),
                run.steps
            ));
        }
        Ok(run)
    }
}

/// Reads a LAMMPS log (see [`LammpsRun`]); the last run is the timed one.
pub fn parse_log(text: &str) -> Result<LammpsRun, String> {
    let version = text
        .lines()
        .find(|l| l.starts_with("LAMMPS ("))
        .unwrap_or("LAMMPS (version not in the log)")
        .trim()
        .to_string();
    let mut header: Vec<String> = Vec::new();
    let mut row: Vec<f64> = Vec::new();
    let mut last_loop = None;
    let mut end_row = Vec::new();
    let mut memory_mib = None;
    let mut sections = Vec::new();
    let mut in_breakdown = false;
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.first() == Some(&"Step") {
            header = words.iter().map(|w| w.to_string()).collect();
            continue;
        }
        if let Some(rest) = line.strip_prefix("Loop time of ") {
            // "Loop time of T on P procs for S steps with A atoms"
            let w: Vec<&str> = rest.split_whitespace().collect();
            let field = |i: usize| w.get(i).copied().unwrap_or("");
            let parsed = (
                field(0).parse::<f64>(),
                field(2).parse::<usize>(),
                field(5).parse::<u64>(),
                field(8).parse::<usize>(),
            );
            match parsed {
                (Ok(t), Ok(p), Ok(s), Ok(a)) => last_loop = Some((t, p, s, a)),
                _ => return Err(format!("unreadable line `{line}`")),
            }
            end_row = std::mem::take(&mut row);
            new_run_breakdown(&mut sections, &mut in_breakdown);
            continue;
        }
        if let Some(rest) = line.strip_prefix("Per MPI rank memory allocation (min/avg/max) =") {
            memory_mib = rest
                .split('|')
                .nth(2)
                .and_then(|w| w.split_whitespace().next())
                .and_then(|w| w.parse::<f64>().ok());
            continue;
        }
        if line.starts_with("Section |") {
            in_breakdown = true;
            continue;
        }
        if in_breakdown {
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            if cells.len() >= 3 {
                if let Ok(avg) = cells[2].parse::<f64>() {
                    sections.push((cells[0].to_string(), avg));
                }
            } else if !line.starts_with('-') {
                in_breakdown = false;
            }
            continue;
        }
        if !header.is_empty() && words.len() == header.len() {
            if let Ok(values) = words.iter().map(|w| w.parse::<f64>()).collect() {
                row = values;
            }
        }
    }
    let (loop_seconds, procs, steps, atoms) =
        last_loop.ok_or("no `Loop time` line: the run did not finish")?;
    let column = |name: &str| header.iter().position(|h| h == name);
    let contacts_per_monomer = match (column("c_contact_sum"), column("Atoms")) {
        (Some(c), Some(a)) if end_row.len() == header.len() && end_row[a] > 0.0 => {
            Some(end_row[c] / end_row[a])
        }
        _ => None,
    };
    Ok(LammpsRun {
        version,
        loop_seconds,
        steps,
        procs,
        atoms,
        memory_mib,
        sections,
        contacts_per_monomer,
    })
}

/// A new `Loop time` starts a new run: its breakdown replaces the previous one's.
fn new_run_breakdown(sections: &mut Vec<(String, f64)>, in_breakdown: &mut bool) {
    sections.clear();
    *in_breakdown = false;
}

#[cfg(test)]
mod tests {
    use super::*;

    const LOG: &str = "LAMMPS (29 Sep 2021 - Update 2)
units cgs
Per MPI rank memory allocation (min/avg/max) = 5.1 | 5.2 | 5.3 Mbytes
Step Atoms c_contact_sum v_top_z CPU 
       0     1000         2300  0.001     0 
     100     1000         2310  0.00099 0.01 
Loop time of 0.0123 on 1 procs for 100 steps with 1000 atoms

MPI task timing breakdown:
Section |  min time  |  avg time  |  max time  |%varavg| %total
---------------------------------------------------------------
Pair    | 0.5        | 0.5        | 0.5        |   0.0 | 50.00
Other   |            | 0.01       |            |       |  1.00

Per MPI rank memory allocation (min/avg/max) = 6.1 | 6.2 | 6.3 Mbytes
Step Atoms c_contact_sum v_top_z CPU 
     100     1000         2310  0.00099 0 
    1100     1000         2400  0.00089 2.5 
Loop time of 2.5 on 2 procs for 1000 steps with 1000 atoms

MPI task timing breakdown:
Section |  min time  |  avg time  |  max time  |%varavg| %total
---------------------------------------------------------------
Pair    | 1.9        | 2          | 2.1        |   1.0 | 80.00
Neigh   | 0.1        | 0.2        | 0.3        |   1.0 |  8.00
Other   |            | 0.3        |            |       | 12.00

Nlocal:            500.000 ave         510 max         490 min
Total wall time: 0:00:03
";

    #[test]
    fn the_last_run_is_read() {
        let run = parse_log(LOG).unwrap();
        assert_eq!(run.version, "LAMMPS (29 Sep 2021 - Update 2)");
        assert_eq!(
            (run.loop_seconds, run.procs, run.steps, run.atoms),
            (2.5, 2, 1000, 1000)
        );
        assert_eq!(run.memory_mib, Some(6.3));
        assert_eq!(
            run.sections,
            [
                ("Pair".to_string(), 2.0),
                ("Neigh".to_string(), 0.2),
                ("Other".to_string(), 0.3)
            ]
        );
        assert_eq!(run.contacts_per_monomer, Some(2.4));
        assert_eq!(run.rate(), 4e5);
    }

    #[test]
    fn an_unfinished_run_is_an_error() {
        let cut = &LOG[..LOG.find("Loop time").unwrap()];
        assert!(parse_log(cut).unwrap_err().contains("Loop time"));
    }
}
