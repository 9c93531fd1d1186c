// requires: math
//
// Twisting: φ = n_c ∫(ω₁ − ω₂)·n_c dt (the scalar integral is stored), U = ½ k_t φ²,
// M₁ = −k_t φ n_c, M₂ = +k_t φ n_c. Twin of src/model/twisting.rs.

// Torque on monomer 1.
fn twisting_torque(twist: f64, nc: vec3<f64>, k_t: f64) -> vec3<f64> {
    return -k_t * twist * nc;
}

fn twisting_potential(twist: f64, k_t: f64) -> f64 {
    return 0.5lf * k_t * twist * twist;
}

// Increment of the twist integral over one step, with the relative angular velocity and the
// contact normal at mid-step.
fn twist_increment(omega_rel: vec3<f64>, nc_mid: vec3<f64>, dt: f64) -> f64 {
    return vec_dot(omega_rel, nc_mid) * dt;
}

// The Rust twin's Option<f64>: `changed` is its Some; when false, `twist` is the value passed in.
struct TwistingCorrection {
    changed: bool,
    twist: f64,
}

// Inelastic twisting: |φ| is clamped to φ_crit (Rust: φ_crit.copysign(φ); φ ≠ 0 here).
fn twisting_correction(twist: f64, phi_crit: f64) -> TwistingCorrection {
    if abs(twist) > phi_crit {
        return TwistingCorrection(true, select(-abs(phi_crit), abs(phi_crit), twist > 0.0lf));
    }
    return TwistingCorrection(false, twist);
}
