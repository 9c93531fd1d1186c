//! `dustdem sweep --slurm`: a job-array script with one case per array task. Each task runs
//! this binary on its case (`dustdem sweep <file> --out <dir> --case $SLURM_ARRAY_TASK_ID`),
//! which skips, resumes or runs it exactly as a local sweep would; `dustdem sweep collect`
//! merges what the tasks wrote.

use super::slurm_settings::SlurmSettings;
use super::SBATCH_FILE;
use crate::output::atomic::write_atomic;
use crate::RESUMABLE_EXIT;
use std::path::{Path, PathBuf};

/// What the script asks for and runs.
#[derive(Clone)]
pub struct Script<'a> {
    pub exe: &'a Path,
    pub sweep_file: &'a Path,
    pub out_dir: &'a Path,
    pub cases: usize,
    pub threads: usize,
    pub backend: &'a str,
    pub precision: &'a str,
    pub settings: &'a SlurmSettings,
    pub job_name: String,
}

/// A word for a POSIX shell, single-quoted.
pub(crate) fn sh_quote(s: &str) -> String {
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
            "# directory merges the results. Tasks of finished cases exit at once.".to_string(),
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
        let lead = s.effective_signal_lead_s();
        if lead > 0 {
            lines.push(format!("#SBATCH --signal=B:USR1@{lead}"));
        }
        if s.requeue {
            // A requeued task appends to its log instead of truncating the first attempt's.
            lines.push("#SBATCH --requeue".to_string());
            lines.push("#SBATCH --open-mode=append".to_string());
        }
        lines.push(String::new());
        lines.extend(self.body(lead));
        lines.push(String::new());
        Ok(lines.join("\n"))
    }

    /// The shell part: the case runs as a child of the batch shell, which Slurm's early
    /// warning (USR1, `lead` seconds before the limit) reaches; the shell asks the case to
    /// checkpoint and stop (SIGTERM), and when it stopped at a checkpoint (exit status
    /// [`RESUMABLE_EXIT`]) requeues the task, which resumes the case from that checkpoint.
    /// A plain SIGTERM (scancel, or the limit itself) stops the case the same way but does not
    /// requeue: a resubmission resumes it.
    fn body(&self, lead: u64) -> Vec<String> {
        let run = format!(
            "{} sweep {} --out {} --case \"$SLURM_ARRAY_TASK_ID\" --threads {} --backend {} \
             --precision {}",
            sh_quote(&self.exe.display().to_string()),
            sh_quote(&self.sweep_file.display().to_string()),
            sh_quote(&self.out_dir.display().to_string()),
            self.threads,
            self.backend,
            self.precision
        );
        if lead == 0 && !self.settings.requeue {
            return vec!["set -u".into(), format!("exec {run}")];
        }
        let mut lines = vec![
            format!(
                "# Slurm's warning (USR1, {lead} s before the time limit) asks the case to \
                 checkpoint and stop;"
            ),
            format!(
                "# a case stopped at a checkpoint exits with status {RESUMABLE_EXIT}{}.",
                if self.settings.requeue {
                    ", and the task is requeued to resume it"
                } else {
                    ""
                }
            ),
            "set -u".into(),
            "warned=0".into(),
            format!("{run} &"),
            "case_pid=$!".into(),
            "trap 'warned=1; kill -TERM \"$case_pid\" 2>/dev/null' USR1".into(),
            "trap 'kill -TERM \"$case_pid\" 2>/dev/null' TERM INT".into(),
            "# `wait` returns early when a trapped signal arrives: wait until the case has ended.".into(),
            "status=0; wait \"$case_pid\" || status=$?".into(),
            "while kill -0 \"$case_pid\" 2>/dev/null; do status=0; wait \"$case_pid\" || status=$?; done".into(),
        ];
        if self.settings.requeue {
            lines.extend([
                format!("if [ \"$warned\" = 1 ] && [ \"$status\" = {RESUMABLE_EXIT} ]; then"),
                "  echo \"dustdem: time limit near; the case checkpointed; requeueing task ${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"".into(),
                "  scontrol requeue \"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"".into(),
                "fi".into(),
            ]);
        }
        lines.push("exit \"$status\"".into());
        lines
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
            precision: "mixed",
            settings: &settings,
            job_name: "dustdem-s".into(),
        };
        let text = script.text().unwrap();
        assert!(text.contains("#SBATCH --array=0-11%4\n"), "{text}");
        assert!(text.contains("#SBATCH --cpus-per-task=2\n"), "{text}");
        assert!(text.contains("#SBATCH --time=01:00:00\n"), "{text}");
        assert!(text.contains("#SBATCH --mem=2000M\n"), "{text}");
        assert!(text.contains(
            "\n'/opt/dustdem' sweep '/data/s.toml' --out '/data/runs/s' --case \
             \"$SLURM_ARRAY_TASK_ID\" --threads 2 --backend cpu --precision mixed &\n"
        ));
        // The warning 300 s ahead, requeue on the resumable status only after the warning.
        for line in [
            "#SBATCH --signal=B:USR1@300\n",
            "#SBATCH --requeue\n",
            "#SBATCH --open-mode=append\n",
            "trap 'warned=1; kill -TERM \"$case_pid\" 2>/dev/null' USR1\n",
            "if [ \"$warned\" = 1 ] && [ \"$status\" = 75 ]; then\n",
            "  scontrol requeue \"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n",
        ] {
            assert!(text.contains(line), "{line} in:\n{text}");
        }
        // Every #SBATCH line comes before the first command (sbatch stops reading there).
        let last_directive = text.rfind("#SBATCH").unwrap();
        assert!(last_directive < text.find("set -u").unwrap(), "{text}");
        let no_requeue = SlurmSettings {
            requeue: false,
            ..settings.clone()
        };
        let plain = Script {
            settings: &no_requeue,
            ..script.clone()
        }
        .text()
        .unwrap();
        assert!(
            !plain.contains("--requeue") && !plain.contains("scontrol"),
            "{plain}"
        );
        assert!(plain.contains("#SBATCH --signal=B:USR1@300\n"), "{plain}");
        let spaced = Script {
            out_dir: Path::new("/data/my runs"),
            ..script
        };
        assert!(spaced.text().unwrap_err().contains("spaces"));
    }
}
