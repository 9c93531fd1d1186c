// requires: math
//
// Rolling: ξ = R(n₁ + n₂), U = ½ k_r ξ², M₁ = −R k_r n₁ × ξ, no force.
// Twin of src/model/rolling.rs.

fn rolling_displacement(n1: vec3<f64>, n2: vec3<f64>, reduced_radius: f64) -> vec3<f64> {
    return (n1 + n2) * reduced_radius;
}

// Torque on the monomer whose pointer is `n`; the partner gets the same call with its pointer.
fn rolling_torque(n: vec3<f64>, xi: vec3<f64>, reduced_radius: f64, k_r: f64) -> vec3<f64> {
    return -reduced_radius * k_r * vec_cross(n, xi);
}

fn rolling_potential(xi: vec3<f64>, k_r: f64) -> f64 {
    return 0.5lf * k_r * vec_length_squared(xi);
}

// The Rust twin's Option<(n₁, n₂)>: `changed` is its Some; when false, n1 and n2 are the
// pointers passed in, so a caller may store them either way.
struct RollingCorrection {
    changed: bool,
    n1: vec3<f64>,
    n2: vec3<f64>,
}

// Inelastic rolling: when |ξ| > ξ_crit, pull both pointers back so that |ξ| = ξ_crit exactly,
// shortening s = n₁ + n₂ along itself and rescaling t = n₁ − n₂ to keep both unit vectors.
fn rolling_correction(
    n1: vec3<f64>,
    n2: vec3<f64>,
    reduced_radius: f64,
    xi_crit: f64,
) -> RollingCorrection {
    let s = n1 + n2;
    let xi = vec_length(s) * reduced_radius;
    if xi <= xi_crit {
        return RollingCorrection(false, n1, n2);
    }
    let s_new = s * (xi_crit / xi);
    let t = n1 - n2;
    let t_perp = t - s_new * (vec_dot(t, s_new) / vec_length_squared(s_new));
    let t_new = t_perp * (sqrt(4.0lf - vec_length_squared(s_new)) / vec_length(t_perp));
    return RollingCorrection(true, 0.5lf * (s_new + t_new), 0.5lf * (s_new - t_new));
}
