// requires: math
//
// Monomer–wall contact (Sect. 2.2): the wall is a sphere of infinite radius, so R = r and its
// pointer is the wall normal n_w (pointing from the wall into the domain, towards the monomer).
// Twin of src/model/wall.rs.

// Overlap δ = r − d with d the signed distance of the centre from the wall plane.
fn wall_overlap(x: vec3<f64>, wall_point: vec3<f64>, normal: vec3<f64>, r: f64) -> f64 {
    return r - vec_dot(x - wall_point, normal);
}

// Rolling displacement ξ = r(n₁ + n_w); the torque is rolling_torque with R = r.
fn wall_rolling_displacement(n1: vec3<f64>, normal: vec3<f64>, r: f64) -> vec3<f64> {
    return (n1 + normal) * r;
}

// The Rust twin's Option<(n₁, anchor)>: `changed` is its Some; when false, n1 and anchor are
// the values passed in.
struct WallRollingCorrection {
    changed: bool,
    n1: vec3<f64>,
    anchor: vec3<f64>,
}

// Inelastic wall rolling: n_w stays fixed, n₁ is turned back towards −n_w in the plane of n₁
// and n_w until |ξ| = ξ_crit exactly. A pointer exactly along −n_w (no plane) takes glam's
// any_orthonormal_vector direction, as in Rust. The anchor moves with the contact centre, by
// r Δn₁, which leaves ζ unchanged (turning n₁ alone could create energy).
fn wall_rolling_correction(
    n1: vec3<f64>,
    anchor: vec3<f64>,
    normal: vec3<f64>,
    r: f64,
    xi_crit: f64,
) -> WallRollingCorrection {
    let xi = vec_length(wall_rolling_displacement(n1, normal, r));
    if xi <= xi_crit {
        return WallRollingCorrection(false, n1, anchor);
    }
    let tangential = n1 - normal * vec_dot(n1, normal);
    let t_len = vec_length(tangential);
    // |n₁ + n_w|² = 2 − 2cos θ  →  cos θ = 1 − (ξ_crit/r)²/2.
    let q = xi_crit / r;
    let cos_theta = 1.0lf - 0.5lf * q * q;
    let sin_theta = sqrt(max(1.0lf - cos_theta * cos_theta, 0.0lf));
    var dir: vec3<f64>;
    if t_len > 0.0lf {
        dir = tangential / t_len;
    } else {
        dir = any_orthonormal_vector(normal);
    }
    let corrected = -normal * cos_theta + dir * sin_theta;
    return WallRollingCorrection(true, corrected, anchor + (corrected - n1) * r);
}

// Sliding displacement: ζ₀ = x + r n₁ − p (p: where the contact formed), ζ = ζ₀ − (ζ₀·n_w)n_w.
fn wall_sliding_displacement(
    x: vec3<f64>,
    n1: vec3<f64>,
    r: f64,
    p: vec3<f64>,
    normal: vec3<f64>,
) -> vec3<f64> {
    let zeta0 = x + n1 * r - p;
    return zeta0 - normal * vec_dot(zeta0, normal);
}

// Sliding force on the monomer, −k_s ζ (∂ζ/∂x is the tangential projector).
fn wall_sliding_force(zeta: vec3<f64>, k_s: f64) -> vec3<f64> {
    return -k_s * zeta;
}

// The Rust twin's Option<p>: `changed` is its Some; when false, p is the point passed in.
struct WallSlidingCorrection {
    changed: bool,
    p: vec3<f64>,
}

// Inelastic wall sliding: p ← p + (1 − ζ_crit/|ζ|) ζ, exact since ζ is linear in p.
fn wall_sliding_correction(p: vec3<f64>, zeta: vec3<f64>, zeta_crit: f64) -> WallSlidingCorrection {
    let len = vec_length(zeta);
    if len > zeta_crit {
        return WallSlidingCorrection(true, p + zeta * (1.0lf - zeta_crit / len));
    }
    return WallSlidingCorrection(false, p);
}
