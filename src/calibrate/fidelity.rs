//! Two fidelities of one response: the screen measures an effect on the screen seeds alone
//! (common random numbers), and their response to an effect can differ from the mean over
//! every seed by tens of percent at small sample sizes. Each full prediction the polish makes
//! ran the screen seeds too, so it is also read as a screened one at no cost; per curve, the
//! least-squares gain g in Δfull ≈ g · Δscreened (both changes from the current model) then
//! rescales the screened points the fit still uses. The fit between full and rescaled points
//! meets no kink, and its minimum lands near the mean response's after one full run instead
//! of creeping there pass by pass.

use super::gap::Prediction;

/// The gains trusted: a screened response near zero, or of the other sign, says nothing
/// about the size of the mean one.
pub const GAIN_LIMITS: (f64, f64) = (0.25, 4.0);

/// Per curve of `current`, the gain g minimising Σ (Δfull − g Δscreened)² over the targets of
/// every (full, screened) pair, Δ from `current`; targets a prediction missed (NaN) are left
/// out. 1 for a sticking curve (its screen is already full) and where the screened response
/// is exactly zero; clamped to [`GAIN_LIMITS`].
pub fn gains(current: &[Prediction], pairs: &[(&[Prediction], &[Prediction])]) -> Vec<f64> {
    (0..current.len())
        .map(|c| {
            let (mut num, mut den) = (0.0, 0.0);
            for (full, screened) in pairs {
                let (Some(base), Some(f), Some(s)) =
                    (phi_of(&current[c]), phi_of(&full[c]), phi_of(&screened[c]))
                else {
                    continue;
                };
                for ((b, f), s) in base.iter().zip(f).zip(s) {
                    let (df, ds) = (f - b, s - b);
                    if df.is_finite() && ds.is_finite() {
                        num += df * ds;
                        den += ds * ds;
                    }
                }
            }
            if den > 0.0 {
                (num / den).clamp(GAIN_LIMITS.0, GAIN_LIMITS.1)
            } else {
                1.0
            }
        })
        .collect()
}

/// `screened` with each compression curve's change from `current` scaled by its gain.
pub fn corrected(
    current: &[Prediction],
    screened: &[Prediction],
    gains: &[f64],
) -> Vec<Prediction> {
    current
        .iter()
        .zip(screened)
        .zip(gains)
        .map(|((b, s), &g)| match s {
            Prediction::Compression { .. } => Prediction::blend(b, s, g),
            Prediction::Sticking { .. } => s.clone(),
        })
        .collect()
}

fn phi_of(p: &Prediction) -> Option<&[f64]> {
    match p {
        Prediction::Compression { phi, .. } => Some(phi),
        Prediction::Sticking { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(phi: &[f64]) -> Prediction {
        Prediction::Compression {
            phi: phi.to_vec(),
            scatter: vec![0.01; phi.len()],
            seeds: 3,
        }
    }

    fn sticking(v: f64) -> Prediction {
        Prediction::Sticking {
            velocity: v,
            resolution: 0.01,
        }
    }

    #[test]
    fn the_gain_is_the_least_squares_ratio_of_full_to_screened_change() {
        let current = vec![curve(&[0.20, 0.30, 0.40]), sticking(1.0)];
        // Screened change (0.01, 0.02, NaN-missed); full change (0.013, 0.024, 0.5):
        // g = (0.01·0.013 + 0.02·0.024) / (0.01² + 0.02²) = 0.00061 / 0.0005 = 1.22.
        let screened = vec![curve(&[0.21, 0.32, f64::NAN]), sticking(2.0)];
        let full = vec![curve(&[0.213, 0.324, 0.90]), sticking(3.0)];
        let g = gains(&current, &[(&full, &screened)]);
        assert!((g[0] - 1.22).abs() < 1e-12, "{g:?}");
        assert_eq!(g[1], 1.0, "a sticking curve keeps its screen");
    }

    #[test]
    fn pairs_pool_and_a_silent_or_contrary_screen_is_not_trusted() {
        let current = vec![curve(&[0.2, 0.3])];
        let pair = |s: f64, f: f64| (vec![curve(&[0.2 + f, 0.3])], vec![curve(&[0.2 + s, 0.3])]);
        let g_of = |pairs: &[(Vec<Prediction>, Vec<Prediction>)]| {
            let refs: Vec<(&[Prediction], &[Prediction])> =
                pairs.iter().map(|(f, s)| (&f[..], &s[..])).collect();
            gains(&current, &refs)
        };
        // Two pairs: (0.01 → 0.02) and (0.03 → 0.03): g = (0.0002 + 0.0009) / (0.0001 + 0.0009).
        let g = g_of(&[pair(0.01, 0.02), pair(0.03, 0.03)]);
        assert!((g[0] - 1.1).abs() < 1e-12, "{g:?}");
        assert_eq!(g_of(&[pair(0.0, 0.05)]), vec![1.0]);
        assert_eq!(g_of(&[pair(0.01, 0.2)]), vec![GAIN_LIMITS.1]);
        assert_eq!(g_of(&[pair(0.01, -0.01)]), vec![GAIN_LIMITS.0]);
    }

    #[test]
    fn a_full_point_rescales_the_screened_ends_and_drops_the_screened_interior() {
        use crate::calibrate::effects::Effect;
        use crate::calibrate::grid::Grid;
        let current = vec![curve(&[0.2, 0.3])];
        let mut g = Grid::new(Effect::RollingStiffness);
        g.insert(0.0, current.clone());
        // Screened: +0.01 per ln 2 at both targets (ln 2, ln 4, ln 8).
        for k in 1..=3 {
            let d = 0.01 * k as f64;
            g.insert_screened(k as f64 * 2f64.ln(), vec![curve(&[0.2 + d, 0.3 + d])]);
        }
        // The full run at ln 4 moves twice as far as the screened one did there.
        let full = vec![curve(&[0.24, 0.34])];
        let screened_there = vec![curve(&[0.22, 0.32])];
        g.insert_full(2.0 * 2f64.ln(), full.clone(), screened_there, &current);
        let us: Vec<f64> = g.points.iter().map(|(u, _)| *u).collect();
        assert_eq!(
            us,
            vec![0.0, 2.0 * 2f64.ln(), 3.0 * 2f64.ln()],
            "ln 2 dropped"
        );
        assert_eq!(g.points[1].1, full);
        // The ×8 end: 0.2 + 2 × 0.03.
        match &g.points[2].1[0] {
            Prediction::Compression { phi, .. } => {
                assert!(
                    (phi[0] - 0.26).abs() < 1e-12 && (phi[1] - 0.36).abs() < 1e-12,
                    "{phi:?}"
                )
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(g.screened.len(), 3, "the screened originals are kept");
    }

    #[test]
    fn correction_scales_the_change_of_compression_curves_only() {
        let current = vec![curve(&[0.2, 0.3]), sticking(1.0)];
        let screened = vec![curve(&[0.22, 0.29]), sticking(2.0)];
        let c = corrected(&current, &screened, &[1.5, 3.0]);
        match &c[0] {
            Prediction::Compression { phi, .. } => {
                assert!((phi[0] - 0.23).abs() < 1e-12 && (phi[1] - 0.285).abs() < 1e-12)
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(c[1], sticking(2.0));
    }
}
