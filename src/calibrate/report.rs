//! What a calibration writes: `report.md` (the gap, where it is, every effect's fit, the
//! decision), `calibration.png` and one SVG per compression curve (measured vs baseline vs
//! corrected), and `corrected.toml` (the config with the named effects applied).

use super::figures::plot_panels;
use super::gap::{chi2_quantile_95, Gap};
use super::measured::MeasuredSet;
use super::report_round::round_section;
use super::report_tables::*;
use super::workflow::Calibration;
use crate::output::atomic::write_atomic;
use crate::output::plot::panels_png;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub const REPORT_FILE: &str = "report.md";
pub const CORRECTED_FILE: &str = "corrected.toml";
pub const PLOT_FILE: &str = "calibration.png";

/// Shrink of the noise-normalised gap, 1 − √(χ²_after/χ²_before): 1 when the corrected model
/// fits perfectly, 0 when nothing changed.
pub fn gap_shrink(before: &Gap, after: &Gap) -> f64 {
    1.0 - (after.chi2 / before.chi2).sqrt()
}

/// The gap of one curve that was beyond its own noise at the baseline, before and after.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveShrink {
    pub name: String,
    pub rms_before: f64,
    pub rms_after: f64,
}

impl CurveShrink {
    /// 1 − RMS_after/RMS_before.
    pub fn shrink(&self) -> f64 {
        1.0 - self.rms_after / self.rms_before
    }
}

/// The RMS gap, before and after, of every curve whose baseline χ² is beyond the 95% quantile
/// of one degree of freedom: the curves the named effects had to fix. Curves already within
/// noise at the baseline are controls; their RMS gap is noise and cannot shrink, so they are
/// judged by staying within noise (the data set's χ²), not here. The data set's normalised
/// shrink ([`gap_shrink`]) mixes both kinds of curve and is reported beside this.
pub fn curve_shrinks(before: &Gap, after: &Gap) -> Vec<CurveShrink> {
    let limit = chi2_quantile_95(1);
    before
        .curves
        .iter()
        .zip(&after.curves)
        .filter(|(b, _)| b.chi2 > limit)
        .map(|(b, a)| CurveShrink {
            name: b.name.clone(),
            rms_before: b.rms,
            rms_after: a.rms,
        })
        .collect()
}

/// "omni 85%, sticking 99%": the shrink of each curve that was beyond noise.
pub fn describe_curve_shrinks(before: &Gap, after: &Gap) -> String {
    let parts: Vec<String> = curve_shrinks(before, after)
        .iter()
        .map(|c| format!("{} {:.0}%", c.name, 100.0 * c.shrink()))
        .collect();
    if parts.is_empty() {
        "no curve was beyond noise".into()
    } else {
        parts.join(", ")
    }
}

/// Writes the report, plots and corrected config into `out`; returns the files written.
pub fn write_outputs(
    cal: &Calibration,
    out: &Path,
    measured: &str,
    config_path: &Path,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let write = |name: &str, bytes: &[u8]| -> Result<PathBuf, String> {
        let path = out.join(name);
        write_atomic(&path, bytes).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(path)
    };
    let mut files = Vec::new();
    files.push(write(
        CORRECTED_FILE,
        corrected_config(cal, measured, config_path).as_bytes(),
    )?);
    let panels = plot_panels(cal);
    let png = panels_png(&panels).map_err(|e| format!("{PLOT_FILE}: {e}"))?;
    files.push(write(PLOT_FILE, &png)?);
    // The compression panels again, one SVG each.
    for (k, panel) in panels
        .iter()
        .take(cal.measured.compression.len())
        .enumerate()
    {
        let name = format!("curve_{}.svg", k + 1);
        let svg = panel.to_svg().map_err(|e| format!("{name}: {e}"))?;
        files.push(write(&name, svg.as_bytes())?);
    }
    files.push(write(
        REPORT_FILE,
        markdown(cal, measured, config_path).as_bytes(),
    )?);
    Ok(files)
}

/// The base config with the named effects applied, headed by what was changed and why.
pub fn corrected_config(cal: &Calibration, measured: &str, config_path: &Path) -> String {
    let mut s = format!(
        "# Calibrated from {} against {}.\n",
        config_path.display(),
        measured
    );
    if cal.applied.is_empty() {
        s.push_str("# No effect was applied: this is the base config.\n");
    }
    for (effect, factor) in &cal.applied {
        let _ = writeln!(
            s,
            "# {} ({}) x{:.4}: {}",
            effect.name(),
            effect.key(),
            factor,
            effect.describe_value(&cal.base, *factor)
        );
    }
    s.push('\n');
    s.push_str(&toml::to_string(&cal.corrected).expect("configs serialise"));
    s
}

/// The Markdown report.
pub fn markdown(cal: &Calibration, measured: &str, config_path: &Path) -> String {
    let mut s = String::from("# Calibration report\n\n");
    header_section(&mut s, cal, measured, config_path);
    baseline_section(&mut s, cal);
    for (k, round) in cal.rounds.iter().enumerate() {
        round_section(&mut s, cal, k, round, k == 0 && nothing_named(cal));
    }
    revisits_section(&mut s, cal);
    result_section(&mut s, cal);
    let _ = writeln!(
        s,
        "\nCorrected config: `{CORRECTED_FILE}`.\n\n![measured, baseline and corrected]({PLOT_FILE})"
    );
    s
}

/// What was compared with what: the data and their source, the base config, the runs and the
/// search.
fn header_section(s: &mut String, cal: &Calibration, measured: &str, config_path: &Path) {
    let m = &cal.measured;
    let c = &cal.base;
    let _ = writeln!(s, "- measured data: `{measured}`");
    let _ = writeln!(s, "  - source: {}", m.source.citation);
    if !m.source.what.is_empty() {
        let _ = writeln!(s, "  - what: {}", m.source.what);
    }
    if !m.source.notes.is_empty() {
        let _ = writeln!(s, "  - notes: {}", m.source.notes);
    }
    let _ = writeln!(s, "- base config: `{}`", config_path.display());
    let _ = writeln!(
        s,
        "- simulations: {} RBD monomers per sample, seeds {:?}, wall at {}, dt {} ns; {} runs",
        c.sample.monomers,
        cal.settings.seeds,
        wall_speeds_text(m, c.experiment.wall_speed_m_s),
        c.integration.dt_ns,
        cal.runs
    );
    let _ = writeln!(s, "- search: {}", search_text(cal));
    if cal.settings.seeds.len() < 2 {
        s.push_str("- note: one seed gives no sample-to-sample scatter; noise is the measured uncertainty only\n");
    }
}

/// The baseline's gap, where it lies, and with nothing named what the data could not see.
fn baseline_section(s: &mut String, cal: &Calibration) {
    let m = &cal.measured;
    s.push_str("\n## Baseline gap\n\n");
    curve_table(s, cal.baseline_gap(), cal);
    if !m.compression.is_empty() {
        s.push_str("Where (Δφ > 0: the simulated sample is denser at that pressure, i.e. the model is too soft):\n\n");
        where_table(s, cal.baseline_gap());
    }
    if nothing_named(cal) {
        s.push_str(
            "## What these data could not have seen\n\nNo effect was named. That does not show \
             the model is right: the table below gives, per effect, the smallest change these \
             data would have shown at 95%. A change inside those limits passes as noise.\n\n",
        );
        if let Some(first) = cal.rounds.first() {
            detection_rows(s, &first.detection);
        }
    }
}

/// The applied effects and the gap they leave.
fn result_section(s: &mut String, cal: &Calibration) {
    s.push_str("## Result\n\n");
    let named = cal.named();
    if cal.applied.is_empty() {
        s.push_str("No effect was applied; the corrected config equals the base config.\n");
    } else {
        for (effect, factor) in &cal.applied {
            let _ = writeln!(
                s,
                "- {} ({}, `{}`) x{}: {}{}",
                effect.name(),
                effect.kind().name(),
                effect.key(),
                fmt_factor(*factor),
                effect.describe_value(&cal.base, *factor),
                if named.contains(effect) {
                    ""
                } else {
                    " (tied with others, see above)"
                }
            );
        }
        let before = cal.baseline_gap();
        let after = cal.final_gap();
        let _ = writeln!(
            s,
            "\nchi2 {:.2} → {:.2}; normalised gap shrank by {:.0}%; RMS gap of the curves beyond \
             noise at the baseline shrank by: {}.",
            before.chi2,
            after.chi2,
            100.0 * gap_shrink(before, &after),
            describe_curve_shrinks(before, &after)
        );
        for (b, a) in before.curves.iter().zip(&after.curves) {
            let _ = writeln!(
                s,
                "- {}: RMS gap {:.4} → {:.4} ({:.0}% smaller)",
                b.name,
                b.rms,
                a.rms,
                100.0 * (1.0 - a.rms / b.rms)
            );
        }
    }
}

/// No effect was applied: the data were within noise or nothing explained them.
fn nothing_named(cal: &Calibration) -> bool {
    cal.applied.is_empty()
}

pub const PLAN_FILE: &str = "plan.md";

/// The plan's report: the system, the data's curves and noise, and the detection limits.
pub fn plan_markdown(plan: &super::workflow::Plan, measured: &str, config_path: &Path) -> String {
    let c = &plan.base;
    let mut s = String::from("# Calibration plan\n\n");
    let _ = writeln!(s, "- planned data: `{measured}`");
    let _ = writeln!(s, "- base config: `{}`", config_path.display());
    let _ = writeln!(
        s,
        "- simulations: {} RBD monomers per sample, seeds {:?}, wall at {} m/s, dt {} ns; {} runs\n",
        c.sample.monomers,
        plan.settings.seeds,
        c.experiment.wall_speed_m_s,
        c.integration.dt_ns,
        plan.runs
    );
    s.push_str(
        "The smallest change of each effect these data would show at 95%, from the baseline \
         and a screen of every effect at the upper end of its range, mirrored below 1 (the \
         measured φ values do not enter, only the pressures, the uncertainties and which \
         curves there are):\n\n",
    );
    detection_rows(&mut s, &plan.detection);
    s.push_str("Noise per curve at the baseline:\n\n| curve | RMS noise |\n|---|---|\n");
    for curve in &plan.baseline.curves {
        let _ = writeln!(s, "| {} | {:.4} |", curve.name, curve.noise);
    }
    s
}

/// Writes `plan.md` into `out`.
pub fn write_plan(
    plan: &super::workflow::Plan,
    out: &Path,
    measured: &str,
    config_path: &Path,
) -> Result<PathBuf, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let path = out.join(PLAN_FILE);
    write_atomic(&path, plan_markdown(plan, measured, config_path).as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

/// The wall speed the compressions ran at: the config's, or, where some curve's measured speed
/// differs from it, each curve's own (a dynamic curve is simulated at its measured speed).
fn wall_speeds_text(m: &MeasuredSet, config_speed: f64) -> String {
    let differs = |v: f64| (v - config_speed).abs() > 1e-9 * v;
    if !m
        .compression
        .iter()
        .any(|c| c.wall_speed.is_some_and(differs))
    {
        return format!("{config_speed} m/s");
    }
    let each: Vec<String> = m
        .compression
        .iter()
        .map(|c| {
            format!(
                "{} m/s for {}",
                c.wall_speed.unwrap_or(config_speed),
                c.name
            )
        })
        .collect();
    format!("each curve's measured speed ({})", each.join(", "))
}

/// How the calibration searched and what its runs cost.
fn search_text(cal: &Calibration) -> String {
    let n = cal.settings.seeds.len();
    let k = match cal.settings.screen_seeds {
        0 => n,
        k => k.min(n),
    };
    let screen = if cal.settings.screen_monomers != 0
        && cal.settings.screen_monomers != cal.base.sample.monomers
    {
        format!(
            "a first screen on {} monomers (the fit's samples have {}) that only drops the \
             effects that cannot come near the best there; the others screened again and \
             fitted at full size on the first {k} of the {n} seeds, as differences from the \
             current model on the same samples; baseline and every kept correction on all {n}",
            cal.settings.screen_monomers, cal.base.sample.monomers
        )
    } else if k == n {
        format!("screen and 1-D fits on all {n} seed(s)")
    } else {
        format!(
            "screen and 1-D fits on the first {k} of the {n} seeds, as differences from the \
             current model on the same samples (common random numbers); baseline and every \
             kept correction on all {n}"
        )
    };
    format!(
        "{screen}; each effect screened at {}; effects that cannot come near the best {}{}{}; \
         {} compressions{} and {} sticking runs requested",
        match cal.settings.both_ends {
            true => "both ends of its range",
            false => "the upper end of its range only",
        },
        if cal.settings.prune {
            "dropped after the screen"
        } else {
            "kept"
        },
        match cal.settings.pairs {
            true => "; pairs of effects fitted jointly, those the decision rests on simulated",
            false => "; single effects only",
        },
        match cal.settings.revisit {
            true => "; applied effects revisited with the others in",
            false => "",
        },
        cal.cost.compressions,
        match cal.cost.screen_size_compressions {
            0 => String::new(),
            k => format!(" ({k} of them on the smaller screen's samples)"),
        },
        cal.cost.sticking,
    )
}

#[cfg(test)]
mod tests;
