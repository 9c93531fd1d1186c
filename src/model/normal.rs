//! JKR normal interaction (Eqs. 1–3 of Seizinger et al. (2012)), in the dimensionless contact radius
//! x = a/a₀ and overlap d = δ/δ₀.

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
    // For y ≥ 1: g(y) ≥ y⁴ ≥ d + 2 > d, so this start lies right of the root.
    let mut y = (d + 2.0).sqrt().sqrt().max(1.0);
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
    let u = jkr_potential(jkr_contact_radius_ratio(d), f_c, delta0);
    if d < D_MIN {
        u + jkr_force(X_MIN, f_c) * (d - D_MIN) * delta0
    } else {
        u
    }
}
