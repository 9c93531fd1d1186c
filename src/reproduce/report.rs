//! REPRODUCTION.md as a referee would want it: the conditions of the paper beside ours, one
//! table of verdicts, the differences of method that remain, then the measurements of each
//! study. Built from the tier's store alone, so the same store gives the same bytes.

use super::analysis::Family;
use super::claims;
use super::figures;
use super::laws::{speed_laws, Law, Laws};
use super::size_trend;
use super::store::CaseRecord;
use super::verdicts::{self, sig};
use super::{Study, StudyKind, Tier};
use crate::analysis::average::Spread;
use crate::analysis::ensemble::EnsembleFit;
use std::fmt::Write as _;
use std::path::Path;

/// One study with its stored cases analysed.
pub struct Analysed {
    pub study: Study,
    pub cases: Vec<CaseRecord>,
    pub families: Vec<Family>,
}

fn pm_delta(e: &Option<EnsembleFit>) -> String {
    match e {
        None => "no fit | –".into(),
        Some(e) => format!(
            "{} ± {} | {} ± {}",
            sig(e.mean_fit.params.p_m / 1e3),
            sig(e.err.p_m / 1e3),
            sig(e.mean_fit.params.delta),
            sig(e.err.delta)
        ),
    }
}

fn spread_cell(s: &Option<Spread>, scale: f64) -> String {
    match s {
        None => "–".into(),
        Some(s) if s.count > 1 => format!("{} ± {}", sig(s.mean * scale), sig(s.sem * scale)),
        Some(s) => sig(s.mean * scale),
    }
}

fn family_table(s: &mut String, f: &Family, kind: StudyKind) {
    let _ = writeln!(
        s,
        "| v [m/s] | seeds | φ₀ | p_m [kPa] (φ₁, φ₂ held) | Δ | φ₁ free: φ₁ | p_m | Δ | first passage: p_m | Δ | wall-clock [s], all seeds |\n\
         |---|---|---|---|---|---|---|---|---|---|---|"
    );
    for r in &f.speeds {
        let free = match &r.phi1_free {
            None => "– | – | –".into(),
            // A free φ₁ outside (0, φ₂) has left the curve's range: the data do not pin it.
            Some(e)
                if !(e.mean_fit.params.phi1 > 0.0
                    && e.mean_fit.params.phi1 < e.mean_fit.params.phi2) =>
            {
                format!(
                    "not constrained (φ₁ → {}) | – | –",
                    sig(e.mean_fit.params.phi1)
                )
            }
            Some(e) => format!(
                "{} ± {} | {}",
                sig(e.mean_fit.params.phi1),
                sig(e.err.phi1),
                pm_delta(&r.phi1_free)
            ),
        };
        let passage = r.first_passage.as_ref().map_or("– | –".into(), |f| {
            format!("{} | {}", sig(f.params.p_m / 1e3), sig(f.params.delta))
        });
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {} | {free} | {passage} | {:.0} |",
            r.speed,
            r.seeds.len(),
            r.phi0.mean,
            pm_delta(&r.fixed),
            r.wall_clock_s
        );
    }
    let cut: Vec<String> = f
        .speeds
        .iter()
        .filter_map(|r| {
            let t = r.transient?;
            Some(format!(
                "{} m/s from φ = {:.3} (falls {:.2}×)",
                r.speed, t.phi_from, t.drop
            ))
        })
        .collect();
    if !cut.is_empty() {
        let _ = writeln!(
            s,
            "\nEq. 13 fitted from the end of the wall's impact transient, where the seed-mean \
             pressure (running median over ±0.01 in φ) falls by more than {:.0} % after the \
             impact before the plateau: {}. The mean curves and figures keep every point.",
            (crate::analysis::transient::IMPACT_DROP - 1.0) * 100.0,
            cut.join("; ")
        );
    }
    if kind == StudyKind::Dynamic && f.speeds.iter().any(|r| r.regimes.is_some()) {
        s.push_str(
            "\n| v [m/s] | runs with three regimes | critical P [kPa] | plateau P [kPa] | φ at the steep rise | v_p first deviation [m/s] | ÷ v_wall | v_p robust [m/s] | mass balance [m/s] | φ of the layer | momentum flux ρ φ₀ v_wall v_p [kPa] |\n\
             |---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for r in f.speeds.iter().filter(|r| r.regimes.is_some()) {
            let g = r.regimes.expect("filtered");
            let ratio = r
                .front_elapsed
                .map_or("–".into(), |e| sig(e.mean / r.speed));
            // The plateau pressure momentum conservation asks for: the wall sets mass ρ φ₀
            // per volume moving at v_wall, swept up at v_p (SI units, then kPa).
            let density = crate::config::MaterialConfig::default().density_g_cm3 * 1e3;
            let flux = r.front_mass_balance.map_or("–".into(), |m| {
                sig(density * r.phi0.mean * r.speed * m.mean / 1e3)
            });
            let _ = writeln!(
                s,
                "| {} | {} of {} | {} | {} | {} | {} | {ratio} | {} | {} | {} | {flux} |",
                r.speed,
                g.three_regimes,
                g.runs,
                spread_cell(&g.critical_pa, 1e-3),
                spread_cell(&g.plateau_pa, 1e-3),
                spread_cell(&g.phi_steep, 1.0),
                spread_cell(&r.front_elapsed, 1.0),
                spread_cell(&r.front_robust, 1.0),
                spread_cell(&r.front_mass_balance, 1.0),
                spread_cell(&r.layer_phi, 1.0),
            );
        }
    }
    s.push('\n');
}

fn law_line<L>(s: &mut String, name: &str, law: &Law<L>, show: impl Fn(&L, &L) -> String) {
    let text = match law {
        Law::Fitted(f) if f.error_scale > 1.0 => format!(
            "{} (χ²/dof {:.2}; errors × √(χ²/dof) = {:.2})",
            show(&f.law, &f.std_err),
            f.chi2_per_dof,
            f.error_scale
        ),
        Law::Fitted(f) => format!(
            "{} (χ²/dof {:.2})",
            show(&f.law, &f.std_err),
            f.chi2_per_dof
        ),
        Law::Unconstrained(why) => format!("not reported: {why}"),
    };
    let _ = writeln!(s, "- {name}: {text}");
}

fn laws_text(s: &mut String, laws: &Laws) {
    let pm = |l: &crate::analysis::speed_laws::PowerLaw,
              e: &crate::analysis::speed_laws::PowerLaw| {
        format!(
            "a = {} ± {}, b = {} ± {}, c = {} ± {} kPa",
            sig(l.a),
            sig(e.a),
            sig(l.b),
            sig(e.b),
            sig(l.c),
            sig(e.c)
        )
    };
    law_line(
        s,
        "Eq. 15, p_m = a v^b + c (paper: 1.340, 1.93, 0.307)",
        &laws.pm_dynamic,
        pm,
    );
    law_line(
        s,
        "Eq. 16, b = 2 (paper: a = 1.087, c = 0.560)",
        &laws.pm_square,
        pm,
    );
    law_line(
        s,
        "Eq. 17, Δ = (v + a)^b + c (paper: 1.598, −1.997, 0.170)",
        &laws.delta,
        |l, e| {
            format!(
                "a = {} ± {}, b = {} ± {}, c = {} ± {}",
                sig(l.a),
                sig(e.a),
                sig(l.b),
                sig(e.b),
                sig(l.c),
                sig(e.c)
            )
        },
    );
    law_line(
        s,
        "Eq. 14, p_m = a v² + b v + c (paper: 18.296, −33.663, 16.667)",
        &laws.pm_slow,
        |l, e| {
            format!(
                "a = {} ± {}, b = {} ± {}, c = {} ± {} kPa",
                sig(l.a),
                sig(e.a),
                sig(l.b),
                sig(e.b),
                sig(l.c),
                sig(e.c)
            )
        },
    );
    let _ = writeln!(
        s,
        "- v_crit = −b/(2a) of Eq. 14 (paper ≈ 0.9 m/s): {}\n",
        match &laws.v_crit {
            Ok((v, e)) => format!("{} ± {} m/s", sig(*v), sig(*e)),
            Err(why) => format!("not reported: {why}"),
        }
    );
}

fn study_section(s: &mut String, a: &Analysed, figures_dir: &str) {
    let st = &a.study;
    let planned = st.sizes.len() * st.speeds.len() * st.seeds.len() * st.variants.len();
    let _ = writeln!(
        s,
        "## {}\n\nPlanned: sizes {:?} monomers, wall speeds {:?} m/s, seeds 1–{}, models {}: \
         {planned} cases. Finished and stored: {}. Stop at φ = {} or a top-wall pressure of \
         {} MPa, whichever comes first.\n",
        st.title,
        st.sizes,
        st.speeds,
        st.seeds.len(),
        st.variants
            .iter()
            .map(|v| v.label)
            .collect::<Vec<_>>()
            .join(", "),
        a.cases.len(),
        st.phi_stop,
        st.pressure_stop_pa / 1e6,
    );
    let mut machines: Vec<&str> = a.cases.iter().map(|c| c.entry.machine.as_str()).collect();
    machines.sort_unstable();
    machines.dedup();
    if !machines.is_empty() {
        let _ = writeln!(s, "Ran on: {}.\n", machines.join("; "));
    }
    let trend_pressures: &[f64] = match st.kind {
        StudyKind::QuasiStatic => &[1e2, 1e3, 1e4, 1e5],
        StudyKind::Uni => &[1e2, 1e3, 1e4],
        _ => &[],
    };
    if !trend_pressures.is_empty() {
        s.push_str(&size_trend::size_trend_table(&a.families, trend_pressures));
    }
    for f in &a.families {
        let _ = writeln!(s, "### {} model, {} monomers\n", f.variant, f.monomers);
        family_table(s, f, st.kind);
        laws_text(s, &speed_laws(f));
        let _ = writeln!(
            s,
            "![φ(P), {} model, {} monomers]({figures_dir}/{})\n",
            f.variant,
            f.monomers,
            figures::curve_name(st.name, f)
        );
    }
}

/// The conditions table, its "this tier" column filled from the tier's own studies.
fn conditions_table(tier: Tier) -> String {
    let mut text = include_str!("conditions.md").to_string();
    for study in tier.studies() {
        let sizes: Vec<String> = study.sizes.iter().map(|&n| thousands(n)).collect();
        let speeds: Vec<String> = study.speeds.iter().map(|v| format!("{v}")).collect();
        let models: Vec<&str> = study.variants.iter().map(|v| v.label).collect();
        let filled = format!(
            "{} monomers at {} m/s, {} seeds planned; models: {}",
            sizes.join(", "),
            speeds.join(", "),
            study.seeds.len(),
            models.join(" and ")
        );
        text = text.replace(&format!("{{{}}}", study.name), &filled);
    }
    text
}

/// 40000 as "40 000".
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// The whole report.
pub fn markdown(
    tier: Tier,
    all: &[Analysed],
    store_bytes: u64,
    speed_figures: &[String],
) -> String {
    let mut s = format!(
        "# Seizinger et al. (2012) reproduced: {tier} tier\n\n\
         Every number below is computed from the curves and profiles stored beside this file \
         (`<study>/cases/`, {:.1} MB in all); `dustdem reproduce --tier {tier} --out <this \
         directory> --report-only` rebuilds this file and its figures from them, byte for \
         byte. Running the tier again runs only the cases not yet stored and adds them.\n\n",
        store_bytes as f64 / 1e6
    );
    s += &conditions_table(tier);
    let claims = claims::claims(all);
    s += "\n## Verdicts\n\n";
    s += &verdicts::table(&claims);
    let sizes: Vec<String> = all
        .iter()
        .map(|a| format!("{} {}", thousands(a.study.paper_monomers), a.study.name))
        .collect();
    let _ = writeln!(
        s,
        "\nVerdicts per sample size. Only rows at the paper's own size for their study \
         (monomers: {}) count towards the headline; smaller samples read differently (see \
         the size checks in the last column).\n",
        sizes.join(", ")
    );
    s += &verdicts::totals_table(&claims);
    s += "\n";
    if let Some(summary) = claims::dynamic_summary(all) {
        s += &summary;
        s += "\n";
    }
    s += include_str!("differences.md");
    if !speed_figures.is_empty() {
        s += "\n## p_m and Δ against wall speed\n\n";
        for name in speed_figures {
            let _ = writeln!(s, "![{name}](figures/{name})\n");
        }
    }
    for a in all {
        study_section(&mut s, a, "figures");
    }
    s
}

/// Bytes of the stored cases under `dir`.
pub fn store_size(dir: &Path) -> u64 {
    let mut total = 0;
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let path = e.path();
            if path.is_dir() {
                // Run directories (checkpoints, full curves) are not part of the store.
                if path.file_name().is_some_and(|n| n != "runs") {
                    total += store_size(&path);
                }
            } else if path.extension().is_some_and(|x| x == "csv" || x == "toml") {
                total += e.metadata().map_or(0, |m| m.len());
            }
        }
    }
    total
}
