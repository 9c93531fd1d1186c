//! One round's section of the calibration report: every effect fitted alone, the pairs, what
//! the screen dropped, the decision and its evidence, and the re-simulated gap of what was
//! applied.

use super::report::gap_shrink;
use super::report_tables::*;
use super::workflow::{describe_decision, Calibration, Round};
use std::fmt::Write as _;

/// Round `k`; `nothing_named_yet`: the first round of a calibration that named nothing, whose
/// detection limits the report gave already.
pub(super) fn round_section(
    s: &mut String,
    cal: &Calibration,
    k: usize,
    round: &Round,
    nothing_named_yet: bool,
) {
    let _ = writeln!(s, "## Round {}\n", k + 1);
    fits_table(s, cal, k, round);
    pairs_table(s, round);
    pruned_text(s, cal, round);
    if let Some(single) = &round.single {
        single_observable_text(s, single);
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
    held_out_table(s, round);
    let _ = writeln!(s, "**Decision:** {}.\n", describe_decision(&round.decision));
    discrimination_text(s, round);
    if let Some(effect) = round.decision.chosen() {
        if let Some(f) = round.fits.iter().find(|f| f.effect == effect) {
            chosen_text(s, f, &round.fits, &round_base(cal, k));
        }
    }
    detection_table(s, round, nothing_named_yet);
    applied_text(s, cal, k, round);
    if round.decision.is_undetermined() {
        s.push_str("The corrected config uses the nominally best of the tied explanations; treat it as one of several equally good ones.\n\n");
    }
}

/// Every effect fitted alone: factor, interval, χ², share explained, the ends of its range.
fn fits_table(s: &mut String, cal: &Calibration, k: usize, round: &Round) {
    if round.fits.is_empty() {
        return;
    }
    s.push_str(
        "Each effect fitted alone (factor on the base value; interval: chi2 within +1; \
         explained: share of the baseline chi2 removed; confidence: relative weight \
         exp(−chi2/2) among the effects; ends: chi2 at the ends of the plausible \
         range, – where the search did not go below factor 1).\n\n\
         | effect | kind | factor | interval | value | chi2 | explained | confidence | chi2 at range ends | simulated factors |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    let current = round_base(cal, k);
    for f in &round.fits {
        let _ = writeln!(
            s,
            "| {} | {} | {}{} | {} – {} | {} | {:.2} | {:.1}% | {:.3} | {} / {:.1} | {} |",
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
            lower_end_text(f.chi2_at_range_ends.0),
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

/// The effects the screen dropped, and on what ground.
fn pruned_text(s: &mut String, cal: &Calibration, round: &Round) {
    if round.pruned.is_empty() {
        return;
    }
    let _ = writeln!(
        s,
        "Not widened or refined after the screen ({}): {}.\n",
        if cal.settings.both_ends {
            "their fit through the runs on both sides of factor 1 stayed beyond Δχ² = 2 \
             of the best effect, with χ² not falling at an end that could be widened"
        } else {
            "no scaling of a screened response, up to ×64 either way, came within \
             Δχ² = 2 of the best effect"
        },
        round
            .pruned
            .iter()
            .map(|e| e.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
}

/// What the round applied (with its pair partner) and the re-simulated gap.
fn applied_text(s: &mut String, cal: &Calibration, k: usize, round: &Round) {
    let (Some((effect, factor)), Some(after)) = (round.applied, &round.gap_after) else {
        return;
    };
    let partner = round.applied_partner.map_or(String::new(), |(e, f)| {
        format!(
            " and {} x{} ({})",
            e.name(),
            fmt_factor(f),
            e.describe_value(&round_base(cal, k), f)
        )
    });
    let _ = writeln!(
        s,
        "Re-simulated with {} x{} ({}){partner}: chi2 {:.2} → {:.2}; normalised gap \
         shrank by {:.0}%{}.\n",
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
    curve_table(s, after, cal);
}

/// χ² at the lower range end, or "–" where the search never went below factor 1.
fn lower_end_text(chi2: f64) -> String {
    if chi2.is_nan() {
        "–".into()
    } else {
        format!("{chi2:.1}")
    }
}
