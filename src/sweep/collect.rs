//! `dustdem sweep collect`: one table of a sweep's cases, from what each case directory holds
//! (however its cases ran: here, in a Slurm job array, by hand).

use super::{last_row, CaseStatus, CASES_FILE, CURVE_FILE, STATUS_FILE, TABLE_FILE};
use crate::output::atomic::write_atomic;
use crate::output::csv::format_number;
use crate::output::run_dir::{earlier_results, CHECKPOINT_FILE};
use std::path::Path;

/// The columns of `sweep.csv`.
pub const COLUMNS: [&str; 14] = [
    "index",
    "case",
    "wall_speed_m_s",
    "seed",
    "variant",
    "monomers",
    "status",
    "attempts",
    "resumed_from_step",
    "steps",
    "final_phi",
    "final_pressure_pa",
    "wall_clock_s",
    "curve",
];

/// One case's row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub index: usize,
    pub case: String,
    /// The parameters as `cases.csv` spells them: wall speed, seed, variant, monomers.
    pub parameters: [String; 4],
    /// `done`, `failed`, `interrupted`, `running` (or killed while running), `incomplete`
    /// (results without a status: an attempt the sweep did not see end) or `missing`.
    pub status: String,
    pub detail: String,
    pub record: Option<CaseStatus>,
    pub curve: Option<String>,
}

/// What `collect` found.
pub struct Collected {
    pub rows: Vec<Row>,
    pub table: std::path::PathBuf,
}

impl Collected {
    pub fn not_done(&self) -> impl Iterator<Item = &Row> {
        self.rows.iter().filter(|r| r.status != "done")
    }
}

/// Reads `cases.csv` of the sweep directory `dir` and every case directory, and writes
/// `sweep.csv` (atomically) with one row per case.
pub fn collect(dir: &Path) -> Result<Collected, String> {
    let list = dir.join(CASES_FILE);
    let text = std::fs::read_to_string(&list).map_err(|e| {
        format!(
            "{}: {e} (is {} the output directory of a sweep? `dustdem sweep` and `dustdem \
             sweep --slurm` write {CASES_FILE} there)",
            list.display(),
            dir.display()
        )
    })?;
    let mut rows = Vec::new();
    let mut header_seen = false;
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if !header_seen {
            header_seen = true;
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        let bad = || format!("{}:{}: not a case line: {line}", list.display(), n + 1);
        if fields.len() != 6 {
            return Err(bad());
        }
        let index: usize = fields[0].parse().map_err(|_| bad())?;
        let case = fields[1].to_string();
        rows.push(case_row(
            dir,
            index,
            case,
            [
                fields[2].to_string(),
                fields[3].to_string(),
                fields[4].to_string(),
                fields[5].to_string(),
            ],
        ));
    }
    let mut out = COLUMNS.join(",");
    out.push('\n');
    for r in &rows {
        let rec = r.record.as_ref();
        let num = |v: Option<f64>| v.map_or(String::new(), format_number);
        let int = |v: Option<u64>| v.map_or(String::new(), |v| v.to_string());
        let (steps, phi, pressure) = match (rec, &r.curve) {
            (Some(s), _) if r.status == "done" => (s.steps, s.final_phi, s.final_pressure_pa),
            (_, Some(curve)) => last_row(&dir.join(curve)),
            _ => (None, None, None),
        };
        let fields = [
            r.index.to_string(),
            r.case.clone(),
            r.parameters[0].clone(),
            r.parameters[1].clone(),
            r.parameters[2].clone(),
            r.parameters[3].clone(),
            r.status.clone(),
            int(rec.map(|s| u64::from(s.attempts))),
            int(rec.and_then(|s| s.resumed_from_step)),
            int(steps),
            num(phi),
            num(pressure),
            rec.filter(|s| s.status != "running")
                .map_or(String::new(), |s| format!("{:.3}", s.wall_clock_s)),
            r.curve.clone().unwrap_or_default(),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    let table = dir.join(TABLE_FILE);
    write_atomic(&table, out.as_bytes()).map_err(|e| format!("{}: {e}", table.display()))?;
    Ok(Collected { rows, table })
}

fn case_row(dir: &Path, index: usize, case: String, parameters: [String; 4]) -> Row {
    let case_dir = dir.join(&case);
    let curve_rel = format!("{case}/{CURVE_FILE}");
    let curve = case_dir.join(CURVE_FILE).is_file().then_some(curve_rel);
    let record = CaseStatus::read(&case_dir);
    let (status, detail) = match &record {
        _ if !case_dir.is_dir() => ("missing".to_string(), "no case directory".to_string()),
        Some(s) if s.is_done_in(&case_dir) => ("done".into(), s.stop.clone()),
        Some(s) if s.status == "done" => (
            "incomplete".into(),
            "the directory's run is not the one the sweep finished (run again by hand?)".into(),
        ),
        Some(s) if s.status == "running" => (
            "running".into(),
            "an attempt started and has not ended, or was killed before it could say so \
             (SIGKILL, node failure): running the sweep again resumes it"
                .into(),
        ),
        Some(s) => (s.status.clone(), s.message.clone()),
        None if case_dir.join(CHECKPOINT_FILE).is_file() => (
            "incomplete".into(),
            "a checkpoint but no status: running the sweep again resumes it".into(),
        ),
        None if earlier_results(&case_dir).is_ok_and(|r| !r.is_empty()) => {
            ("incomplete".into(), format!("results but no {STATUS_FILE}"))
        }
        None => ("missing".into(), "not started".into()),
    };
    Row {
        index,
        case,
        parameters,
        status,
        detail,
        record,
        curve,
    }
}
