//! Every claim of Seizinger et al. (2012) in the order of its Sect. 5, each at the sample
//! size it rests on and, where it differs, with the check that says why (`why`).

use super::analysis::{reference, Family, SpeedResult};
use super::claims_curves::{curve_claim, one_mpa_claim, quasi_static_pm_claim, uni_size_claim};
use super::claims_dynamic as dynamic;
use super::laws::speed_laws;
use super::report::Analysed;
use super::verdicts::{sig, Claim};
use super::why;
use super::{CALIBRATED, UNMODIFIED};

fn headline<'a>(a: &'a Analysed, variant: &str) -> Option<&'a Family> {
    a.families
        .iter()
        .filter(|f| f.variant == variant)
        .max_by_key(|f| f.monomers)
}

fn seeds_condition(f: &Family, a: &Analysed, seeds: usize) -> String {
    let planned = a.study.seeds.len();
    format!("ours: {} monomers, {seeds} of {planned} seeds", f.monomers)
}

/// Our conditions for a claim resting on all speeds of `f` (the most seeds any speed has).
fn conditions(f: &Family, a: &Analysed) -> String {
    let seeds = f.speeds.iter().map(|s| s.seeds.len()).max().unwrap_or(0);
    seeds_condition(f, a, seeds)
}

fn study<'a>(all: &'a [Analysed], name: &str) -> Option<&'a Analysed> {
    all.iter().find(|a| a.study.name == name)
}

fn slowest(f: &Family) -> Option<&SpeedResult> {
    f.speeds.iter().min_by(|a, b| a.speed.total_cmp(&b.speed))
}

/// The row at the size of `f` within study `a`.
fn sized(c: Claim, f: &Family, a: &Analysed) -> Claim {
    c.at_size(f.monomers, a.study.paper_monomers)
}

/// The quasi-static p_m of the calibrated model at each stored size, at the speed `v`.
fn pm_by_size(a: &Analysed, v: f64) -> String {
    let parts: Vec<String> = a
        .families
        .iter()
        .filter(|f| f.variant == CALIBRATED.name)
        .filter_map(|f| {
            let s = f.speeds.iter().find(|s| s.speed == v)?;
            let e = s.fixed.as_ref()?;
            Some(format!(
                "{}: {} kPa",
                f.monomers,
                sig(e.mean_fit.params.p_m / 1e3)
            ))
        })
        .collect();
    format!(
        "Eq. 14's v → 0 limit is Güttler's 16.7 kPa; ours by size {} against the paper's \
         {} (size)",
        parts.join(", "),
        a.study.paper_monomers
    )
}

/// The quasi-static and unidirectional claims against the laboratory curves.
fn curve_claims(out: &mut Vec<Claim>, a: &Analysed, omni: bool) {
    let (ref_name, refc) = reference(a.study.kind);
    let (soft, agree, cap, paper_cm_s) = if omni {
        (
            "Quasi-static omni, unmodified model: softer than Güttler at low pressure",
            "Quasi-static omni, calibrated model: agrees with Güttler below 100 kPa",
            vec![1e2, 1e3, 1e4, 1e5],
            1.0,
        )
    } else {
        (
            "Unidirectional, unmodified model: softer than Blum & Schräpler",
            "Unidirectional, calibrated model: agrees with Blum & Schräpler below 10⁴ Pa",
            vec![1e2, 1e3, 1e4],
            5.0,
        )
    };
    for (claim, variant, too_soft) in [
        (soft, UNMODIFIED.name, true),
        (agree, CALIBRATED.name, false),
    ] {
        let f = headline(a, variant);
        let s = f.and_then(slowest);
        let cm_s = s.map_or(a.study.speeds[0], |s| s.speed) * 100.0;
        let paper = format!(
            "{ref_name}; the paper at {paper_cm_s} cm/s, paper-size samples, 6 seeds; ours at \
             {cm_s} cm/s"
        );
        let mut c = curve_claim(claim, &paper, s, (ref_name, &refc), &cap, too_soft);
        if let Some(f) = f {
            c.paper += &format!("; {}", conditions(f, a));
            c = sized(c, f, a).because(|| {
                format!(
                    "φ(P) against {ref_name} at the listed pressures (pressure at fixed φ); \
                     {} monomers against the paper's {} (size)",
                    f.monomers, a.study.paper_monomers
                )
            });
        }
        out.push(c);
    }
    let calibrated = headline(a, CALIBRATED.name);
    let Some(f) = calibrated else { return };
    let s = slowest(f);
    if omni {
        let c = one_mpa_claim(s, &conditions(f, a));
        out.push(sized(c, f, a).because(|| {
            format!(
                "the seed-mean curve's φ at 1 MPa; {} monomers against the paper's {} (size)",
                f.monomers, a.study.paper_monomers
            )
        }));
        let c = quasi_static_pm_claim(s, &conditions(f, a));
        let v = s.map_or(0.0, |s| s.speed);
        out.push(sized(c, f, a).because(|| pm_by_size(a, v)));
    } else {
        let unmodified: Vec<&Family> = a
            .families
            .iter()
            .filter(|f| f.variant == UNMODIFIED.name)
            .collect();
        let paper = "φ above Blum & Schräpler above 10 kPa, more so for larger samples (Sect. 5.3)";
        out.push(uni_size_claim(&unmodified, &refc, paper));
    }
}

fn dynamic_claims(out: &mut Vec<Claim>, a: &Analysed) {
    let Some(f) = headline(a, CALIBRATED.name) else {
        return;
    };
    let cond = format!("calibrated model; {}", conditions(f, a));
    let at_speed = |seeds: usize| format!("calibrated model; {}", seeds_condition(f, a, seeds));
    let mut rows = vec![
        dynamic::regimes_claim(f),
        dynamic::front_ratio_claim(f),
        dynamic::front_speed_claim(f),
        dynamic::plateau_claim(f, &why::per_speed),
    ];
    rows.extend(dynamic::per_speed_claims(f, &at_speed, &why::per_speed));
    let laws = speed_laws(f);
    rows.extend(
        dynamic::dynamic_law_claims(&laws, &cond)
            .into_iter()
            .map(|c| c.because(|| why::law(f))),
    );
    out.extend(rows.into_iter().map(|c| sized(c, f, a)));
}

/// The slow study's claims, each explained where it differs by the same readings at the
/// dynamic study's size (both ran 1 m/s).
fn slow_claims(out: &mut Vec<Claim>, a: &Analysed, large: Option<&Family>) {
    let Some(f) = headline(a, CALIBRATED.name) else {
        return;
    };
    let cond = format!("calibrated model; {}", conditions(f, a));
    let at_speed = |seeds: usize| format!("calibrated model; {}", seeds_condition(f, a, seeds));
    let size_why = |_: &SpeedResult| why::size(f, large);
    let mut rows = dynamic::per_speed_claims(f, &at_speed, &size_why);
    let laws = speed_laws(f);
    rows.push(dynamic::v_crit_claim(&laws, &cond).because(|| why::size(f, large)));
    out.extend(rows.into_iter().map(|c| sized(c, f, a)));
}

/// The paragraph that reads the dynamic rows together, from the headline family.
pub fn dynamic_summary(all: &[Analysed]) -> Option<String> {
    let a = study(all, "dynamic")?;
    why::summary(headline(a, CALIBRATED.name)?)
}

/// Every claim of the paper, in the order of its Sect. 5.
pub fn claims(all: &[Analysed]) -> Vec<Claim> {
    let mut out = Vec::new();
    if let Some(a) = study(all, "quasi_static") {
        curve_claims(&mut out, a, true);
    }
    if let Some(a) = study(all, "uni") {
        curve_claims(&mut out, a, false);
    }
    let large = study(all, "dynamic").and_then(|a| headline(a, CALIBRATED.name));
    if let Some(a) = study(all, "dynamic") {
        dynamic_claims(&mut out, a);
    }
    if let Some(a) = study(all, "slow_dynamic") {
        slow_claims(&mut out, a, large);
    }
    out
}
