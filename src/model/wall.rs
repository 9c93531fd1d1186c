//! Monomer–wall contact (Sect. 2.2): the wall is a sphere of infinite radius, so R = r and its
//! pointer is the wall normal n_w (pointing from the wall into the domain, towards the monomer).

use glam::DVec3;

/// Overlap δ = r − d with d the signed distance of the centre from the wall plane.
pub fn wall_overlap(x: DVec3, wall_point: DVec3, normal: DVec3, r: f64) -> f64 {
    r - (x - wall_point).dot(normal)
}

/// Rolling displacement ξ = r(n₁ + n_w); the torque is
/// [`super::rolling::rolling_torque`] with R = r.
pub fn wall_rolling_displacement(n1: DVec3, normal: DVec3, r: f64) -> DVec3 {
    (n1 + normal) * r
}

/// Inelastic wall rolling: n_w stays fixed, n₁ is turned back towards −n_w in the plane of n₁ and
/// n_w until |ξ| = ξ_crit exactly (|n₁ + n_w| = 2 sin(θ/2) for the angle θ between n₁ and −n_w).
///
/// The anchor moves with the contact centre, by r Δn₁: the contact area relocates on the monomer
/// and along the wall together, which leaves ζ unchanged, as Δn₁ = Δn₂ leaves ζ unchanged for a
/// monomer pair. (Turning n₁ alone, as printed, converts rolling into sliding displacement and can
/// raise the contact's potential energy, i.e. create energy.) Returns (n₁, anchor).
pub fn wall_rolling_correction(
    n1: DVec3,
    anchor: DVec3,
    normal: DVec3,
    r: f64,
    xi_crit: f64,
) -> Option<(DVec3, DVec3)> {
    let xi = wall_rolling_displacement(n1, normal, r).length();
    if xi <= xi_crit {
        return None;
    }
    let tangential = n1 - normal * n1.dot(normal);
    let t_len = tangential.length();
    // |n₁ + n_w|² = 2 − 2cos θ  →  cos θ = 1 − (ξ_crit/r)²/2.
    let q = xi_crit / r;
    let cos = 1.0 - 0.5 * q * q;
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let dir = if t_len > 0.0 {
        tangential / t_len
    } else {
        normal.any_orthonormal_vector()
    };
    let corrected = -normal * cos + dir * sin;
    Some((corrected, anchor + (corrected - n1) * r))
}

/// Sliding displacement: ζ₀ = x + r n₁ − p (p: where the contact formed), ζ = ζ₀ − (ζ₀·n_w)n_w.
pub fn wall_sliding_displacement(x: DVec3, n1: DVec3, r: f64, p: DVec3, normal: DVec3) -> DVec3 {
    let zeta0 = x + n1 * r - p;
    zeta0 - normal * zeta0.dot(normal)
}

/// Sliding force on the monomer, −k_s ζ (∂ζ/∂x is the tangential projector).
pub fn wall_sliding_force(zeta: DVec3, k_s: f64) -> DVec3 {
    -k_s * zeta
}

/// Inelastic wall sliding: p ← p + (1 − ζ_crit/|ζ|) ζ, exact since ζ is linear in p.
pub fn wall_sliding_correction(p: DVec3, zeta: DVec3, zeta_crit: f64) -> Option<DVec3> {
    let len = zeta.length();
    (len > zeta_crit).then(|| p + zeta * (1.0 - zeta_crit / len))
}
