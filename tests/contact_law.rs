//! Closed-form checks of the contact law's pure functions.

mod common;

use common::*;
use dustdem::model::normal::*;
use dustdem::model::pointer::rotate_pointer;
use dustdem::model::{rolling, sliding, twisting, wall};
use glam::DVec3;

#[test]
fn branch_constants_are_consistent() {
    assert!((X_MIN - 6f64.powf(-2.0 / 3.0)).abs() < 1e-15);
    assert!((Y_MIN * Y_MIN - X_MIN).abs() < 1e-15);
    assert!((jkr_overlap_ratio(X_MIN) - D_MIN).abs() < 1e-15);
    assert!((D_MIN + (9.0f64 / 16.0).cbrt()).abs() < 1e-15);
    assert!(jkr_overlap_ratio(X_AT_ZERO_OVERLAP).abs() < 1e-15);
    // Equilibrium: zero force at a = a₀, δ = δ₀.
    assert_eq!(jkr_force(1.0, 1.0), 0.0);
    assert_eq!(jkr_overlap_ratio(1.0), 1.0);
}

#[test]
fn contact_radius_inversion_is_accurate_over_the_whole_branch() {
    // From just above the branch end (where dδ/da = 0) to deep compression.
    let mut worst: f64 = 0.0;
    let mut d = D_MIN + 1e-14;
    while d < 1e3 {
        let x = jkr_contact_radius_ratio(d);
        assert!(x >= X_MIN);
        let back = jkr_overlap_ratio(x);
        worst = worst.max((back - d).abs() / d.abs().max(1.0));
        d += (d - D_MIN) * 0.01 + 1e-6;
    }
    assert!(worst < 1e-13, "worst backward error {worst:e}");
    // Below the branch end the contact radius is clamped.
    assert_eq!(jkr_contact_radius_ratio(D_MIN - 0.1), X_MIN);
    // Stable branch, not the inner root: at δ = 0 the answer is x₀, not 0.
    assert!((jkr_contact_radius_ratio(0.0) - X_AT_ZERO_OVERLAP).abs() < 1e-14);
}

#[test]
fn potential_is_the_integral_of_the_force() {
    let (f_c, delta0) = (1.0, 1.0);
    // dU/dδ = F along the branch, checked by central differences in x.
    for &x in &[0.35, 0.5, 0.763, 1.0, 1.7, 3.0] {
        let h = 1e-6;
        let du = jkr_potential(x + h, f_c, delta0) - jkr_potential(x - h, f_c, delta0);
        let dd = jkr_overlap_ratio(x + h) - jkr_overlap_ratio(x - h);
        assert!((du / dd - jkr_force(x, f_c)).abs() < 1e-7, "x = {x}");
    }
    assert!(jkr_potential(X_AT_ZERO_OVERLAP, f_c, delta0).abs() < 1e-15);
    // The JKR loop: 0.772241 F_c δ₀ from formation to the break.
    assert!((jkr_potential(X_MIN, f_c, delta0) - 0.772_241).abs() < 1e-6);
}

fn random_pair_beyond_limits(rng: &mut SplitMix64, spread: f64) -> (DVec3, DVec3) {
    let axis = rng.unit_vector();
    (
        (-axis + rng.unit_vector() * spread).normalize(),
        (axis + rng.unit_vector() * spread).normalize(),
    )
}

#[test]
fn inelastic_corrections_land_exactly_on_the_critical_lengths() {
    let law = undamped();
    let k = law.pair;
    let r = law.radius;
    let mut rng = SplitMix64(3);
    for _ in 0..2000 {
        let spread = 0.5 * rng.unit();
        let (n1, n2) = random_pair_beyond_limits(&mut rng, spread);
        let nc = (-n1 + n2).normalize();
        if let Some((a, b)) = rolling::rolling_correction(n1, n2, k.reduced_radius, k.xi_crit) {
            let xi = rolling::rolling_displacement(a, b, k.reduced_radius).length();
            assert!((xi / k.xi_crit - 1.0).abs() < 1e-9, "rolling {xi:e}");
            assert!((a.length() - 1.0).abs() < 1e-14 && (b.length() - 1.0).abs() < 1e-14);
        }
        if let Some((a, b)) = sliding::sliding_correction(n1, n2, nc, r, r, k.zeta_crit) {
            let zeta = sliding::sliding_displacement(a, b, nc, r, r).length();
            assert!((zeta / k.zeta_crit - 1.0).abs() < 1e-9, "sliding {zeta:e}");
            assert!((a.length() - 1.0).abs() < 1e-14 && (b.length() - 1.0).abs() < 1e-14);
        }
        let twist = (rng.unit() - 0.5) * 0.2;
        if let Some(t) = twisting::twisting_correction(twist, k.phi_crit) {
            assert_eq!(t.abs(), k.phi_crit);
            assert_eq!(t.signum(), twist.signum());
        }
        let normal = rng.unit_vector();
        let n1w = (-normal + rng.unit_vector() * spread).normalize();
        let x = normal * r + rng.unit_vector() * (spread * 1e-6);
        let anchor = x - normal * r;
        if let Some((a, p)) = wall::wall_rolling_correction(n1w, anchor, normal, r, k.xi_crit) {
            let xi = wall::wall_rolling_displacement(a, normal, r).length();
            assert!((xi / k.xi_crit - 1.0).abs() < 1e-9, "wall rolling {xi:e}");
            assert!((a.length() - 1.0).abs() < 1e-14);
            // The sliding displacement is left as it was.
            let before = wall::wall_sliding_displacement(x, n1w, r, anchor, normal);
            let after = wall::wall_sliding_displacement(x, a, r, p, normal);
            assert!((after - before).length() <= 1e-12 * r);
        }
        let zeta = wall::wall_sliding_displacement(x, n1w, r, anchor, normal);
        if let Some(p) = wall::wall_sliding_correction(anchor, zeta, k.zeta_crit) {
            let z = wall::wall_sliding_displacement(x, n1w, r, p, normal).length();
            assert!((z / k.zeta_crit - 1.0).abs() < 1e-9, "wall sliding {z:e}");
        }
    }
    // Below the limits nothing changes.
    let axis = DVec3::X;
    assert!(rolling::rolling_correction(-axis, axis, k.reduced_radius, k.xi_crit).is_none());
    assert!(sliding::sliding_correction(-axis, axis, -axis, r, r, k.zeta_crit).is_none());
}

#[test]
fn pointer_rotation_is_a_rotation() {
    let mut rng = SplitMix64(5);
    for _ in 0..1000 {
        let n = rng.unit_vector();
        let w = rng.unit_vector() * (0.3 * rng.unit());
        let turned = rotate_pointer(n, w);
        assert!((turned.length() - 1.0).abs() < 1e-15);
        // Angle about the axis is |w|; the component along the axis is kept.
        let axis = w.normalize();
        assert!((turned.dot(axis) - n.dot(axis)).abs() < 1e-14);
        let (a, b) = (n - axis * n.dot(axis), turned - axis * turned.dot(axis));
        if a.length() > 1e-3 {
            let angle = a.cross(b).dot(axis).atan2(a.dot(b));
            assert!((angle - w.length()).abs() < 1e-12);
        }
        // Rodrigues' formula with the library's sin and cos: the series (to θ¹¹ and θ¹⁰) is
        // exact to rounding up to |w| = 0.3 (the first dropped terms, θ¹²/13! and θ¹²/14!,
        // are below 1e-16), so the two agree to the rounding of a dozen operations. A wrong
        // coefficient of even the θ¹⁰ term moves the result by ~1e-13 at |w| = 0.3.
        let theta = w.length();
        let exact = n * theta.cos()
            + axis.cross(n) * theta.sin()
            + axis * (axis.dot(n) * (1.0 - theta.cos()));
        assert!(
            (turned - exact).length() < 2e-15,
            "|w| = {theta}: {:e}",
            (turned - exact).length()
        );
    }
}

#[test]
fn tangential_forces_are_gradients_of_their_potentials() {
    // Finite-difference check of F_s and of the three torques against U = ½kξ² + ½kζ² + ½kφ².
    let law = undamped();
    let k = law.pair;
    let r = law.radius;
    let mut rng = SplitMix64(9);
    let axis = rng.unit_vector();
    let n1 = (-axis + rng.unit_vector() * 0.01).normalize();
    let n2 = (axis + rng.unit_vector() * 0.01).normalize();
    let x1 = DVec3::ZERO;
    let x2 = x1 - axis * (2.0 * r - k.delta0);
    let potential = |x1: DVec3, n1: DVec3| {
        let nc = (x1 - x2).normalize();
        rolling::rolling_potential(
            rolling::rolling_displacement(n1, n2, k.reduced_radius),
            k.k_r,
        ) + sliding::sliding_potential(sliding::sliding_displacement(n1, n2, nc, r, r), k.k_s)
    };
    let nc = (x1 - x2).normalize();
    let zeta = sliding::sliding_displacement(n1, n2, nc, r, r);
    let xi = rolling::rolling_displacement(n1, n2, k.reduced_radius);
    let force = sliding::sliding_force(zeta, n1, n2, nc, r, r, (x1 - x2).length(), k.k_s);
    let torque = rolling::rolling_torque(n1, xi, k.reduced_radius, k.k_r)
        + sliding::sliding_torque(n1, zeta, r, k.k_s, 1.0);
    let h = 1e-12;
    let scale_f = force.length();
    let scale_m = torque.length();
    for e in [DVec3::X, DVec3::Y, DVec3::Z] {
        let fd = -(potential(x1 + e * h, n1) - potential(x1 - e * h, n1)) / (2.0 * h);
        assert!(
            (fd - force.dot(e)).abs() < 1e-5 * scale_f,
            "force {fd:e} vs {:e}",
            force.dot(e)
        );
        let a = 1e-7;
        let md = -(potential(x1, rotate_pointer(n1, e * a))
            - potential(x1, rotate_pointer(n1, -e * a)))
            / (2.0 * a);
        assert!(
            (md - torque.dot(e)).abs() < 1e-5 * scale_m,
            "torque {md:e} vs {:e}",
            torque.dot(e)
        );
    }
}

/// Sliding's correction lands on ζ_crit and moves the two pointers against each other, by
/// equal amounts for equal
/// radii: the relative displacement ζ shrinks to ζ_crit while the rolling displacement
/// ξ ∝ n₁ + n₂ stays as it was, up to the second-order change that renormalising the pointers
/// makes (|Δn|² ≲ (ζ/r)², below 1e-2 of |Δζ| for the spreads drawn here). Moving only one
/// pointer (or the two by different amounts) changes ξ by half of Δζ.
#[test]
fn the_sliding_correction_lands_on_zeta_crit_and_leaves_rolling_alone() {
    let law = undamped();
    let k = law.pair;
    let r = law.radius;
    let mut rng = SplitMix64(8);
    let mut checked = 0;
    for _ in 0..2000 {
        let spread = 0.02 * rng.unit();
        let (n1, n2) = random_pair_beyond_limits(&mut rng, spread);
        // A contact normal off the pointers' axis, so that they have a sliding displacement
        // (along n₂ − n₁ itself they have none).
        let nc = ((n2 - n1) + rng.unit_vector() * (4.0 * spread)).normalize();
        if let Some((a, b)) = sliding::sliding_correction(n1, n2, nc, r, r, k.zeta_crit) {
            let xi_change = (rolling::rolling_displacement(a, b, k.reduced_radius)
                - rolling::rolling_displacement(n1, n2, k.reduced_radius))
            .length();
            let zeta_change = (sliding::sliding_displacement(a, b, nc, r, r)
                - sliding::sliding_displacement(n1, n2, nc, r, r))
            .length();
            assert!(
                xi_change <= 1e-2 * zeta_change,
                "ξ moved {xi_change:e} while ζ moved {zeta_change:e}"
            );
            // And it lands on ζ_crit (the loop stops within 1e-13 of it).
            let zeta = sliding::sliding_displacement(a, b, nc, r, r).length();
            assert!((zeta / k.zeta_crit - 1.0).abs() < 1e-9, "sliding {zeta:e}");
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} corrections");
}
