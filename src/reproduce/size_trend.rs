//! The size trend of a slow study: the same model and wall speed at each sample size that
//! finished, so a reader sees how far the verdicts (read at the largest size) could still
//! move with size.

use super::analysis::{phi_at_pressure, Family};
use std::fmt::Write as _;

/// A Markdown table of φ at `pressures` for every size of each model at the slowest speed all
/// its sizes share; empty when no model finished at two sizes.
pub fn size_trend_table(families: &[Family], pressures: &[f64]) -> String {
    let mut rows = String::new();
    let mut variants: Vec<&str> = Vec::new();
    for f in families {
        if !variants.contains(&f.variant.as_str()) {
            variants.push(&f.variant);
        }
    }
    for variant in variants {
        let mut sizes: Vec<&Family> = families.iter().filter(|f| f.variant == variant).collect();
        if sizes.len() < 2 {
            continue;
        }
        sizes.sort_by_key(|f| f.monomers);
        let Some(speed) = shared_slowest_speed(&sizes) else {
            continue;
        };
        for f in sizes {
            let s = f
                .speeds
                .iter()
                .find(|s| s.speed == speed)
                .expect("a shared speed");
            let phis: Vec<String> = pressures
                .iter()
                .map(|&p| {
                    phi_at_pressure(&s.mean_curve, p).map_or("–".into(), |v| format!("{v:.3}"))
                })
                .collect();
            let _ = writeln!(
                rows,
                "| {variant} | {} | {} | {} | {:.3} | {} |",
                f.monomers,
                speed * 100.0,
                s.seeds.len(),
                s.phi0.mean,
                phis.join(" | ")
            );
        }
    }
    if rows.is_empty() {
        return rows;
    }
    let heads: Vec<String> = pressures.iter().map(|p| format!("φ({p:.0e} Pa)")).collect();
    let rules = vec!["---"; pressures.len()].join("|");
    format!(
        "Size trend (seed means at fixed pressure; two samples of one size differ by about \
         0.005 in φ):\n\n| model | monomers | cm/s | seeds | φ₀ | {} |\n|---|---|---|---|---|{rules}|\n{rows}\n",
        heads.join(" | ")
    )
}

/// The slowest wall speed at which every one of `sizes` finished.
fn shared_slowest_speed(sizes: &[&Family]) -> Option<f64> {
    sizes[0]
        .speeds
        .iter()
        .map(|s| s.speed)
        .filter(|v| sizes.iter().all(|f| f.speeds.iter().any(|s| s.speed == *v)))
        .fold(None, |slowest: Option<f64>, v| {
            Some(slowest.map_or(v, |m| m.min(v)))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::ensemble::FixedPhiPoint;
    use crate::reproduce::analysis::SpeedResult;
    use crate::reproduce::fixtures::bare_speed;

    /// A run whose pressure is 10^(10 φ) Pa at every φ of its grid, shifted by `dphi`.
    fn speed(v: f64, seeds: usize, dphi: f64) -> SpeedResult {
        let mean_curve = (0..60)
            .map(|k| {
                let phi = 0.1 + 0.01 * k as f64;
                FixedPhiPoint {
                    phi: phi + dphi,
                    p_mean: 10f64.powf(10.0 * phi),
                    p_sd: 0.0,
                }
            })
            .collect();
        let mut s = bare_speed(v, seeds);
        s.phi0.mean = 0.12 + dphi;
        s.mean_curve = mean_curve;
        s
    }

    fn family(variant: &str, monomers: usize, speeds: Vec<SpeedResult>) -> Family {
        Family {
            variant: variant.into(),
            monomers,
            speeds,
        }
    }

    #[test]
    fn each_size_of_a_model_gets_a_row_at_their_slowest_shared_speed() {
        let families = vec![
            family(
                "modified",
                2000,
                vec![speed(0.01, 2, 0.0), speed(0.05, 3, 0.0)],
            ),
            // Not next to its other size: still one model, two rows.
            family("unmodified", 2000, vec![speed(0.05, 1, 0.0)]),
            family("modified", 4000, vec![speed(0.05, 1, 0.02)]),
        ];
        let table = size_trend_table(&families, &[1e2, 1e3]);
        // 10^(10 φ) = 100 Pa at φ = 0.2, 1000 Pa at φ = 0.3; the larger sample 0.02 above.
        assert!(
            table.contains("| modified | 2000 | 5 | 3 | 0.120 | 0.200 | 0.300 |"),
            "{table}"
        );
        assert!(
            table.contains("| modified | 4000 | 5 | 1 | 0.140 | 0.220 | 0.320 |"),
            "{table}"
        );
        assert!(
            !table.contains("| unmodified |"),
            "one size is no trend:\n{table}"
        );
        assert_eq!(table.matches("\n| modified").count(), 2, "{table}");
    }

    #[test]
    fn no_model_at_two_sizes_gives_no_table() {
        let families = vec![family("modified", 2000, vec![speed(0.05, 1, 0.0)])];
        assert_eq!(size_trend_table(&families, &[1e2]), "");
        let apart = vec![
            family("modified", 2000, vec![speed(0.01, 1, 0.0)]),
            family("modified", 4000, vec![speed(0.05, 1, 0.0)]),
        ];
        assert_eq!(size_trend_table(&apart, &[1e2]), "", "no shared speed");
    }
}
