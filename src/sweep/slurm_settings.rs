//! `[slurm]` of a sweep file: what the job-array script asks the scheduler for, read key by
//! key so that every problem names the field, the value and what is allowed.

use super::spec::Problems;

/// `[slurm]`: what the job-array script asks the scheduler for.
#[derive(Clone, Debug, PartialEq)]
pub struct SlurmSettings {
    /// Time limit per array task, Slurm's format (`MM`, `HH:MM:SS`, `D-HH:MM:SS`, ...).
    pub time: String,
    /// Memory per array task [MB].
    pub mem_mb: u64,
    pub partition: Option<String>,
    pub account: Option<String>,
    /// At most this many array tasks at once (`--array=0-(K-1)%N`); 0: no limit.
    pub max_running: u64,
    /// Slurm's early warning comes this many seconds before the time limit
    /// (`--signal=B:USR1@N`): the case checkpoints and stops, and the task is requeued.
    /// It must cover the time to the next row plus one checkpoint write.
    pub signal_lead_s: u64,
    /// Requeue a task stopped by the early warning (`--requeue`, then `scontrol requeue`).
    pub requeue: bool,
}

impl Default for SlurmSettings {
    fn default() -> Self {
        SlurmSettings {
            time: "01:00:00".to_string(),
            mem_mb: 2000,
            partition: None,
            account: None,
            max_running: 0,
            signal_lead_s: 300,
            requeue: true,
        }
    }
}

/// sbatch(1) on `--signal`: "due to the resolution of event handling by Slurm, the signal may
/// be sent up to 60 seconds earlier than specified" (slurmctld checks limits every 30 s and
/// sends the warning one check ahead).
pub const SIGNAL_EARLY_BY_S: u64 = 60;

/// Slurm's `@sig_time` is a 16-bit count of seconds.
const MAX_SIGNAL_LEAD_S: u64 = 65_535;

impl SlurmSettings {
    /// The lead the script asks for: `signal_lead_s`, but at most half of what the limit
    /// leaves after [`SIGNAL_EARLY_BY_S`], so that even a short limit (a test, a debug queue)
    /// gives every attempt time to work before the warning. A limit of a minute or less gets
    /// no warning (0): it could come as the task starts, and a requeued task would then never
    /// progress.
    pub fn effective_signal_lead_s(&self) -> u64 {
        let limit = slurm_time_seconds(&self.time).unwrap_or(u64::MAX);
        self.signal_lead_s
            .min(limit.saturating_sub(SIGNAL_EARLY_BY_S) / 2)
    }
}

/// Slurm's time formats: `M`, `M:S`, `H:M:S`, `D-H`, `D-H:M`, `D-H:M:S`.
pub(super) fn valid_slurm_time(t: &str) -> bool {
    let (days, rest) = match t.split_once('-') {
        Some((d, r)) => (Some(d), r),
        None => (None, t),
    };
    let digits = |s: &str| !s.is_empty() && s.len() <= 4 && s.chars().all(|c| c.is_ascii_digit());
    if days.is_some_and(|d| !digits(d)) {
        return false;
    }
    let parts: Vec<&str> = rest.split(':').collect();
    let max_parts = 3;
    parts.len() <= max_parts && parts.iter().all(|p| digits(p)) && !(t == "0" || t == "00")
}

/// A Slurm time limit in seconds (None where it is not one).
pub fn slurm_time_seconds(t: &str) -> Option<u64> {
    if !valid_slurm_time(t) {
        return None;
    }
    let (days, rest) = match t.split_once('-') {
        Some((d, r)) => (Some(d.parse::<u64>().ok()?), r),
        None => (None, t),
    };
    let parts: Vec<u64> = rest
        .split(':')
        .map(|p| p.parse().ok())
        .collect::<Option<_>>()?;
    // Without days: M, M:S, H:M:S. With days: D-H, D-H:M, D-H:M:S.
    let seconds = match (days, parts.as_slice()) {
        (None, [m]) => m * 60,
        (None, [m, s]) => m * 60 + s,
        (None, [h, m, s]) | (Some(_), [h, m, s]) => h * 3600 + m * 60 + s,
        (Some(_), [h]) => h * 3600,
        (Some(_), [h, m]) => h * 3600 + m * 60,
        _ => return None,
    };
    Some(days.unwrap_or(0) * 86_400 + seconds)
}

pub(super) fn slurm_settings(p: &mut Problems, table: Option<&toml::Table>) -> SlurmSettings {
    let mut s = SlurmSettings::default();
    for (key, value) in table.into_iter().flatten() {
        let field = format!("[slurm] {key}");
        match key.as_str() {
            "time" => match value.as_str() {
                Some(t) if valid_slurm_time(t) => s.time = t.to_string(),
                _ => p.fail(
                    &field,
                    value,
                    "must be a Slurm time limit such as \"30\" (minutes), \"02:00:00\" or \
                     \"1-00:00:00\"",
                ),
            },
            "mem_mb" => match value.as_integer() {
                Some(m) if (1..=16_000_000).contains(&m) => s.mem_mb = m as u64,
                _ => p.fail(
                    &field,
                    value,
                    "must be an integer between 1 and 16000000 (MB)",
                ),
            },
            "partition" | "account" => match value.as_str() {
                Some(t) if valid_slurm_word(t) => {
                    if key == "partition" {
                        s.partition = Some(t.to_string());
                    } else {
                        s.account = Some(t.to_string());
                    }
                }
                _ => p.fail(
                    &field,
                    value,
                    "must be a name of letters, digits, '_', '-', '.' or ','",
                ),
            },
            "max_running" => match value.as_integer() {
                Some(m) if (0..=100_000).contains(&m) => s.max_running = m as u64,
                _ => p.fail(
                    &field,
                    value,
                    "must be an integer between 0 (no limit) and 100000",
                ),
            },
            "signal_lead_s" => match value.as_integer() {
                Some(m) if (10..=MAX_SIGNAL_LEAD_S as i64).contains(&m) => {
                    s.signal_lead_s = m as u64
                }
                _ => p.fail(
                    &field,
                    value,
                    format!(
                        "must be an integer between 10 and {MAX_SIGNAL_LEAD_S} (seconds before \
                         the time limit)"
                    ),
                ),
            },
            "requeue" => match value.as_bool() {
                Some(b) => s.requeue = b,
                None => p.fail(&field, value, "must be true or false"),
            },
            _ => p.fail(
                &field,
                value,
                "unknown key; allowed: time, mem_mb, partition, account, max_running, \
                 signal_lead_s, requeue",
            ),
        }
    }
    s
}

fn valid_slurm_word(t: &str) -> bool {
    !t.is_empty()
        && t.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-.,".contains(c))
}

/// Checks a `--time` value given on the command line.
pub fn check_slurm_time(t: &str) -> Result<(), String> {
    if valid_slurm_time(t) {
        Ok(())
    } else {
        Err(format!(
            "--time {t}: not a Slurm time limit; allowed e.g. 30 (minutes), 02:00:00, 1-00:00:00"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slurm_times() {
        for ok in ["30", "02:00:00", "1-00:00:00", "1-12", "90:00"] {
            assert!(valid_slurm_time(ok), "{ok}");
        }
        for bad in ["", "1h", "1:2:3:4", "-1", "0", "a-1"] {
            assert!(!valid_slurm_time(bad), "{bad}");
        }
    }

    #[test]
    fn time_limits_in_seconds_follow_slurms_formats() {
        // sbatch(1): "minutes", "minutes:seconds", "hours:minutes:seconds", "days-hours",
        // "days-hours:minutes" and "days-hours:minutes:seconds".
        for (t, s) in [
            ("30", 1800),
            ("2:30", 150),
            ("01:02:03", 3723),
            ("1-2", 93_600),
            ("1-2:30", 95_400),
            ("2-00:00:05", 172_805),
        ] {
            assert_eq!(slurm_time_seconds(t), Some(s), "{t}");
        }
        assert_eq!(slurm_time_seconds("1h"), None);
    }

    #[test]
    fn the_warning_leaves_half_the_limit_even_when_it_comes_a_minute_early() {
        let mut s = SlurmSettings {
            time: "60".into(),
            signal_lead_s: 300,
            ..SlurmSettings::default()
        };
        assert_eq!(s.effective_signal_lead_s(), 300);
        // 120 s: the warning asked 30 s ahead comes 30 to 90 s ahead, after 30 s of work.
        s.time = "2".into();
        assert_eq!(s.effective_signal_lead_s(), 30);
        s.time = "2:01".into();
        assert_eq!(s.effective_signal_lead_s(), 30);
        // A minute or less: no warning, which could come at the start of every attempt.
        s.time = "1".into();
        assert_eq!(s.effective_signal_lead_s(), 0);
        s.time = "0:30".into();
        assert_eq!(s.effective_signal_lead_s(), 0);
        s.time = "1-0".into();
        s.signal_lead_s = 900;
        assert_eq!(s.effective_signal_lead_s(), 900);
    }
}
