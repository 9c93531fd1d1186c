//! JKR normal interaction (Eqs. 1–3 of Seizinger et al. (2012)), in the dimensionless contact
//! radius x = a/a₀ and overlap d = δ/δ₀.

/// Smallest contact radius on the stable branch, x_min = 6^(−2/3): δ(x) has its minimum there.
pub const X_MIN: f64 = 0.302_853_432_138_69;
/// Square root of [`X_MIN`], 6^(−1/3).
pub const Y_MIN: f64 = 0.550_321_208_149_104_5;
/// Overlap ratio at the end of the stable branch: δ(x_min)/δ₀ = −(9/16)^(1/3).
pub const D_MIN: f64 = -0.825_481_812_223_656_7;
/// Contact radius at zero overlap, where a new contact forms: x₀ = (2/3)^(2/3).
pub const X_AT_ZERO_OVERLAP: f64 = 0.763_142_828_368_887_9;

/// δ/δ₀ = 3x² − 2√x.
pub fn jkr_overlap_ratio(x: f64) -> f64 {
    3.0 * x * x - 2.0 * x.sqrt()
}

/// Inverse of [`jkr_overlap_ratio`] on the stable branch x ≥ x_min.
///
/// With y = √x the relation is the quartic g(y) = 3y⁴ − 2y = d. g is convex and increasing for
/// y > y_min, so Newton's method started to the right of the root converges monotonically
/// (quadratically away from the turning point, still reliably next to it). Overlaps below the
/// branch end return x_min. Uses only + − × ÷ √ so the GPU twin matches bit for bit in f64.
pub fn jkr_contact_radius_ratio(d: f64) -> f64 {
    if d <= D_MIN {
        return X_MIN;
    }
    let mut y = newton_start(d);
    for _ in 0..100 {
        let y3 = y * y * y;
        let g = 3.0 * y3 * y - 2.0 * y - d;
        let slope = 12.0 * y3 - 2.0;
        let step = g / slope;
        let next = (y - step).max(Y_MIN);
        if next >= y {
            break;
        }
        y = next;
        if step <= 1e-15 * y {
            break;
        }
    }
    y * y
}

/// A start right of the root of g(y) = 3y⁴ − 2y = d, close to it where contacts usually are
/// (d near 1, g(1) = 1), so Newton needs 3–5 iterations there instead of 7.
///
/// With h = y − 1, g = 1 + 10h + 18h² + 12h³ + 3h⁴. Any y with g(y) ≥ d lies right of the
/// root (g increases), and each candidate below is such a y, so their minimum is too:
/// - y ≥ 1 with y⁴ ≥ d + 2, since then g(y) ≥ y⁴ ≥ d + 2 > d;
/// - for d ≥ 1, the root of 1 + 10h + 18h² = d (h ≥ 0), as the dropped terms are ≥ 0 there;
/// - for d < 1, the root of the tangent 1 + 10h = d, as g is convex (g'' = 36y² > 0); it is
///   above y_min for every d > d_min (1 + (d_min − 1)/10 = 0.817).
pub fn newton_start(d: f64) -> f64 {
    let far = (d + 2.0).sqrt().sqrt().max(1.0);
    let near = if d >= 1.0 {
        1.0 + ((100.0 + 72.0 * (d - 1.0)).sqrt() - 10.0) / 36.0
    } else {
        1.0 + (d - 1.0) / 10.0
    };
    far.min(near)
}

/// Normal force F = 4F_c (x³ − x^(3/2)), positive when repulsive [dyn].
pub fn jkr_force(x: f64, f_c: f64) -> f64 {
    4.0 * f_c * (x * x * x - x * x.sqrt())
}

/// ∫F dδ along the branch up to x, in units of F_c δ₀, up to a constant.
pub fn potential_shape(x: f64) -> f64 {
    let x2 = x * x;
    4.0 * (1.2 * x2 * x2 * x - 2.0 * x2 * x * x.sqrt() + 0.5 * x2)
}

/// Normal potential energy U(x) = ∫₀^δ F dδ' [erg], zero where a contact forms (δ = 0).
///
/// It is negative in the bound state (U(a₀) < 0) and positive when stretched past δ = 0; at the
/// break (−δ_c) U is the energy the JKR loop has taken from the relative motion.
pub fn jkr_potential(x: f64, f_c: f64, delta0: f64) -> f64 {
    f_c * delta0 * (potential_shape(x) - potential_shape(X_AT_ZERO_OVERLAP))
}

/// Normal potential at any overlap ratio, continued linearly below the branch end with the force
/// at x_min: the energy the contact holds at the step it breaks.
pub fn jkr_potential_at_overlap(d: f64, f_c: f64, delta0: f64) -> f64 {
    jkr_potential_at_overlap_with(jkr_contact_radius_ratio(d), d, f_c, delta0)
}

/// [`jkr_potential_at_overlap`] where the contact radius ratio x of the overlap ratio d is
/// known (`jkr_contact_radius_ratio(d)`, as the force evaluated it): the same bits without a
/// second inversion.
pub fn jkr_potential_at_overlap_with(x: f64, d: f64, f_c: f64, delta0: f64) -> f64 {
    let u = jkr_potential(x, f_c, delta0);
    if d < D_MIN {
        u + jkr_force(X_MIN, f_c) * (d - D_MIN) * delta0
    } else {
        u
    }
}

#[cfg(test)]
mod newton_start_tests {
    use super::*;

    /// The start lies right of the root (g(start) ≥ d, in exact arithmetic; here with a margin
    /// of rounding) and on the stable branch, over the whole range of overlaps, and within 1 %
    /// of the root near d = 1.
    #[test]
    fn the_start_is_right_of_the_root_and_close_to_it_near_equilibrium() {
        let g = |y: f64| 3.0 * y * y * y * y - 2.0 * y;
        let mut d = D_MIN + 1e-9;
        while d < 1e4 {
            let y0 = newton_start(d);
            assert!(y0 > Y_MIN, "d = {d}: start {y0}");
            assert!(
                g(y0) >= d - 1e-12 * d.abs().max(1.0),
                "d = {d}: g({y0}) = {}",
                g(y0)
            );
            let root = jkr_contact_radius_ratio(d).sqrt();
            assert!(
                y0 >= root - 1e-15,
                "d = {d}: start {y0} left of the root {root}"
            );
            if (0.5..=2.0).contains(&d) {
                assert!(y0 - root <= 0.01 * root, "d = {d}: start {y0}, root {root}");
            }
            d += 1e-3 * d.abs().max(1e-2);
        }
        assert_eq!(newton_start(1.0), 1.0);
    }
}
