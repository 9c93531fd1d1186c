//! Sliding: ζ = r₁n₁ − r₂n₂ − ((r₁n₁ − r₂n₂)·n_c) n_c, U = ½ k_s ζ²,
//! F₁ = −k_s ζ ((r₂n₂ − r₁n₁)·n_c)/|x₁ − x₂|, M₁ = −r₁ k_s n₁ × ζ, M₂ = +r₂ k_s n₂ × ζ.

use glam::DVec3;

pub fn sliding_displacement(n1: DVec3, n2: DVec3, nc: DVec3, r1: f64, r2: f64) -> DVec3 {
    let p = n1 * r1 - n2 * r2;
    p - nc * p.dot(nc)
}

/// Force on monomer 1 (monomer 2 gets the opposite); `distance` = |x₁ − x₂|.
pub fn sliding_force(
    zeta: DVec3,
    n1: DVec3,
    n2: DVec3,
    nc: DVec3,
    r1: f64,
    r2: f64,
    distance: f64,
    k_s: f64,
) -> DVec3 {
    -k_s * zeta * ((n2 * r2 - n1 * r1).dot(nc) / distance)
}

/// Torque on a monomer of radius `r` with pointer `n`; pass `sign` = +1 for monomer 1 and −1
/// for monomer 2 (ζ enters the two with opposite signs).
pub fn sliding_torque(n: DVec3, zeta: DVec3, r: f64, k_s: f64, sign: f64) -> DVec3 {
    -sign * r * k_s * n.cross(zeta)
}

pub fn sliding_potential(zeta: DVec3, k_s: f64) -> f64 {
    0.5 * k_s * zeta.length_squared()
}

/// Inelastic sliding: when |ζ| > ζ_crit, Δn₁ = −Δζ/(2r₁), Δn₂ = +Δζ/(2r₂) with
/// Δζ = ζ(1 − ζ_crit/|ζ|), pointers renormalised. Renormalising leaves a second-order excess, so
/// the step is repeated (quadratic convergence) until |ζ| = ζ_crit to rounding.
pub fn sliding_correction(
    n1: DVec3,
    n2: DVec3,
    nc: DVec3,
    r1: f64,
    r2: f64,
    zeta_crit: f64,
) -> Option<(DVec3, DVec3)> {
    let mut zeta = sliding_displacement(n1, n2, nc, r1, r2);
    if zeta.length() <= zeta_crit {
        return None;
    }
    let (mut a, mut b) = (n1, n2);
    for _ in 0..6 {
        let len = zeta.length();
        if len <= zeta_crit * (1.0 + 1e-13) {
            break;
        }
        let dz = zeta * (1.0 - zeta_crit / len);
        a = (a - dz / (2.0 * r1)).normalize();
        b = (b + dz / (2.0 * r2)).normalize();
        zeta = sliding_displacement(a, b, nc, r1, r2);
    }
    Some((a, b))
}
