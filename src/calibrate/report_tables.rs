//! The tables of `report.md`: per-curve gaps and where they lie, detection limits, held-out
//! predictions, and the text that explains the chosen effect.

use super::attribution::{DetectionLimit, EffectFit, PREDICTION_LIMIT};
use super::effects::Effect;
use super::gap::{CurveGap, Gap};
use super::workflow::{describe_decision, Calibration, Round};
use std::fmt::Write as _;

pub(super) fn fmt_factor(f: f64) -> String {
    if (0.01..1000.0).contains(&f) {
        format!("{f:.3}")
    } else {
        format!("{f:.3e}")
    }
}

pub(super) fn curve_table(s: &mut String, gap: &Gap, cal: &Calibration) {
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

pub(super) fn verdict_text(c: &CurveGap, sticking: bool) -> String {
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

pub(super) fn where_table(s: &mut String, gap: &Gap) {
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

pub(super) fn detection_rows(s: &mut String, limits: &[DetectionLimit]) {
    s.push_str(
        "| effect | shown below | shown above | with 4× the samples | with the measured σ halved | noise from the simulated samples |\n\
         |---|---|---|---|---|---|\n",
    );
    for d in limits {
        let t = d.texts();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} / {} | {} / {} | {:.0}% |",
            d.effect.name(),
            t[0],
            t[1],
            t[2],
            t[3],
            t[4],
            t[5],
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

pub(super) fn detection_table(s: &mut String, round: &Round, already_shown: bool) {
    if round.detection.is_empty() || already_shown {
        return;
    }
    s.push_str("Detection limits of these data (smallest factor each way shown at 95%):\n\n");
    detection_rows(s, &round.detection);
    if let Some((monomers, dropped)) = &round.size_screened {
        let names: Vec<&str> = dropped.iter().map(|e| e.name()).collect();
        let _ = writeln!(
            s,
            "\nThe limits of {} come from the {monomers}-monomer screen that dropped them, \
             not from the fit's sample size; every other limit is at the fit's size.\n",
            names.join(", ")
        );
    }
}

pub(super) fn single_observable_text(
    s: &mut String,
    single: &super::attribution::SingleObservable,
) {
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

pub(super) fn held_out_table(s: &mut String, round: &Round) {
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
pub(super) fn chosen_text(
    s: &mut String,
    f: &EffectFit,
    fits: &[EffectFit],
    base: &crate::config::Config,
) {
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
pub(super) fn round_base(cal: &Calibration, round: usize) -> crate::config::Config {
    let mut c = cal.base.clone();
    // A round that chose a pair applied two effects.
    let earlier: usize = cal.rounds[..round.min(cal.rounds.len())]
        .iter()
        .filter(|r| r.applied.is_some() && !r.rejected)
        .map(|r| 1 + usize::from(r.applied_partner.is_some()))
        .sum();
    for (effect, factor) in cal.applied.iter().take(earlier) {
        c = effect.apply(&c, *factor);
    }
    c
}

/// The revisits (`--revisit`): each applied effect searched for again with the others in.
pub(super) fn revisits_section(s: &mut String, cal: &Calibration) {
    if cal.revisits.is_empty() {
        return;
    }
    s.push_str(
        "## Revisits\n\nEach round fitted its effect with the later ones missing. Each applied \
         effect but the last was searched for again (a full round) on the base model with every \
         other applied effect in; a correction that fits better than the model as it stood \
         takes its place (then the last effect is searched for again too).\n\n\
         | revisited | with | decision | best fits: factor (interval), chi2 | chi2 re-simulated | chi2 before | outcome |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for r in &cal.revisits {
        let (effect, factor) = r.was;
        let others: Vec<String> = r
            .with
            .iter()
            .map(|(e, f)| format!("{} x{}", e.name(), fmt_factor(*f)))
            .collect();
        let fits: Vec<String> = r
            .round
            .fits
            .iter()
            .take(3)
            .map(|f| {
                format!(
                    "{} x{} ({} – {}), {:.2}",
                    f.effect.name(),
                    fmt_factor(f.factor),
                    fmt_factor(f.interval.0),
                    fmt_factor(f.interval.1),
                    f.chi2
                )
            })
            .collect();
        let after = r.round.gap_after.as_ref().map(|g| format!("{:.2}", g.chi2));
        let outcome = match (r.replaced, r.round.applied) {
            (true, Some((e, f))) => format!("replaced by {} x{}", e.name(), fmt_factor(f)),
            _ => "kept".to_string(),
        };
        let _ = writeln!(
            s,
            "| {} x{} | {} | {} | {} | {} | {:.2} | {} |",
            effect.name(),
            fmt_factor(factor),
            others.join(", "),
            describe_decision(&r.round.decision),
            fits.join("; "),
            after.unwrap_or_else(|| "–".into()),
            r.chi2_before,
            outcome
        );
    }
    s.push('\n');
}

/// The pairs fitted jointly that need both their effects, best first; a sentence when none
/// does. Nothing when no pair was fitted (the gap was within noise).
pub(super) fn pairs_table(s: &mut String, round: &Round) {
    if round.pairs.is_empty() {
        return;
    }
    // A pinned fit at the free fit's factors is the same model: listed once.
    let mut needed: Vec<&super::pairs::PairFit> = Vec::new();
    for p in round.pairs.iter().filter(|p| p.needs_both()) {
        if !needed
            .iter()
            .any(|q| q.effects == p.effects && q.factors == p.factors)
        {
            needed.push(p);
        }
    }
    if needed.is_empty() {
        let _ = writeln!(
            s,
            "Pairs of effects fitted jointly ({} pairs, from the simulated responses added to \
             the current model): none fits better than each of its effects alone by more than \
             χ²₉₅(1) = {:.2}, so no pair needs both its effects.\n",
            round.pairs.len(),
            super::gap::chi2_quantile_95(1)
        );
        return;
    }
    let _ = writeln!(
        s,
        "Pairs of effects fitted jointly (the simulated responses added to the current model; \
         listed when the pair beats each of its effects alone by more than χ²₉₅(1) = {:.2}; \
         \"bound\": the factor sits on the end of the simulated range):\n\n\
         | pair | factors [interval] | χ² | χ² simulated | χ² alone |\n|---|---|---|---|---|",
        super::gap::chi2_quantile_95(1)
    );
    for p in needed.iter().take(8) {
        let factor = |k: usize| {
            format!(
                "{}{} [{}, {}]",
                if p.on_bound[k] { "bound " } else { "" },
                fmt_factor(p.factors[k]),
                fmt_factor(p.intervals[k].0),
                fmt_factor(p.intervals[k].1)
            )
        };
        let _ = writeln!(
            s,
            "| {} | {}; {} | {:.2} | {} | {:.2} / {:.2} |",
            p.names(),
            factor(0),
            factor(1),
            p.chi2,
            p.simulated_chi2
                .map_or("–".to_string(), |c| format!("{c:.2}")),
            p.alone[0],
            p.alone[1]
        );
    }
    s.push('\n');
}

/// For an undetermined round: the measurements that would tell its two leading explanations
/// apart, best first, with the χ² separation each gives at the data's noise.
pub(super) fn discrimination_text(s: &mut String, round: &Round) {
    let Some(d) = &round.discrimination else {
        return;
    };
    let _ = writeln!(
        s,
        "**What would tell them apart** ({} or {}; χ² that data made by the first would show \
         against the second, one degree per curve, noise aside; {} runs):\n\n\
         | measurement | χ² separation |\n|---|---|",
        d.between[0], d.between[1], d.runs
    );
    for p in &d.proposals {
        let _ = writeln!(s, "| {} | {:.2} |", p.what, p.separation);
    }
    if let Some(best) = d.proposals.first() {
        let q = super::gap::chi2_quantile_95(1);
        let _ = writeln!(
            s,
            "\nProposed: {} ({}).\n",
            best.what,
            if best.separation > q {
                format!("separates them beyond χ²₉₅(1) = {q:.2}")
            } else {
                format!("does not reach χ²₉₅(1) = {q:.2}: more samples or smaller σ needed")
            }
        );
    }
}
