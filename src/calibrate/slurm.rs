//! `dustdem calibrate --slurm`: the runs a calibration step needs, made as a Slurm job array
//! over the run cache instead of on local threads.
//!
//! Each batch of missing runs is written as one request file per run (the run's cache key:
//! its kind and complete config) into `CACHE/slurm/batch-<hash>/`, with a job-array script
//! whose task K runs `dustdem calibrate-run --cache CACHE --request .../task-K.key`. That
//! task makes the run through the same cache (its entry lock keeps two tasks from making
//! one run) and stores it; a task whose run is already stored exits at once, so a resubmitted
//! or requeued batch only makes what is missing. The calibration submits with `sbatch --wait`,
//! then reads every result from the cache exactly as a local calibration does, so the two
//! give the same report. The batch directory is named by the hash of its requests, so an
//! interrupted calibration run again finds its batch where it left it.

use super::simulate::Run;
use crate::binary::fnv1a64;
use crate::output::atomic::write_atomic;
use crate::sweep::slurm::sh_quote;
use crate::sweep::slurm_settings::SlurmSettings;
use std::path::{Path, PathBuf};
use std::process::Command;

/// How calibration runs go to Slurm.
#[derive(Clone, Debug)]
pub struct SlurmRuns {
    /// This binary, by its absolute path (the tasks run it).
    pub exe: PathBuf,
    /// Time, memory, partition, account and the most tasks at once of each array.
    pub settings: SlurmSettings,
}

/// The batch's directory under the cache: named by the hash of its requests in order.
pub fn batch_dir(cache: &Path, keys: &[String]) -> PathBuf {
    let all = keys.join("\u{0}");
    cache
        .join("slurm")
        .join(format!("batch-{:016x}", fnv1a64(all.as_bytes())))
}

/// The job-array script of a batch of `count` runs.
pub fn script(s: &SlurmRuns, cache: &Path, dir: &Path, count: usize) -> String {
    let mut array = format!("0-{}", count - 1);
    if s.settings.max_running > 0 {
        array.push_str(&format!("%{}", s.settings.max_running));
    }
    let mut lines = vec![
        "#!/bin/bash".to_string(),
        format!(
            "# dustdem calibration batch: {count} run(s), one per array task (requests: \
             task-K.key beside this file); a task whose run is in the cache exits at once."
        ),
        "#SBATCH --job-name=dustdem-calibrate".to_string(),
        format!("#SBATCH --array={array}"),
        "#SBATCH --ntasks=1".to_string(),
        "#SBATCH --cpus-per-task=1".to_string(),
        format!("#SBATCH --time={}", s.settings.time),
        format!("#SBATCH --mem={}M", s.settings.mem_mb),
        format!("#SBATCH --output={}/%A_%a.out", dir.display()),
    ];
    if let Some(p) = &s.settings.partition {
        lines.push(format!("#SBATCH --partition={p}"));
    }
    if let Some(a) = &s.settings.account {
        lines.push(format!("#SBATCH --account={a}"));
    }
    lines.push(String::new());
    lines.push("set -u".to_string());
    lines.push(format!(
        "exec {} calibrate-run --cache {} --request {}/task-\"$SLURM_ARRAY_TASK_ID\".key",
        sh_quote(&s.exe.display().to_string()),
        sh_quote(&cache.display().to_string()),
        sh_quote(&dir.display().to_string()),
    ));
    lines.push(String::new());
    lines.join("\n")
}

/// Makes `runs` (the ones the cache does not hold yet) as one job array and waits for it.
/// Returns the batch directory; an error names the tasks' logs when the array failed.
pub fn run_batch(
    s: &SlurmRuns,
    cache: &Path,
    runs: &[&Run],
    progress: &(dyn Fn(&str) + Sync),
) -> Result<PathBuf, String> {
    let keys: Vec<String> = runs.iter().map(|r| r.key()).collect();
    let dir = batch_dir(cache, &keys);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (k, key) in keys.iter().enumerate() {
        let path = dir.join(format!("task-{k}.key"));
        write_atomic(&path, key.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let path = dir.join("batch.sbatch");
    write_atomic(&path, script(s, cache, &dir, keys.len()).as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    progress(&format!(
        "  slurm: {} run(s) as a job array ({}), waiting for it",
        keys.len(),
        path.display()
    ));
    let out = Command::new("sbatch")
        .args(["--parsable", "--wait"])
        .arg(&path)
        .current_dir(&dir)
        .output()
        .map_err(|e| format!("sbatch {}: {e} (is Slurm installed here?)", path.display()))?;
    if !out.status.success() {
        return Err(format!(
            "the Slurm job array {} failed ({}): {}; the tasks' logs are in {}; runs that \
             finished are kept in the cache, so running the calibration again only makes the \
             rest",
            path.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim(),
            dir.display()
        ));
    }
    Ok(dir)
}

/// `dustdem calibrate-run`: one array task. Reads the request, checks that it names a run
/// exactly (its config read back gives the same key), and makes it through the cache.
pub fn run_request(cache: &Path, request: &Path) -> Result<String, String> {
    let key =
        std::fs::read_to_string(request).map_err(|e| format!("{}: {e}", request.display()))?;
    let run = Run::from_key(&key).map_err(|e| format!("{}: {e}", request.display()))?;
    if run.key() != key {
        return Err(format!(
            "{}: the request's config does not read back to the same run (written by another \
             dustdem version?)",
            request.display()
        ));
    }
    let store = super::simulate::RunCache::persistent(cache);
    store.get(&run)?;
    Ok(format!(
        "{} {} {}",
        run.describe(),
        if store.made() > 0 {
            "made and stored in"
        } else {
            "found in"
        },
        store
            .entry_path(&run)
            .map_or_else(|| cache.display().to_string(), |p| p.display().to_string())
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    #[test]
    fn a_run_reads_back_from_its_key_and_names_its_batch_by_content() {
        let mut config = Config::default();
        config.sample.monomers = 60;
        let runs = [Run::Compression(config.clone()), Run::Sticking(config)];
        for run in &runs {
            let back = Run::from_key(&run.key()).unwrap();
            assert_eq!(&back, run);
        }
        assert!(Run::from_key("melting\n").is_err());
        let keys: Vec<String> = runs.iter().map(|r| r.key()).collect();
        let cache = Path::new("/c");
        assert_eq!(batch_dir(cache, &keys), batch_dir(cache, &keys));
        assert_ne!(batch_dir(cache, &keys), batch_dir(cache, &keys[..1]));
        let s = SlurmRuns {
            exe: PathBuf::from("/opt/dustdem"),
            settings: SlurmSettings::default(),
        };
        let text = script(&s, cache, Path::new("/c/slurm/b"), 2);
        assert!(text.contains("#SBATCH --array=0-1\n"), "{text}");
        assert!(
            text.contains(
                "exec '/opt/dustdem' calibrate-run --cache '/c' --request \
                 '/c/slurm/b'/task-\"$SLURM_ARRAY_TASK_ID\".key\n"
            ),
            "{text}"
        );
    }
}
