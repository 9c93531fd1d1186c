//! `dustdem sweep --slurm`: a job-array script with one case per array task. Each task runs
//! this binary on its case (`dustdem sweep <file> --out <dir> --case $SLURM_ARRAY_TASK_ID`),
//! which skips, resumes or runs it exactly as a local sweep would; `dustdem sweep collect`
//! merges what the tasks wrote.

use super::spec::SlurmSettings;
use super::SBATCH_FILE;
use crate::output::atomic::write_atomic;
use std::path::{Path, PathBuf};

/// What the script asks for and runs.
pub struct Script<'a> {
    pub exe: &'a Path,
    pub sweep_file: &'a Path,
    pub out_dir: &'a Path,
    pub cases: usize,
    pub threads: usize,
    pub backend: &'a str,
    pub settings: &'a SlurmSettings,
    pub job_name: String,
}

/// A word for a POSIX shell, single-quoted.
fn sh_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

/// Slurm reads `#SBATCH` lines without a shell: a path there must not need quoting.
fn plain_path(what: &str, p: &Path) -> Result<String, String> {
    let s = p.display().to_string();
    if s.chars()
        .any(|c| c.is_whitespace() || "'\"\\$`%".contains(c))
    {
        return Err(format!(
            "{what} {s}: Slurm's #SBATCH lines cannot hold a path with spaces, quotes, '$', '`', \
             '\\' or '%'; use --out with a plainer directory"
        ));
    }
    Ok(s)
}

impl Script<'_> {
    /// The script's text.
    pub fn text(&self) -> Result<String, String> {
        let s = self.settings;
        let logs = plain_path("output directory", &self.out_dir.join("slurm"))?;
        let mut array = format!("0-{}", self.cases - 1);
        if s.max_running > 0 {
            array.push_str(&format!("%{}", s.max_running));
        }
        let mut lines = vec![
            "#!/bin/bash".to_string(),
            format!(
                "# dustdem sweep of {}: {} cases, one per array task (list: {}/cases.csv).",
                self.sweep_file.display(),
                self.cases,
                self.out_dir.display()
            ),
            "# Submit with `sbatch` on this file; then `dustdem sweep collect` on the output"
                .to_string(),
            "# directory merges the results. Tasks of finished cases exit at once; a task cut"
                .to_string(),
            "# off (time limit, preemption) checkpoints on SIGTERM, and a resubmission resumes it."
                .to_string(),
            format!("#SBATCH --job-name={}", self.job_name),
            format!("#SBATCH --array={array}"),
            "#SBATCH --ntasks=1".to_string(),
            format!("#SBATCH --cpus-per-task={}", self.threads),
            format!("#SBATCH --time={}", s.time),
            format!("#SBATCH --mem={}M", s.mem_mb),
            format!("#SBATCH --output={logs}/%A_%a.out"),
        ];
        if let Some(p) = &s.partition {
            lines.push(format!("#SBATCH --partition={p}"));
        }
        if let Some(a) = &s.account {
            lines.push(format!("#SBATCH --account={a}"));
        }
        lines.push(String::new());
        lines.push("set -u".to_string());
        lines.push(format!(
            "exec {} sweep {} --out {} --case \"$SLURM_ARRAY_TASK_ID\" --threads {} --backend {}",
            sh_quote(&self.exe.display().to_string()),
            sh_quote(&self.sweep_file.display().to_string()),
            sh_quote(&self.out_dir.display().to_string()),
            self.threads,
            self.backend
        ));
        lines.push(String::new());
        Ok(lines.join("\n"))
    }

    /// Writes `sweep.sbatch` (and the `slurm/` directory for the tasks' output) into the
    /// output directory; returns the script's path.
    pub fn write(&self) -> Result<PathBuf, String> {
        let text = self.text()?;
        let logs = self.out_dir.join("slurm");
        std::fs::create_dir_all(&logs).map_err(|e| format!("{}: {e}", logs.display()))?;
        let path = self.out_dir.join(SBATCH_FILE);
        write_atomic(&path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_survive_the_shell() {
        assert_eq!(sh_quote("a b"), "'a b'");
        assert_eq!(sh_quote("it's"), "'it'\\''s'");
    }

    #[test]
    fn the_array_has_one_task_per_case() {
        let settings = SlurmSettings {
            max_running: 4,
            ..SlurmSettings::default()
        };
        let script = Script {
            exe: Path::new("/opt/dustdem"),
            sweep_file: Path::new("/data/s.toml"),
            out_dir: Path::new("/data/runs/s"),
            cases: 12,
            threads: 2,
            backend: "cpu",
            settings: &settings,
            job_name: "dustdem-s".into(),
        };
        let text = script.text().unwrap();
        assert!(text.contains("#SBATCH --array=0-11%4\n"), "{text}");
        assert!(text.contains("#SBATCH --cpus-per-task=2\n"), "{text}");
        assert!(text.contains("#SBATCH --time=01:00:00\n"), "{text}");
        assert!(text.contains("#SBATCH --mem=2000M\n"), "{text}");
        assert!(text.contains(
            "exec '/opt/dustdem' sweep '/data/s.toml' --out '/data/runs/s' --case \
             \"$SLURM_ARRAY_TASK_ID\" --threads 2 --backend cpu"
        ));
        let spaced = Script {
            out_dir: Path::new("/data/my runs"),
            ..script
        };
        assert!(spaced.text().unwrap_err().contains("spaces"));
    }
}
