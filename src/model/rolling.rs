//! Rolling: ξ = R(n₁ + n₂), U = ½ k_r ξ², M₁ = −R k_r n₁ × ξ, no force.

use glam::DVec3;

pub fn rolling_displacement(n1: DVec3, n2: DVec3, reduced_radius: f64) -> DVec3 {
    (n1 + n2) * reduced_radius
}

/// Torque on the monomer whose pointer is `n`; the partner gets the same call with its pointer.
pub fn rolling_torque(n: DVec3, xi: DVec3, reduced_radius: f64, k_r: f64) -> DVec3 {
    -reduced_radius * k_r * n.cross(xi)
}

pub fn rolling_potential(xi: DVec3, k_r: f64) -> f64 {
    0.5 * k_r * xi.length_squared()
}

/// Inelastic rolling: when |ξ| > ξ_crit, pull both pointers back so that |ξ| = ξ_crit exactly.
///
/// With s = n₁ + n₂ and t = n₁ − n₂ (t ⊥ s and |s|² + |t|² = 4 for unit pointers), the
/// correction Δn₁ = Δn₂ = −Δξ/(2R) shortens s along itself; rescaling t to √(4 − |s|²) then
/// keeps both pointers unit vectors without the error a renormalisation would bring.
pub fn rolling_correction(
    n1: DVec3,
    n2: DVec3,
    reduced_radius: f64,
    xi_crit: f64,
) -> Option<(DVec3, DVec3)> {
    let s = n1 + n2;
    let xi = s.length() * reduced_radius;
    if xi <= xi_crit {
        return None;
    }
    let s_new = s * (xi_crit / xi);
    let t = n1 - n2;
    let t_perp = t - s_new * (t.dot(s_new) / s_new.length_squared());
    let t_new = t_perp * ((4.0 - s_new.length_squared()).sqrt() / t_perp.length());
    Some((0.5 * (s_new + t_new), 0.5 * (s_new - t_new)))
}
