//! `dustdem sweep analyze`: the science of a finished sweep as Seizinger et al. (2012, Sect. 5)
//! do it. The seeds of each (variant, size, speed) are averaged on a common pressure grid,
//! Eq. 13 is fitted per speed (φ₁, φ₂ held at Güttler's values, and free), p_m(v) and Δ(v) with
//! the paper's ansätze where enough speeds exist, the compaction-front speed per run and over
//! seeds, and the three regimes of a dynamic curve are marked; all written as `analysis.md`
//! beside the paper's numbers, with figures.

use super::collect::collect;
use crate::analysis::average::{average_on_log_grid, spread, AveragePoint, Spread};
use crate::analysis::fit::{Eq13, FitResult};
use crate::analysis::front::{front_heights, run_front_speed, FrontOptions};
use crate::analysis::law_checks::{self, Law, Laws, SpeedValue};
use crate::analysis::per_speed::{fit_speed, SpeedFit, GUETTLER_PHI1, GUETTLER_PHI2};
use crate::analysis::regimes::{regimes_of_runs, RegimeOptions, RegimeSummary};
use crate::analysis::run_files::{read_curve, read_run_profiles};
use crate::analysis::speed_laws::{
    PowerLaw, Quadratic, ShiftedPowerLaw, PAPER_DELTA, PAPER_PM_DYNAMIC, PAPER_PM_DYNAMIC_SQUARE,
    PAPER_PM_QUASI_STATIC, PAPER_V_CRIT,
};
use crate::job::figure::{BLUM_SCHRAEPLER_2004_UNI, GUETTLER_2009_OMNI};
use crate::output::atomic::write_atomic;
use crate::output::plot::{panels_png, panels_svg, Plot, Series, Style, PALETTE};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod figures;
#[cfg(test)]
mod tests;

use figures::{curves_plot, delta_plot, pm_plot, profiles_plot};
pub use figures::{first_seeds, law_series, profile_figure_name, reference_series};

/// Wall speeds from this one up are dynamic compression (the paper's v ≥ 1 m/s).
pub const DYNAMIC_FROM: f64 = 1.0;
/// Pressure-grid points per decade of the seed averages.
const GRID_PER_DECADE: usize = 8;
/// The pressure range over which a curve is compared with Güttler et al. (2009) [Pa].
pub const COMPARE_RANGE: (f64, f64) = (1e2, 1e5);

/// One finished run of a sweep, as the analysis needs it.
#[derive(Clone, Debug)]
pub struct CaseData {
    pub name: String,
    pub wall_speed: f64,
    pub seed: u64,
    pub variant: String,
    pub monomers: usize,
    /// (P [Pa], φ) rows of its curve.
    pub curve: Vec<(f64, f64)>,
    /// Compaction-front speed [m/s] from its profiles, where it has one.
    pub front_speed: Option<f64>,
}

/// The seeds of one (variant, size, speed).
#[derive(Clone, Debug)]
pub struct SpeedGroup {
    pub wall_speed: f64,
    pub seeds: usize,
    pub average: Vec<AveragePoint>,
    pub fit: SpeedFit,
    /// RMS of the mean φ minus Güttler's Eq. 13 over [`COMPARE_RANGE`], and the points in it.
    pub rms_vs_guettler: Option<(f64, usize)>,
    /// Front speed over the seeds that have one.
    pub front: Option<Spread>,
    /// Regimes of each run in time order, over the seeds (dynamic speeds only).
    pub regimes: Option<RegimeSummary>,
}

/// Everything of one (variant, size).
#[derive(Clone, Debug)]
pub struct Family {
    pub variant: String,
    pub monomers: usize,
    pub speeds: Vec<SpeedGroup>,
    pub laws: Laws,
}

/// Groups the cases by (variant, size, speed) and analyses each group and family.
pub fn analyze_cases(cases: &[CaseData]) -> Vec<Family> {
    let mut families: BTreeMap<(String, usize), BTreeMap<u64, Vec<&CaseData>>> = BTreeMap::new();
    for c in cases {
        families
            .entry((c.variant.clone(), c.monomers))
            .or_default()
            .entry(c.wall_speed.to_bits())
            .or_default()
            .push(c);
    }
    families
        .into_iter()
        .map(|((variant, monomers), by_speed)| {
            let mut speeds: Vec<SpeedGroup> = by_speed.into_values().map(speed_group).collect();
            speeds.sort_by(|a, b| a.wall_speed.total_cmp(&b.wall_speed));
            let laws = speed_laws(&speeds);
            Family {
                variant,
                monomers,
                speeds,
                laws,
            }
        })
        .collect()
}

fn speed_group(runs: Vec<&CaseData>) -> SpeedGroup {
    let curves: Vec<Vec<(f64, f64)>> = runs.iter().map(|c| c.curve.clone()).collect();
    let average = average_on_log_grid(&curves, GRID_PER_DECADE);
    let points: Vec<(f64, f64)> = average.iter().map(|a| (a.p, a.mean)).collect();
    // The seeds' standard errors weight the fit where every point has one; a single seed
    // (or a point only one seed reached) leaves the residual scatter to scale the errors.
    let sem: Vec<f64> = average.iter().map(|a| a.sem).collect();
    let sigma = sem
        .iter()
        .all(|s| s.is_finite() && *s > 0.0)
        .then_some(&sem[..]);
    let fit = fit_speed(&points, sigma, GUETTLER_PHI1, GUETTLER_PHI2);
    let fronts: Vec<f64> = runs.iter().filter_map(|c| c.front_speed).collect();
    SpeedGroup {
        wall_speed: runs[0].wall_speed,
        seeds: runs.len(),
        rms_vs_guettler: rms_against(&points, &GUETTLER_2009_OMNI, COMPARE_RANGE),
        front: spread(&fronts),
        regimes: (runs[0].wall_speed >= DYNAMIC_FROM).then(|| {
            let rows: Vec<&[(f64, f64)]> = runs.iter().map(|c| c.curve.as_slice()).collect();
            regimes_of_runs(&rows, &RegimeOptions::default())
        }),
        average,
        fit,
    }
}

/// RMS of φ − reference φ over the points with P in `range`.
pub fn rms_against(
    points: &[(f64, f64)],
    reference: &Eq13,
    range: (f64, f64),
) -> Option<(f64, usize)> {
    let d: Vec<f64> = points
        .iter()
        .filter(|(p, _)| *p >= range.0 && *p <= range.1)
        .map(|(p, phi)| phi - reference.phi(*p))
        .collect();
    if d.is_empty() {
        return None;
    }
    Some((
        (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt(),
        d.len(),
    ))
}

/// p_m [kPa] and Δ of the fixed-φ fits, with their errors, speed by speed.
#[derive(Default)]
struct Fitted {
    v: Vec<f64>,
    pm: Vec<f64>,
    pm_err: Vec<f64>,
    delta: Vec<f64>,
    delta_err: Vec<f64>,
}

/// The fixed-φ fits at the speeds `keep` accepts (those with usable errors).
fn fitted(speeds: &[SpeedGroup], keep: impl Fn(f64) -> bool) -> Fitted {
    let mut out = Fitted::default();
    for s in speeds.iter().filter(|s| keep(s.wall_speed)) {
        if let Ok(f) = &s.fit.fixed {
            if f.std_err.p_m.is_finite() && f.std_err.p_m > 0.0 && f.std_err.delta > 0.0 {
                out.v.push(s.wall_speed);
                out.pm.push(f.params.p_m / 1e3);
                out.pm_err.push(f.std_err.p_m / 1e3);
                out.delta.push(f.params.delta);
                out.delta_err.push(f.std_err.delta);
            }
        }
    }
    out
}

/// Eqs. 14–17 where the speeds constrain them (`analysis::law_checks`).
fn speed_laws(speeds: &[SpeedGroup]) -> Laws {
    let f = fitted(speeds, |_| true);
    let values: Vec<SpeedValue> = (0..f.v.len())
        .map(|k| [f.v[k], f.pm[k], f.pm_err[k], f.delta[k], f.delta_err[k]])
        .collect();
    law_checks::speed_laws(&values)
}

/// Reads every finished case of the sweep directory `dir` (after `collect`).
pub fn read_cases(dir: &Path) -> Result<(Vec<CaseData>, Vec<String>), String> {
    let collected = collect(dir)?;
    let mut cases = Vec::new();
    let mut skipped = Vec::new();
    for row in &collected.rows {
        if row.status != "done" {
            skipped.push(format!("{} ({})", row.case, row.status));
            continue;
        }
        let [speed, seed, variant, monomers] = &row.parameters;
        let parse = |what: &str, text: &str| format!("{}: cannot read {what} '{text}'", row.case);
        let case_dir = dir.join(&row.case);
        let wall_speed: f64 = speed.parse().map_err(|_| parse("wall speed", speed))?;
        let curve = read_curve(case_dir.join("curve.csv"))?;
        let front_speed = if wall_speed >= DYNAMIC_FROM {
            front_of(&case_dir)
        } else {
            None
        };
        cases.push(CaseData {
            name: row.case.clone(),
            wall_speed,
            seed: seed.parse().map_err(|_| parse("seed", seed))?,
            variant: variant.clone(),
            monomers: monomers.parse().map_err(|_| parse("monomers", monomers))?,
            curve,
            front_speed,
        });
    }
    Ok((cases, skipped))
}

/// The front speed of one run from its profiles, where it wrote enough of them.
fn front_of(case_dir: &Path) -> Option<f64> {
    let profiles = read_run_profiles(case_dir).ok()?;
    run_front_speed(&profiles, &FrontOptions::default()).map(|f| f.front.v)
}

/// Analyses the sweep in `dir` and writes `analysis.md`, `analysis.png` and `analysis.svg` (every
/// figure in a grid of three a row) and one SVG per figure there. Returns the report's path.
pub fn analyze_dir(dir: &Path) -> Result<PathBuf, String> {
    let (cases, skipped) = read_cases(dir)?;
    if cases.is_empty() {
        return Err(format!("{}: no finished case to analyse", dir.display()));
    }
    let families = analyze_cases(&cases);
    let mut panels = Vec::new();
    for f in &families {
        let tag = format!("{}_n{}", f.variant, f.monomers);
        for (name, plot) in [
            (format!("phi_p_{tag}.svg"), curves_plot(f)),
            (format!("pm_v_{tag}.svg"), pm_plot(f)),
            (format!("delta_v_{tag}.svg"), delta_plot(f)),
        ] {
            plot.save(dir.join(&name))
                .map_err(|e| format!("{}: {e}", dir.join(&name).display()))?;
            panels.push(plot);
        }
    }
    // Profiles of the first seed of each dynamic speed, with the front.
    for c in first_seeds(&cases) {
        if let Some(plot) = profiles_plot(&dir.join(&c.name), c) {
            let name = profile_figure_name(c);
            plot.save(dir.join(&name))
                .map_err(|e| format!("{}: {e}", dir.join(&name).display()))?;
            panels.push(plot);
        }
    }
    // Every figure in one grid (three panels a row), as PNG and as SVG.
    let png = panels_png(&panels)?;
    write_atomic(&dir.join("analysis.png"), &png).map_err(|e| format!("analysis.png: {e}"))?;
    let svg = panels_svg(&panels)?;
    write_atomic(&dir.join("analysis.svg"), svg.as_bytes())
        .map_err(|e| format!("analysis.svg: {e}"))?;
    let report = dir.join("analysis.md");
    write_atomic(&report, markdown(&families, &skipped).as_bytes())
        .map_err(|e| format!("{}: {e}", report.display()))?;
    Ok(report)
}

/// Runs with three regimes, and their critical and plateau pressures over those runs.
fn regimes_cell(r: &RegimeSummary) -> String {
    let kpa = |s: Option<crate::analysis::average::Spread>| {
        s.map_or("–".into(), |s| match s.count {
            1 => format!("{:.3}", s.mean / 1e3),
            _ => format!("{:.3} ± {:.3}", s.mean / 1e3, s.sem / 1e3),
        })
    };
    format!(
        "{} of {} runs; critical {} kPa, plateau {} kPa",
        r.three_regimes,
        r.runs,
        kpa(r.critical_pa),
        kpa(r.plateau_pa)
    )
}

fn fmt_fit(f: &Result<FitResult, crate::analysis::fit::FitError>) -> String {
    match f {
        Ok(f) => format!(
            "{:.3} ± {:.3} | {:.3} ± {:.3}",
            f.params.p_m / 1e3,
            f.std_err.p_m / 1e3,
            f.params.delta,
            f.std_err.delta
        ),
        Err(e) => format!("no fit ({e}) | –"),
    }
}

/// The report: per family a table of speeds, then the speed laws beside the paper's.
pub fn markdown(families: &[Family], skipped: &[String]) -> String {
    let mut s = String::from("# Sweep analysis\n\n");
    s += "Seeds averaged on a common pressure grid (φ at the first time a run held P), Eq. 13 \
          fitted to the mean (φ₁ = 0.15, φ₂ = 0.58 held as in Seizinger et al. 2012, and all \
          free), p_m in kPa. Güttler: RMS of mean φ minus Güttler et al. (2009)'s Eq. 13 over \
          10²–10⁵ Pa. v_p: compaction-front speed, mean ± standard error over seeds (paper: \
          6.98 ± 0.16 m/s).\n\n";
    if !skipped.is_empty() {
        let _ = writeln!(s, "Not analysed (not finished): {}.\n", skipped.join(", "));
    }
    for f in families {
        let _ = writeln!(s, "## {} model, {} monomers\n", f.variant, f.monomers);
        s += "| v [m/s] | seeds | p_m fixed | Δ fixed | p_m free | Δ free | paper p_m | paper Δ | RMS Δφ vs Güttler | v_p [m/s] | regimes |\n";
        s += "|---|---|---|---|---|---|---|---|---|---|---|\n";
        for g in &f.speeds {
            let v = g.wall_speed;
            let paper_pm = if v <= 1.0 {
                PAPER_PM_QUASI_STATIC.eval(v)
            } else {
                PAPER_PM_DYNAMIC.eval(v)
            };
            let rms = g
                .rms_vs_guettler
                .map_or("–".into(), |(r, n)| format!("{r:.4} ({n} points)"));
            let front = g.front.as_ref().map_or("–".into(), |f| {
                format!("{:.2} ± {:.2} ({})", f.mean, f.sem, f.count)
            });
            let regimes = g.regimes.as_ref().map_or("–".into(), regimes_cell);
            let free = fmt_fit(&g.fit.free);
            let _ = writeln!(
                s,
                "| {v} | {} | {} | {free} | {paper_pm:.3} | {:.3} | {rms} | {front} | {regimes} |",
                g.seeds,
                fmt_fit(&g.fit.fixed),
                PAPER_DELTA.eval(v)
            );
        }
        s += "\nSpeed laws (p_m in kPa), each only where the speeds constrain it:\n\n";
        s += "| law | fitted | paper |\n|---|---|---|\n";
        let l = &f.laws;
        s += &law_row(
            "p_m = a v² + b v + c (v ≤ 1)",
            &l.pm_slow,
            &PAPER_PM_QUASI_STATIC,
        );
        s += &law_row("p_m = a v^b + c (v ≥ 1)", &l.pm_dynamic, &PAPER_PM_DYNAMIC);
        s += &law_row(
            "p_m = a v² + c (v ≥ 1)",
            &l.pm_square,
            &PAPER_PM_DYNAMIC_SQUARE,
        );
        s += &law_row("Δ = (v + a)^b + c", &l.delta, &PAPER_DELTA);
        let _ = writeln!(
            s,
            "\nThe paper's transition between the two regimes: v_crit ≈ {PAPER_V_CRIT} m/s.\n"
        );
    }
    s
}

/// A law's row: its parameters with errors, or why it is not reported.
fn law_row<L: PlainLaw>(name: &str, law: &Law<L>, paper: &L) -> String {
    let fit = match law {
        Law::Fitted(f) => format!("{} (± {})", f.law.plain(), f.std_err.plain()),
        Law::Unconstrained(why) => format!("not reported: {why}"),
    };
    format!("| {name} | {fit} | {} |\n", paper.plain())
}

/// A law's parameters as plain numbers.
trait PlainLaw {
    fn plain(&self) -> String;
}

impl PlainLaw for Quadratic {
    fn plain(&self) -> String {
        format!("a = {:.4}, b = {:.4}, c = {:.4}", self.a, self.b, self.c)
    }
}

impl PlainLaw for PowerLaw {
    fn plain(&self) -> String {
        format!("a = {:.4}, b = {:.4}, c = {:.4}", self.a, self.b, self.c)
    }
}

impl PlainLaw for ShiftedPowerLaw {
    fn plain(&self) -> String {
        format!("a = {:.4}, b = {:.4}, c = {:.4}", self.a, self.b, self.c)
    }
}
