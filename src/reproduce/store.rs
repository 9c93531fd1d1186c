//! The committed record of a tier: for every finished case, what the analysis reads (its
//! curve and a thinned set of its profiles, as compact CSV) and an index entry (parameters,
//! wall-clock, stop reason, machine). The report is built from this store alone, so
//! `dustdem reproduce --report-only` rebuilds it from the repository, and a later run only
//! adds the cases still missing.
//!
//! Layout: `<study>/cases.toml` (the index) and `<study>/cases/<case>.curve.csv`,
//! `<study>/cases/<case>.profiles.csv`. Numbers keep six significant digits: the analysis
//! reads φ to 1e-4 and pressures to a per cent, and the store stays small (about 100 kB per
//! 40 000-monomer run at 1 m/s).

use crate::analysis::run_files::{
    attach_wall_heights, read_curve_table, read_profiles, CurveTable, Profile,
};
use crate::output::atomic::write_atomic;
use crate::output::csv::format_number;
use crate::sweep::collect::collect;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Profiles kept per case besides the initial one: enough to follow a front through the
/// sample (one every ~1.5 µm of wall travel in a 60 µm box).
pub const PROFILES_KEPT: usize = 40;
/// A run directory's own record of where it ran, read instead of the harvesting machine: a
/// case started on a lent GPU and continued from its checkpoint on a CPU says so here.
pub const MACHINE_FILE: &str = "machine.txt";
/// Significant digits of the stored numbers.
const DIGITS: usize = 6;

/// One case's index entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredCase {
    pub case: String,
    pub wall_speed_m_s: f64,
    pub seed: u64,
    pub variant: String,
    pub monomers: usize,
    pub steps: u64,
    pub wall_clock_s: f64,
    pub stop: String,
    /// The machine it ran on, as `dustdem bench` names it; for a case run elsewhere or on
    /// several machines, the run directory's `machine.txt` (see [`MACHINE_FILE`]).
    pub machine: String,
}

#[derive(Debug, Default, Serialize, Deserialize)]
struct Index {
    #[serde(default)]
    case: Vec<StoredCase>,
}

/// A stored case with its data, ready for the analysis.
#[derive(Clone, Debug)]
pub struct CaseRecord {
    pub entry: StoredCase,
    pub curve: CurveTable,
    /// The initial profile first; each with its top-wall height attached.
    pub profiles: Vec<Profile>,
}

fn index_path(store: &Path) -> PathBuf {
    store.join("cases.toml")
}

fn read_index(store: &Path) -> Result<Index, String> {
    let path = index_path(store);
    match std::fs::read_to_string(&path) {
        Ok(text) => toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Index::default()),
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// `v` rounded to [`DIGITS`] significant digits, in its shortest form.
fn compact(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return format_number(v);
    }
    let rounded: f64 = format!("{:.*e}", DIGITS - 1, v)
        .parse()
        .expect("a formatted float parses");
    format_number(rounded)
}

fn csv_line(out: &mut String, values: &[f64]) {
    let cells: Vec<String> = values.iter().map(|&v| compact(v)).collect();
    let _ = writeln!(out, "{}", cells.join(","));
}

/// The curve columns the analysis reads, compacted.
fn curve_csv(run: &Path) -> Result<String, String> {
    let (header, rows) = crate::output::csv::read_csv(run.join("curve.csv"))?;
    let names = [
        "step",
        "time_s",
        "wall_gap_um",
        "area_um2",
        "phi",
        "p_top_pa",
    ];
    let cols: Vec<usize> = names
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h == n)
                .ok_or_else(|| format!("{}: no column {n}", run.join("curve.csv").display()))
        })
        .collect::<Result<_, _>>()?;
    let mut out = names.join(",") + "\n";
    for r in &rows {
        let values: Vec<f64> = cols.iter().map(|&c| r[c]).collect();
        csv_line(&mut out, &values);
    }
    Ok(out)
}

/// Indices of the profiles kept: the initial one and at most [`PROFILES_KEPT`] others spread
/// evenly over the run.
pub fn kept_profiles(count: usize) -> Vec<usize> {
    if count <= PROFILES_KEPT + 1 {
        return (0..count).collect();
    }
    let mut keep: Vec<usize> = (0..=PROFILES_KEPT)
        .map(|k| (k * (count - 1) + PROFILES_KEPT / 2) / PROFILES_KEPT)
        .collect();
    keep.dedup();
    keep
}

fn profiles_csv(run: &Path) -> Result<String, String> {
    let path = run.join("profiles.csv");
    let mut out = String::from("step,time_s,phi_mean,z_um,phi\n");
    if !path.exists() {
        return Ok(out);
    }
    let profiles = read_profiles(&path)?;
    for k in kept_profiles(profiles.len()) {
        let p = &profiles[k];
        for (z, phi) in p.z_m.iter().zip(&p.phi) {
            csv_line(
                &mut out,
                &[p.step as f64, p.time_s, p.phi_mean, z * 1e6, *phi],
            );
        }
    }
    Ok(out)
}

/// Copies every finished case of the sweep directory `runs` that the store lacks into
/// `store`; returns how many were added. Cases already stored are left as they are.
pub fn harvest(runs: &Path, store: &Path, machine: &str) -> Result<usize, String> {
    let collected = collect(runs)?;
    let mut index = read_index(store)?;
    let cases_dir = store.join("cases");
    let mut added = 0;
    for row in collected.rows.iter().filter(|r| r.status == "done") {
        if index.case.iter().any(|c| c.case == row.case) {
            continue;
        }
        let record = row.record.as_ref().expect("a done case has its status");
        let [speed, seed, variant, monomers] = &row.parameters;
        let bad = |what: &str, text: &str| format!("{}: cannot read {what} '{text}'", row.case);
        let run = runs.join(&row.case);
        let ran_on = machine_of(&run, machine)?;
        std::fs::create_dir_all(&cases_dir).map_err(|e| format!("{}: {e}", cases_dir.display()))?;
        for (suffix, text) in [
            ("curve", curve_csv(&run)?),
            ("profiles", profiles_csv(&run)?),
        ] {
            let path = cases_dir.join(format!("{}.{suffix}.csv", row.case));
            write_atomic(&path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        index.case.push(StoredCase {
            case: row.case.clone(),
            wall_speed_m_s: speed.parse().map_err(|_| bad("wall speed", speed))?,
            seed: seed.parse().map_err(|_| bad("seed", seed))?,
            variant: variant.clone(),
            monomers: monomers.parse().map_err(|_| bad("monomers", monomers))?,
            steps: record.steps.unwrap_or(0),
            wall_clock_s: (record.wall_clock_s * 10.0).round() / 10.0,
            stop: record.stop.clone(),
            machine: ran_on,
        });
        added += 1;
    }
    index.case.sort_by(|a, b| a.case.cmp(&b.case));
    let text = "# Finished cases of this study (written by dustdem reproduce).\n".to_string()
        + &toml::to_string(&index).map_err(|e| format!("cases.toml: {e}"))?;
    std::fs::create_dir_all(store).map_err(|e| format!("{}: {e}", store.display()))?;
    write_atomic(&index_path(store), text.as_bytes())
        .map_err(|e| format!("{}: {e}", index_path(store).display()))?;
    Ok(added)
}

/// Where the run in `run` ran: its [`MACHINE_FILE`] (one line) if it has one, else `harvester`.
fn machine_of(run: &Path, harvester: &str) -> Result<String, String> {
    let path = run.join(MACHINE_FILE);
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            let line = text.trim();
            if line.is_empty() || line.contains('\n') {
                return Err(format!(
                    "{}: expected one non-empty line naming the machine(s), found {:?}",
                    path.display(),
                    line
                ));
            }
            Ok(line.to_string())
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(harvester.to_string()),
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// Every case of the store, with its curve and profiles.
pub fn read_store(store: &Path) -> Result<Vec<CaseRecord>, String> {
    let index = read_index(store)?;
    let cases_dir = store.join("cases");
    index
        .case
        .into_iter()
        .map(|entry| {
            let curve = read_curve_table(cases_dir.join(format!("{}.curve.csv", entry.case)))?;
            let mut profiles =
                read_profiles(cases_dir.join(format!("{}.profiles.csv", entry.case)))?;
            attach_wall_heights(&mut profiles, &curve);
            Ok(CaseRecord {
                entry,
                curve,
                profiles,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compact_keeps_six_significant_digits() {
        assert_eq!(compact(0.150000938736), "0.150001");
        assert_eq!(compact(17386126.58403273), "17386100");
        assert_eq!(compact(1.83e-6), "1.83e-6");
        assert_eq!(compact(0.0), "0");
        assert_eq!(compact(f64::NAN), "NaN");
        let v = 123.456789e-7;
        let back: f64 = compact(v).parse().unwrap();
        assert!((back / v - 1.0).abs() < 5e-6);
    }

    #[test]
    fn kept_profiles_start_and_end_with_the_run() {
        assert_eq!(kept_profiles(5), vec![0, 1, 2, 3, 4]);
        let k = kept_profiles(1001);
        assert_eq!(k.len(), PROFILES_KEPT + 1);
        assert_eq!((k[0], *k.last().unwrap()), (0, 1000));
        assert!(k.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn a_run_names_its_own_machines_in_machine_txt() {
        let dir = std::env::temp_dir().join(format!("dustdem-machine-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(machine_of(&dir, "harvester").unwrap(), "harvester");
        std::fs::write(dir.join(MACHINE_FILE), "GPU to step 10, then CPU\n").unwrap();
        assert_eq!(
            machine_of(&dir, "harvester").unwrap(),
            "GPU to step 10, then CPU"
        );
        std::fs::write(dir.join(MACHINE_FILE), " \n").unwrap();
        let err = machine_of(&dir, "harvester").unwrap_err();
        assert!(
            err.contains("machine.txt") && err.contains("one non-empty line"),
            "{err}"
        );
        std::fs::write(dir.join(MACHINE_FILE), "a\nb\n").unwrap();
        assert!(machine_of(&dir, "harvester").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
