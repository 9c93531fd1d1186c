use super::*;
use crate::analysis::speed_laws::PAPER_PM_DYNAMIC;

/// The paper's Eq. 13 at speed `v` (φ₁, φ₂ of Güttler; p_m and Δ from the paper's laws).
fn paper_curve_at(v: f64) -> Eq13 {
    let p_m_kpa = if v <= 1.0 {
        PAPER_PM_QUASI_STATIC.eval(v)
    } else {
        PAPER_PM_DYNAMIC.eval(v)
    };
    Eq13 {
        phi1: GUETTLER_PHI1,
        phi2: GUETTLER_PHI2,
        p_m: p_m_kpa * 1e3,
        delta: PAPER_DELTA.eval(v),
    }
}

/// A run's curve: 400 rows from 10 Pa to 10 MPa of `eq` shifted by `offset` in φ.
fn curve(eq: &Eq13, offset: f64) -> Vec<(f64, f64)> {
    (0..400)
        .map(|k| {
            let p = 10f64.powf(1.0 + 6.0 * k as f64 / 399.0);
            (p, eq.phi(p) + offset)
        })
        .collect()
}

const SLOW: [f64; 5] = [0.05, 0.25, 0.5, 0.75, 0.9];
const FAST: [f64; 5] = [2.0, 5.0, 10.0, 15.0, 20.0];
/// Seed offsets in φ: mean 0, sample standard deviation 0.004.
const OFFSETS: [f64; 3] = [-0.004, 0.0, 0.004];

fn cases(variant: &str, monomers: usize) -> Vec<CaseData> {
    let mut out = Vec::new();
    for v in SLOW.iter().chain(&FAST) {
        for (seed, offset) in OFFSETS.iter().enumerate() {
            out.push(CaseData {
                name: format!("v{v}_seed{seed}_{variant}_n{monomers}"),
                wall_speed: *v,
                seed: seed as u64,
                variant: variant.into(),
                monomers,
                curve: curve(&paper_curve_at(*v), *offset),
                // 6.8, 7.0, 7.2 m/s on dynamic runs: mean 7, standard error 0.2/√3.
                front_speed: (*v >= DYNAMIC_FROM).then(|| 7.0 + 50.0 * offset),
            });
        }
    }
    out
}

fn close(found: f64, expected: f64, rel: f64, what: &str) {
    assert!(
        ((found - expected) / expected).abs() <= rel,
        "{what}: found {found}, expected {expected} (relative tolerance {rel})"
    );
}

#[test]
fn a_sweep_of_paper_curves_gives_back_the_papers_laws() {
    let families = analyze_cases(&cases("unmodified", 1000));
    assert_eq!(families.len(), 1);
    let f = &families[0];
    assert_eq!(f.speeds.len(), SLOW.len() + FAST.len());
    for g in &f.speeds {
        assert_eq!(g.seeds, 3);
        let truth = paper_curve_at(g.wall_speed);
        // The seed mean is the curve itself up to the grid interpolation (≈ 1e-5 in φ, which
        // moves log p_m by ≈ 1e-4 decades where the curve is flattest): 0.1 % is ten times that.
        let fit = g.fit.fixed.as_ref().expect("fixed fit");
        close(fit.params.p_m, truth.p_m, 1e-3, "p_m");
        close(fit.params.delta, truth.delta, 1e-3, "Δ");
        // The spread of the seeds is their offsets' standard deviation wherever all reached P.
        let full: Vec<_> = g.average.iter().filter(|a| a.count == 3).collect();
        assert!(
            full.len() > 30,
            "{} grid points with every seed",
            full.len()
        );
        for a in full {
            close(a.sd, 0.004, 1e-3, "seed spread");
        }
        if g.wall_speed >= DYNAMIC_FROM {
            let front = g.front.as_ref().expect("front speed");
            close(front.mean, 7.0, 1e-12, "v_p");
            close(front.sem, 0.2 / 3f64.sqrt(), 1e-9, "v_p standard error");
        } else {
            assert!(g.front.is_none(), "no front below {DYNAMIC_FROM} m/s");
        }
    }
    // Laws through exact points: the fit returns the paper's coefficients (limited by the
    // per-speed p_m above, 1e-3, amplified by the quadratic's conditioning).
    let q = f.laws.pm_slow.fitted().expect("quadratic law").law;
    close(q.a, PAPER_PM_QUASI_STATIC.a, 2e-2, "quadratic a");
    close(q.b, PAPER_PM_QUASI_STATIC.b, 2e-2, "quadratic b");
    close(q.c, PAPER_PM_QUASI_STATIC.c, 2e-2, "quadratic c");
    let d = f.laws.pm_dynamic.fitted().expect("power law").law;
    close(d.a, PAPER_PM_DYNAMIC.a, 2e-2, "power law a");
    close(d.b, PAPER_PM_DYNAMIC.b, 2e-2, "power law b");
    let delta = f.laws.delta.fitted().expect("Δ law").law;
    close(delta.a, PAPER_DELTA.a, 5e-2, "Δ law a");
    close(delta.b, PAPER_DELTA.b, 5e-2, "Δ law b");
    close(delta.c, PAPER_DELTA.c, 5e-2, "Δ law c");
}

#[test]
fn variants_and_sizes_are_analysed_apart() {
    let mut all = cases("unmodified", 1000);
    let mut modified = cases("modified", 1000);
    // Move the modified model's curves by +0.02 in φ: its fits must differ, the others not.
    for c in &mut modified {
        for p in &mut c.curve {
            p.1 += 0.02;
        }
    }
    all.extend(modified);
    all.extend(cases("unmodified", 4000).into_iter().take(3));
    let families = analyze_cases(&all);
    let names: Vec<(String, usize, usize)> = families
        .iter()
        .map(|f| (f.variant.clone(), f.monomers, f.speeds.len()))
        .collect();
    assert_eq!(
        names,
        vec![
            ("modified".into(), 1000, 10),
            ("unmodified".into(), 1000, 10),
            ("unmodified".into(), 4000, 1)
        ]
    );
    let rms = |f: &Family| f.speeds[0].rms_vs_guettler.unwrap().0;
    assert!(rms(&families[0]) > rms(&families[1]) + 0.01);
}

#[test]
fn the_rms_against_guettler_is_the_offset_of_a_shifted_copy() {
    let points: Vec<(f64, f64)> = curve(&GUETTLER_2009_OMNI, 0.013);
    let (rms, n) = rms_against(&points, &GUETTLER_2009_OMNI, COMPARE_RANGE).unwrap();
    close(rms, 0.013, 1e-9, "RMS");
    // 400 rows over 6 decades, of which 3 decades are compared: 199 or 200 rows.
    assert!((199..=201).contains(&n), "{n} points");
    assert!(rms_against(&points, &GUETTLER_2009_OMNI, (1e8, 1e9)).is_none());
}

#[test]
fn the_report_puts_each_speed_beside_the_papers_values() {
    let families = analyze_cases(&cases("unmodified", 1000));
    let text = markdown(&families, &["v1_seed9_base_n10 (failed)".into()]);
    assert!(text.contains("## unmodified model, 1000 monomers"));
    assert!(text.contains("Not analysed (not finished): v1_seed9_base_n10 (failed)"));
    // One table row per speed, with the paper's p_m at that speed.
    for v in SLOW.iter().chain(&FAST) {
        let paper = if *v <= 1.0 {
            PAPER_PM_QUASI_STATIC.eval(*v)
        } else {
            PAPER_PM_DYNAMIC.eval(*v)
        };
        let row = format!("| {v} | 3 |");
        let line = text
            .lines()
            .find(|l| l.starts_with(&row))
            .unwrap_or_else(|| panic!("no row for {v} m/s"));
        assert!(line.contains(&format!("{paper:.3}")), "{line}");
    }
    assert!(text.contains("6.98 ± 0.16"));
}
