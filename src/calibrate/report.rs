//! What a calibration writes: `report.md` (the gap, where it is, every effect's fit, the
//! decision), `calibration.png` and one SVG per compression curve (measured vs baseline vs
//! corrected), and `corrected.toml` (the config with the named effects applied).

use super::attribution::{Decision, DetectionLimit, EffectFit, PREDICTION_LIMIT};
use super::effects::Effect;
use super::figures::plot_panels;
use super::gap::{chi2_quantile_95, CurveGap, Gap};
use super::workflow::{describe_decision, limit_text, Calibration, Round};
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

fn fmt_factor(f: f64) -> String {
    if (0.01..1000.0).contains(&f) {
        format!("{f:.3}")
    } else {
        format!("{f:.3e}")
    }
}

fn curve_table(s: &mut String, gap: &Gap, cal: &Calibration) {
    s.push_str("| curve | points covered | RMS gap | RMS noise | chi2 | verdict |\n|---|---|---|---|---|---|\n");
    let n_comp = cal.measured.compression.len();
    for (k, c) in gap.curves.iter().enumerate() {
        let unit = if k < n_comp { "" } else { " m/s" };
        let _ = writeln!(
            s,
            "| {} | {}/{} | {:.4}{unit} | {:.4}{unit} | {:.2} | {} |",
            c.name,
            c.covered,
            c.residual.len(),
            c.rms,
            c.noise,
            c.chi2,
            verdict_text(c, k >= n_comp)
        );
    }
    let _ = writeln!(
        s,
        "\nTotal chi2 = {:.2} (one degree of freedom per curve); the 95% noise threshold is {:.2}: \
         the gap is **{}**.\n",
        gap.chi2,
        gap.threshold,
        if gap.within_noise() {
            "within noise"
        } else {
            "beyond noise"
        }
    );
}

fn verdict_text(c: &CurveGap, sticking: bool) -> String {
    use super::gap::Verdict;
    if !sticking {
        return c.verdict.text().to_string();
    }
    match c.verdict {
        Verdict::WithinNoise => "within noise".into(),
        Verdict::TooSoft => "sticks only below the measured speed (too little loss)".into(),
        Verdict::TooStiff => "sticks above the measured speed (too much loss)".into(),
        Verdict::Mixed => "differs".into(),
    }
}

fn where_table(s: &mut String, gap: &Gap) {
    s.push_str("| curve | pressure band [Pa] | mean Δφ (sim − meas) | 1σ | verdict |\n|---|---|---|---|---|\n");
    for c in &gap.curves {
        for b in &c.bands {
            let _ = writeln!(
                s,
                "| {} | {:.2e} – {:.2e} | {:+.4} | {:.4} | {} |",
                c.name,
                b.p_lo,
                b.p_hi,
                b.mean,
                b.sigma,
                b.verdict.text()
            );
        }
    }
    s.push('\n');
}

/// The Markdown report.
pub fn markdown(cal: &Calibration, measured: &str, config_path: &Path) -> String {
    let m = &cal.measured;
    let c = &cal.base;
    let mut s = String::from("# Calibration report\n\n");
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
        "- simulations: {} RBD monomers per sample, seeds {:?}, wall at {} m/s, dt {} ns; {} runs",
        c.sample.monomers,
        cal.settings.seeds,
        c.experiment.wall_speed_m_s,
        c.integration.dt_ns,
        cal.runs
    );
    for curve in &m.compression {
        if let Some(v) = curve.wall_speed {
            if (v - c.experiment.wall_speed_m_s).abs() > 1e-9 * v {
                let _ = writeln!(
                    s,
                    "- note: {} was measured at {v} m/s, simulated at {} m/s; compression \
                     curves depend on the wall speed",
                    curve.name, c.experiment.wall_speed_m_s
                );
            }
        }
    }
    if cal.settings.seeds.len() < 2 {
        s.push_str("- note: one seed gives no sample-to-sample scatter; noise is the measured uncertainty only\n");
    }
    s.push_str("\n## Baseline gap\n\n");
    curve_table(&mut s, cal.baseline_gap(), cal);
    if !m.compression.is_empty() {
        s.push_str("Where (Δφ > 0: the simulated sample is denser at that pressure, i.e. the model is too soft):\n\n");
        where_table(&mut s, cal.baseline_gap());
    }
    if nothing_named(cal) {
        s.push_str(
            "## What these data could not have seen\n\nNo effect was named. That does not show \
             the model is right: the table below gives, per effect, the smallest change these \
             data would have shown at 95%. A change inside those limits passes as noise.\n\n",
        );
        if let Some(first) = cal.rounds.first() {
            detection_rows(&mut s, &first.detection);
        }
    }
    for (k, round) in cal.rounds.iter().enumerate() {
        let _ = writeln!(s, "## Round {}\n", k + 1);
        if !round.fits.is_empty() {
            s.push_str(
                "Each effect fitted alone (factor on the base value; interval: chi2 within +1; \
                 explained: share of the baseline chi2 removed; confidence: relative weight \
                 exp(−chi2/2) among the effects; ends: chi2 at the ends of the plausible range).\n\n\
                 | effect | kind | factor | interval | value | chi2 | explained | confidence | chi2 at range ends | simulated factors |\n\
                 |---|---|---|---|---|---|---|---|---|---|\n",
            );
            let current = round_base(cal, k);
            for f in &round.fits {
                let _ = writeln!(
                    s,
                    "| {} | {} | {}{} | {} – {} | {} | {:.2} | {:.1}% | {:.3} | {:.1} / {:.1} | {} |",
                    f.effect.name(),
                    f.effect.kind().name(),
                    match &f.bound {
                        None => String::new(),
                        Some(b) => (if b.upper { "≥ " } else { "≤ " }).to_string(),
                    },
                    fmt_factor(f.factor),
                    fmt_factor(f.interval.0),
                    fmt_factor(f.interval.1),
                    f.effect.describe_value(&current, f.factor),
                    f.chi2,
                    100.0 * f.explained,
                    f.confidence,
                    f.chi2_at_range_ends.0,
                    f.chi2_at_range_ends.1,
                    f.grid_factors
                        .iter()
                        .map(|&x| fmt_factor(x))
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
            s.push('\n');
        }
        if let Some(single) = &round.single {
            single_observable_text(&mut s, single);
        }
        if let Some(outside) = &round.outside {
            let _ = writeln!(
                s,
                "**The cause may lie outside the library:** {}. Candidates the model itself \
                 suggests: {}. Confidences count each as one equally good explanation.\n",
                outside.signs.join("; "),
                outside.candidates.join("; ")
            );
        }
        held_out_table(&mut s, round);
        let _ = writeln!(s, "**Decision:** {}.\n", describe_decision(&round.decision));
        if let Some(effect) = round.decision.chosen() {
            if let Some(f) = round.fits.iter().find(|f| f.effect == effect) {
                chosen_text(&mut s, f, &round.fits, &round_base(cal, k));
            }
        }
        detection_table(&mut s, round, k == 0 && nothing_named(cal));
        if let (Some((effect, factor)), Some(after)) = (round.applied, &round.gap_after) {
            let _ = writeln!(
                s,
                "Re-simulated with {} x{} ({}): chi2 {:.2} → {:.2}; normalised gap shrank by \
                 {:.0}%{}.\n",
                effect.name(),
                fmt_factor(factor),
                effect.describe_value(&round_base(cal, k), factor),
                round.gap_before.chi2,
                after.chi2,
                100.0 * gap_shrink(&round.gap_before, after),
                if round.rejected {
                    " — not kept, it did not lower the gap"
                } else {
                    ""
                }
            );
            curve_table(&mut s, after, cal);
        }
        if let Decision::Undetermined(_) = round.decision {
            s.push_str("The corrected config uses the nominally best of the tied effects; treat it as one of several equally good explanations.\n\n");
        }
    }
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
    let _ = writeln!(
        s,
        "\nCorrected config: `{CORRECTED_FILE}`.\n\n![measured, baseline and corrected]({PLOT_FILE})"
    );
    s
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
         and a screen of every effect at the ends of its range (the measured φ values do not \
         enter, only the pressures, the uncertainties and which curves there are):\n\n",
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

fn detection_rows(s: &mut String, limits: &[DetectionLimit]) {
    s.push_str(
        "| effect | shown below | shown above | with 4× the samples | with the measured σ halved | noise from the simulated samples |\n\
         |---|---|---|---|---|---|\n",
    );
    for d in limits {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} / {} | {} / {} | {:.0}% |",
            d.effect.name(),
            limit_text(d.lower, d.searched.0),
            limit_text(d.upper, d.searched.1),
            limit_text(d.lower_4x_samples, d.searched.0),
            limit_text(d.upper_4x_samples, d.searched.1),
            limit_text(d.lower_half_sigma, d.searched.0),
            limit_text(d.upper_half_sigma, d.searched.1),
            100.0 * d.simulated_share
        );
    }
    s.push_str(
        "\nA factor is shown when the model against data made with it would pass the 95% \
         noise threshold of chi2 (noise at its expected value); found on the screened points, \
         linear in ln factor. To lower a limit: more samples per curve (or more monomers per \
         sample, about as much per factor) where the simulated samples carry the noise, a \
         tighter measurement where it does, or another kind of curve (each curve counts as one \
         degree of freedom, so more points on the same curve do not help).\n\n",
    );
}

fn detection_table(s: &mut String, round: &Round, already_shown: bool) {
    if round.detection.is_empty() || already_shown {
        return;
    }
    s.push_str("Detection limits of these data (smallest factor each way shown at 95%):\n\n");
    detection_rows(s, &round.detection);
}

fn single_observable_text(s: &mut String, single: &super::attribution::SingleObservable) {
    let names = |v: &[Effect]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|e| e.name()).collect::<Vec<_>>().join(", ")
        }
    };
    let _ = writeln!(
        s,
        "**The signal rests on one observable:** only {} is beyond noise. Whatever moves it \
         explains these data as well: in the library, {} (within their searched ranges); not in \
         the library, {}. Confidences count each of the latter as one equally good explanation.\n",
        single.curve,
        names(&single.library),
        single.outside.join(", ")
    );
}

fn held_out_table(s: &mut String, round: &Round) {
    let fits: Vec<&EffectFit> = round
        .fits
        .iter()
        .filter(|f| !f.held_out.is_empty())
        .take(3)
        .collect();
    if fits.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "Leave one curve out: each of the best fits refitted without one curve, and that \
         curve's lowest chi2 over the factors the other curves allow (their chi2 within 3.84 of \
         its minimum; predicted: below {PREDICTION_LIMIT}, the 99% limit of one degree).\n\n\
         | effect | left out | factor without it (allowed) | chi2 of the left-out curve | predicted |\n|---|---|---|---|---|"
    );
    for f in fits {
        for h in &f.held_out {
            let _ = writeln!(
                s,
                "| {} | {} | {} ({} – {}) | {:.2} | {} |",
                f.effect.name(),
                h.curve,
                fmt_factor(h.factor),
                fmt_factor(h.allowed.0),
                fmt_factor(h.allowed.1),
                h.chi2,
                if !h.constrained {
                    "not judged: the other curves do not pin the factor"
                } else if h.predicted {
                    "yes"
                } else {
                    "**no**"
                }
            );
        }
        let fails = f.failed_predictions();
        if !fails.is_empty() {
            let fitted: Vec<&str> = f
                .held_out
                .iter()
                .filter(|h| h.predicted && h.constrained)
                .map(|h| h.curve.as_str())
                .collect();
            let _ = writeln!(
                s,
                "| {} | fits {}, does not predict {} | | | |",
                f.effect.name(),
                if fitted.is_empty() {
                    "the curves jointly".to_string()
                } else {
                    fitted.join(", ")
                },
                fails.join(", ")
            );
        }
    }
    s.push('\n');
}

/// The chosen effect's value, whether it is a bound (and why the search stopped), and for
/// the damping which form was chosen.
fn chosen_text(s: &mut String, f: &EffectFit, fits: &[EffectFit], base: &crate::config::Config) {
    if let Some(b) = &f.bound {
        let _ = writeln!(
            s,
            "The fit of {} lands on the end of the searched range: the data ask for {} x{} \
             ({}), a bound, not a value. {}\n",
            f.effect.name(),
            if b.upper { "at least" } else { "at most" },
            fmt_factor(f.factor),
            f.effect.describe_value(base, f.factor),
            match b.limit {
                Some(why) => format!("The search stopped at the effect's limit: {why}."),
                None => "The search stopped after its widenings; widen further with more rounds \
                         of the calibration or a base config nearer the bound."
                    .into(),
            }
        );
    }
    if f.effect.family() == Effect::NormalDamping {
        let other = fits
            .iter()
            .find(|g| g.effect.family() == Effect::NormalDamping && g.effect != f.effect);
        let _ = writeln!(
            s,
            "Damping: chose the {} form, {}{}.\n",
            if f.effect.identity_at_one() {
                "config's own"
            } else {
                "other"
            },
            f.effect.describe_value(base, f.factor),
            match other {
                Some(g) => format!(
                    " (chi2 {:.2}; the {} form fits to chi2 {:.2} with {})",
                    f.chi2,
                    if g.effect.identity_at_one() {
                        "config's own"
                    } else {
                        "other"
                    },
                    g.chi2,
                    g.effect.describe_value(base, g.factor)
                ),
                None => String::new(),
            }
        );
    }
}

/// The config a round started from: the base with the earlier rounds' effects applied.
fn round_base(cal: &Calibration, round: usize) -> crate::config::Config {
    let mut c = cal.base.clone();
    for (effect, factor) in cal.applied.iter().take(round) {
        c = effect.apply(&c, *factor);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::gap::Verdict;

    fn curve(name: &str, rms: f64, chi2: f64) -> CurveGap {
        CurveGap {
            name: name.into(),
            residual: vec![rms],
            sigma: vec![0.01],
            rms,
            noise: 0.01,
            chi2,
            covered: 1,
            bands: Vec::new(),
            verdict: Verdict::WithinNoise,
        }
    }

    fn gap(curves: Vec<CurveGap>) -> Gap {
        let chi2 = curves.iter().map(|c| c.chi2).sum();
        Gap {
            threshold: chi2_quantile_95(curves.len()),
            curves,
            chi2,
        }
    }

    #[test]
    fn only_curves_beyond_noise_at_the_baseline_are_judged_by_their_shrink() {
        let before = gap(vec![curve("omni", 0.08, 9.5), curve("uni", 0.012, 1.5)]);
        let after = gap(vec![curve("omni", 0.01, 0.7), curve("uni", 0.012, 1.5)]);
        let shrinks = curve_shrinks(&before, &after);
        assert_eq!(shrinks.len(), 1);
        assert_eq!(shrinks[0].name, "omni");
        assert!((shrinks[0].shrink() - 0.875).abs() < 1e-12);
        assert_eq!(describe_curve_shrinks(&before, &after), "omni 88%");
        // The data set's normalised shrink counts the control curve's noise too.
        assert!((gap_shrink(&before, &after) - (1.0 - (2.2f64 / 11.0).sqrt())).abs() < 1e-12);
        let quiet = gap(vec![curve("uni", 0.012, 1.5)]);
        assert_eq!(
            describe_curve_shrinks(&quiet, &quiet),
            "no curve was beyond noise"
        );
    }
}
