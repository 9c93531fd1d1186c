//! How a running job shows itself: a progress bar on a terminal, `key=value` lines for scripts,
//! the signal flag that stops a run at its next checkpoint (and, for commands without one, the
//! signal handler that releases their locks), and the summary printed at the end.

use super::args::ReportArgs;
use crate::job::{JobSummary, Progress};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Shows progress as a bar (on a terminal), as machine-readable lines, or not at all.
pub(super) struct Reporter {
    bar: Option<ProgressBar>,
    log_lines: bool,
}

impl Reporter {
    pub(super) fn new(args: &ReportArgs) -> Self {
        let bar = (!args.quiet && !args.log_lines).then(|| {
            let bar = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {percent:>3}% eta {eta} | {msg}")
                    .expect("valid template"),
            );
            bar
        });
        Reporter {
            bar,
            log_lines: args.log_lines && !args.quiet,
        }
    }

    pub(super) fn report(&self, p: &Progress) {
        let r = p.row;
        if let Some(bar) = &self.bar {
            bar.set_position((p.fraction * 1000.0) as u64);
            bar.set_message(format!(
                "step {} | {:.3e} steps/s | phi {:.4} | P {:.3e} Pa",
                r.step, p.steps_per_second, r.phi, r.p_top
            ));
        }
        if self.log_lines {
            eprintln!(
                "row step={} time_s={:e} phi={} p_top_pa={:e} p_bottom_pa={:e} contacts={} steps_per_s={:.4e} progress={:.4}",
                r.step, r.time, r.phi, r.p_top, r.p_bottom, r.contacts, p.steps_per_second, p.fraction
            );
        }
    }

    /// A line between the bar's redraws (a plain line where there is no bar).
    pub(super) fn note(&self, line: &str) {
        match &self.bar {
            Some(bar) => bar.println(line),
            None => eprintln!("{line}"),
        }
    }

    pub(super) fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// SIGINT and SIGTERM raise this flag; the run checkpoints at the next row and stops.
pub(super) fn interrupt_flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // If a handler cannot be installed the run simply cannot be interrupted cleanly.
        let _ = signal_hook::flag::register(signal, Arc::clone(&flag));
    }
    flag
}

/// Set when the command stopped on a signal after writing its checkpoints (and nothing
/// failed): it then exits with [`crate::RESUMABLE_EXIT`] instead of the error status.
static STOPPED_AT_CHECKPOINT: AtomicBool = AtomicBool::new(false);

pub(super) fn mark_stopped_at_checkpoint() {
    STOPPED_AT_CHECKPOINT.store(true, Ordering::SeqCst);
}

pub(super) fn stopped_at_checkpoint() -> bool {
    STOPPED_AT_CHECKPOINT.load(Ordering::SeqCst)
}

/// For commands without a stop of their own (calibrate, reproduce): SIGINT and SIGTERM remove
/// the directory locks this process holds, then end it with status 128 + the signal, as the
/// signal itself would.
pub(super) fn release_locks_on_signal() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            crate::output::lock::remove_held();
            std::process::exit(128 + signal);
        }
    });
}

pub(super) fn print_summary(summary: &JobSummary) {
    for line in &summary.lines {
        println!("{line}");
    }
    println!("results in {}:", summary.out_dir.display());
    for f in &summary.files {
        println!("  {}", f.display());
    }
}
