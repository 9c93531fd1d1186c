// requires: math
//
// Sliding: ζ = r₁n₁ − r₂n₂ − ((r₁n₁ − r₂n₂)·n_c) n_c, U = ½ k_s ζ²,
// F₁ = −k_s ζ ((r₂n₂ − r₁n₁)·n_c)/|x₁ − x₂|, M₁ = −r₁ k_s n₁ × ζ, M₂ = +r₂ k_s n₂ × ζ.
// Twin of src/model/sliding.rs.

fn sliding_displacement(n1: vec3<f64>, n2: vec3<f64>, nc: vec3<f64>, r1: f64, r2: f64) -> vec3<f64> {
    let p = n1 * r1 - n2 * r2;
    return p - nc * vec_dot(p, nc);
}

// Force on monomer 1 (monomer 2 gets the opposite); `distance` = |x₁ − x₂|.
fn sliding_force(
    zeta: vec3<f64>,
    n1: vec3<f64>,
    n2: vec3<f64>,
    nc: vec3<f64>,
    r1: f64,
    r2: f64,
    distance: f64,
    k_s: f64,
) -> vec3<f64> {
    return -k_s * zeta * (vec_dot(n2 * r2 - n1 * r1, nc) / distance);
}

// Torque on a monomer of radius `r` with pointer `n`; `sign` = +1 for monomer 1, −1 for
// monomer 2.
fn sliding_torque(n: vec3<f64>, zeta: vec3<f64>, r: f64, k_s: f64, sign: f64) -> vec3<f64> {
    return -sign * r * k_s * vec_cross(n, zeta);
}

fn sliding_potential(zeta: vec3<f64>, k_s: f64) -> f64 {
    return 0.5lf * k_s * vec_length_squared(zeta);
}

// The Rust twin's Option<(n₁, n₂)>: `changed` is its Some; when false, n1 and n2 are the
// pointers passed in.
struct SlidingCorrection {
    changed: bool,
    n1: vec3<f64>,
    n2: vec3<f64>,
}

// Inelastic sliding: when |ζ| > ζ_crit, Δn₁ = −Δζ/(2r₁), Δn₂ = +Δζ/(2r₂) with
// Δζ = ζ(1 − ζ_crit/|ζ|), pointers renormalised, repeated (at most 6 times, as in Rust) until
// |ζ| = ζ_crit to rounding.
fn sliding_correction(
    n1: vec3<f64>,
    n2: vec3<f64>,
    nc: vec3<f64>,
    r1: f64,
    r2: f64,
    zeta_crit: f64,
) -> SlidingCorrection {
    var zeta = sliding_displacement(n1, n2, nc, r1, r2);
    if vec_length(zeta) <= zeta_crit {
        return SlidingCorrection(false, n1, n2);
    }
    var a = n1;
    var b = n2;
    for (var i = 0u; i < 6u; i++) {
        let len = vec_length(zeta);
        if len <= zeta_crit * (1.0lf + 1e-13lf) {
            break;
        }
        let dz = zeta * (1.0lf - zeta_crit / len);
        a = vec_normalize(a - dz / (2.0lf * r1));
        b = vec_normalize(b + dz / (2.0lf * r2));
        zeta = sliding_displacement(a, b, nc, r1, r2);
    }
    return SlidingCorrection(true, a, b);
}
