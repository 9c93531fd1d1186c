//! The head-on collision job: two monomers at the configured speed on the CPU reference, and a
//! summary file.

use super::backend::reference_engine;
use super::{create_run_dir, io_err, JobSummary};
use crate::config::Config;
use crate::experiment::collision::{analytic_sticking_speed, head_on_collision, Outcome};
use crate::experiment::compression::RunError;
use crate::output::atomic::write_atomic;
use crate::output::run_dir::{NewRunDir, CONFIG_FILE, SUMMARY_FILE};

pub(super) fn run_collision(
    config: &Config,
    fresh: NewRunDir,
    effective: &str,
) -> Result<JobSummary, RunError> {
    let law = config.contact_law();
    let speed = config.experiment.collision_speed_m_s * 100.0;
    let result = head_on_collision(&law, speed, config.dt(), 5.0, reference_engine)?;
    let outcome = match result.outcome {
        Outcome::Stuck => "stuck".to_string(),
        Outcome::Separated { rebound_speed } => {
            format!("separated, rebound speed {:.4} m/s", rebound_speed / 100.0)
        }
    };
    let lines = vec![
        format!("head-on collision at {:.4} m/s: {outcome}", speed / 100.0),
        format!(
            "largest overlap {:.4} delta0",
            result.max_overlap / law.pair.delta0
        ),
        format!(
            "undamped sticking threshold from the JKR loop: {:.4} m/s",
            analytic_sticking_speed(&law) / 100.0
        ),
    ];
    let (dir, summary_path) = create_run_dir(fresh, effective, |dir| {
        let summary_path = dir.dir.join(SUMMARY_FILE);
        write_atomic(&summary_path, (lines.join("\n") + "\n").as_bytes())
            .map_err(io_err(&summary_path))?;
        Ok(summary_path)
    })?;
    Ok(JobSummary {
        files: vec![dir.dir.join(CONFIG_FILE), summary_path],
        out_dir: dir.dir,
        lines,
    })
}
