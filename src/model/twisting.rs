//! Twisting: φ = n_c ∫(ω₁ − ω₂)·n_c dt (the scalar integral is stored), U = ½ k_t φ²,
//! M₁ = −k_t φ n_c, M₂ = +k_t φ n_c.

use glam::DVec3;

/// Torque on monomer 1.
pub fn twisting_torque(twist: f64, nc: DVec3, k_t: f64) -> DVec3 {
    -k_t * twist * nc
}

pub fn twisting_potential(twist: f64, k_t: f64) -> f64 {
    0.5 * k_t * twist * twist
}

/// Increment of the twist integral over one step, with the relative angular velocity and the
/// contact normal at mid-step.
pub fn twist_increment(omega_rel: DVec3, nc_mid: DVec3, dt: f64) -> f64 {
    omega_rel.dot(nc_mid) * dt
}

/// Inelastic twisting: |φ| is clamped to φ_crit.
pub fn twisting_correction(twist: f64, phi_crit: f64) -> Option<f64> {
    (twist.abs() > phi_crit).then(|| phi_crit.copysign(twist))
}
