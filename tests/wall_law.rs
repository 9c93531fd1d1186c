//! The monomer–wall law (Seizinger et al. 2012, Sect. 2.2) against expectations written
//! independently of the code: forces and torques as numerical gradients of the wall potentials
//! (constants as docs/physics.md prints them), energy balances of a monomer rolling, sliding and
//! twisting on a wall, and a monomer sliding off a weak side wall.

mod common;

use common::printed::{self, K_T, RADIUS};
use common::*;
use dustdem::backend::cpu::CpuEngine;
use dustdem::material::WallTwisting;
use dustdem::model::{ContactLaw, Damping, ModelOptions, WallFactors};
use dustdem::state::interaction::wall_interaction;
use dustdem::state::{Monomers, Wall, WallContact};
use dustdem::state::{DEFAULT_PAIR_SLOTS, DEFAULT_WALL_SLOTS};
use glam::{DQuat, DVec3};

const WEAK: WallFactors = WallFactors {
    rolling: 1e-3,
    sliding: 1e-3,
    twisting: 1e-3,
};
const MIXED: WallFactors = WallFactors {
    rolling: 0.25,
    sliding: 4.0,
    twisting: 1e-2,
};

fn wall(law: &ContactLaw, point: DVec3, normal: DVec3, factors: WallFactors) -> Wall {
    Wall {
        name: "wall".into(),
        point,
        normal,
        velocity: DVec3::ZERO,
        constants: law.wall_constants(factors),
    }
}

/// Tangential potential of a wall contact, ½k_r|ξ|² + ½k_s|ζ|² + ½k_t φ², with ξ = r(n₁ + n_w),
/// ζ the tangential part of x + r n₁ − p, and the wall's k_t equal to the pair's (Sect. 2.2.4).
fn tangential_potential(x: DVec3, c: &WallContact, w: &Wall, f: WallFactors) -> f64 {
    let n = w.normal;
    let xi = (c.n1 + n) * RADIUS;
    let zeta0 = x + c.n1 * RADIUS - c.anchor;
    let zeta = zeta0 - n * zeta0.dot(n);
    0.5 * printed::k_r_wall() * f.rolling * xi.length_squared()
        + 0.5 * printed::k_s_wall() * f.sliding * zeta.length_squared()
        + 0.5 * K_T * f.twisting * c.twist * c.twist
}

fn overlap(x: DVec3, w: &Wall) -> f64 {
    RADIUS - (x - w.point).dot(w.normal)
}

/// Normal (JKR) potential of a wall contact, zero where it formed.
fn normal_potential(x: DVec3, w: &Wall) -> f64 {
    printed::jkr_potential(overlap(x, w), printed::F_C_WALL, printed::delta0_wall())
}

/// Potential after turning the monomer by `angle` about `axis`: the pointer turns with it and
/// the twist integral grows by angle·(axis·n_w).
fn turned_potential(
    x: DVec3,
    c: &WallContact,
    w: &Wall,
    f: WallFactors,
    axis: DVec3,
    angle: f64,
) -> f64 {
    let turned = WallContact {
        n1: DQuat::from_axis_angle(axis, angle) * c.n1,
        twist: c.twist + angle * axis.dot(w.normal),
        ..*c
    };
    tangential_potential(x, &turned, w, f)
}

#[test]
fn wall_forces_and_torques_are_gradients_of_the_wall_potentials() {
    let law = undamped();
    let mut rng = SplitMix64(5);
    let mut checked = 0;
    for factors in [WallFactors::FULL, WEAK, MIXED] {
        for _ in 0..20 {
            let normal = rng.unit_vector();
            let w = wall(&law, rng.unit_vector() * 1e-4, normal, factors);
            let tangent = normal.any_orthonormal_vector();
            let delta = rng.uniform(-0.8, 3.0) * printed::delta0_wall();
            let x = w.point + normal * (RADIUS - delta) + tangent * rng.uniform(-1e-4, 1e-4);
            // A pointer up to 2e-3 rad off −n_w, an anchor up to 1e-7 cm off the contact centre
            // and a twist up to 0.03 rad: beyond the critical values, as between two corrections.
            let n1 = (-normal + rng.unit_vector() * rng.uniform(0.0, 2e-3)).normalize();
            let c = WallContact {
                wall: 0,
                n1,
                anchor: x + n1 * RADIUS + rng.unit_vector() * rng.uniform(0.0, 1e-7),
                twist: rng.uniform(-0.03, 0.03),
            };
            let (force, damping, torque) = wall_interaction(&law, x, w.velocity, &w, &c);
            assert_eq!(damping, DVec3::ZERO);
            // Normal force: the JKR law written again (bisection inversion).
            let jkr = printed::jkr_force(delta, printed::F_C_WALL, printed::delta0_wall());
            // The printed F_c,wall and a₀,wall carry 5e-6 each, δ₀,wall ∝ a₀² twice that: the
            // force may be off by 5e-6 F + 1e-5 δ dF/dδ ≤ 1e-5 (F_c + k_n|δ|), k_n = 6F_c/5δ₀.
            let k_n = 6.0 * printed::F_C_WALL / (5.0 * printed::delta0_wall());
            let bound = 1e-5 * (printed::F_C_WALL + k_n * delta.abs());
            let off = (force.dot(normal) - jkr).abs();
            assert!(
                off < bound,
                "normal force off by {off:e} dyn (bound {bound:e})"
            );
            // Tangential force: −∂U/∂x by central differences (U is quadratic in x: exact).
            let h = 1e-9;
            let mut gradient = DVec3::ZERO;
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                let up = tangential_potential(x + axis * h, &c, &w, factors);
                let down = tangential_potential(x - axis * h, &c, &w, factors);
                gradient += axis * ((up - down) / (2.0 * h));
            }
            let tangential = force - normal * force.dot(normal);
            let scale = gradient.length().max(1e-3 * printed::F_C_WALL);
            assert!(
                (tangential + gradient).length() < 3e-5 * scale,
                "tangential force {tangential} vs −∇U {:?}",
                -gradient
            );
            // Torque: −∂U/∂θ about each axis (pointer and twist turn with the monomer).
            let theta = 1e-7;
            let mut expected_torque = DVec3::ZERO;
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                let up = turned_potential(x, &c, &w, factors, axis, theta);
                let down = turned_potential(x, &c, &w, factors, axis, -theta);
                expected_torque -= axis * ((up - down) / (2.0 * theta));
            }
            let scale = expected_torque.length();
            assert!(
                (torque - expected_torque).length() < 3e-5 * scale,
                "torque {torque} vs −∂U/∂θ {expected_torque} (factors {factors:?})"
            );
            // The twisting part alone (about n_w): −k_t φ with the pair's k_t.
            let twist_only = WallContact {
                n1: -normal,
                anchor: x - normal * RADIUS,
                ..c
            };
            let (_, _, twist_torque) = wall_interaction(&law, x, w.velocity, &w, &twist_only);
            let expected_twist = -K_T * factors.twisting * c.twist;
            // k_t is printed with 5 digits: half a unit is 2.2e-5 of it.
            assert!(
                (twist_torque.dot(normal) - expected_twist).abs() < 2.3e-5 * expected_twist.abs(),
                "twisting torque {} vs −k_t φ {expected_twist}",
                twist_torque.dot(normal)
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 60);
}

#[test]
fn wall_twisting_stiffness_is_the_pairs_unless_asked_otherwise() {
    // Sect. 2.2.4: k_t,wall = k_t. The option with the wall's own contact radius gives
    // 16/3 G a₀,wall³ = 4 k_t (a₀³ ∝ R², R = r against a wall, r/2 between monomers).
    let law = undamped();
    assert!((law.wall.k_t / K_T - 1.0).abs() < 2.3e-5);
    let options = ModelOptions {
        damping: Damping::None,
        wall_twisting: WallTwisting::WallContactRadius,
        ..ModelOptions::default()
    };
    let own = ContactLaw::new(&dustdem::material::Material::silicate(), &options);
    let g = 5.4e11 / (2.0 * 1.17);
    let expected = 16.0 / 3.0 * g * printed::A0_WALL.powi(3);
    assert!((own.wall.k_t / expected - 1.0).abs() < 3.0 * printed::PRINTED_REL);
    assert!((own.wall.k_t / K_T - 4.0).abs() < 1e-4);
    // Nothing else changes.
    assert_eq!(own.pair, law.pair);
    assert_eq!((own.wall.k_r, own.wall.k_s), (law.wall.k_r, law.wall.k_s));
}

/// Energy of a single monomer with its wall contact, from the state alone: kinetic and
/// rotational (synchronised), the potentials written above, and the dissipation tally.
fn energy(e: &CpuEngine, factors: WallFactors) -> f64 {
    let v = e.synchronized_velocity(0);
    let omega = e.synchronized_angular_velocity(0);
    let x = e.monomers.position[0];
    let mut total = 0.5 * printed::MASS * v.length_squared()
        + 0.5 * printed::moment_of_inertia() * omega.length_squared()
        + e.tally.total();
    for c in e.contacts.walls_of(0) {
        let w = &e.walls[c.wall as usize];
        total += normal_potential(x, w) + tangential_potential(x, c, w, factors);
    }
    total
}

/// A monomer resting on a floor at δ₀,wall, set moving with `v` and spinning with `omega`;
/// returns the largest energy error over `steps` steps relative to the initial kinetic energy,
/// and what the walls channel took.
fn wall_energy_error(factors: WallFactors, v: DVec3, omega: DVec3, steps: u64) -> (f64, f64) {
    let law = undamped();
    let floor = wall(&law, DVec3::ZERO, DVec3::Z, factors);
    let mut m = Monomers::new(vec![DVec3::new(0.0, 0.0, RADIUS - printed::delta0_wall())]);
    m.velocity[0] = v;
    m.angular_velocity[0] = omega;
    let dt = 2e-12;
    let mut e = CpuEngine::new(
        law,
        dt,
        m,
        vec![floor],
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )
    .unwrap();
    assert_eq!(e.contacts.walls_of(0).len(), 1);
    let kinetic = 0.5 * printed::MASS * v.length_squared()
        + 0.5 * printed::moment_of_inertia() * omega.length_squared();
    let e0 = energy(&e, factors);
    let mut worst: f64 = 0.0;
    for _ in 0..steps / 100 {
        e.run(100).unwrap();
        assert_eq!(e.contacts.walls_of(0).len(), 1, "stays on the wall");
        worst = worst.max((energy(&e, factors) - e0).abs());
    }
    (worst / kinetic, e.tally.walls / kinetic)
}

#[test]
fn a_monomer_rolling_sliding_or_twisting_on_a_wall_keeps_its_energy() {
    // Speeds scale with √factor so each motion reaches the same fraction of its critical
    // displacement: the small ones stay elastic, the large ones pass the limits many times.
    let cases = [
        ("rolling", DVec3::new(0.0, -RADIUS, 0.0), DVec3::X, 5e3, 2e6),
        ("sliding", DVec3::X, DVec3::ZERO, 0.5, 300.0),
        ("twisting", DVec3::ZERO, DVec3::Z, 5e3, 2e6),
    ];
    for factors in [WallFactors::FULL, WEAK] {
        for (name, v_unit, omega_unit, elastic, inelastic) in cases {
            let scale = match name {
                "rolling" => factors.rolling,
                "sliding" => factors.sliding,
                _ => factors.twisting,
            }
            .sqrt();
            // One rolling or twisting period (0.25 µs at full strength) or ~40 sliding periods.
            let steps = (2e-7 / scale / 2e-12) as u64;
            for (regime, speed) in [("elastic", elastic), ("inelastic", inelastic)] {
                let s = speed * scale;
                let (error, dissipated) =
                    wall_energy_error(factors, v_unit * s, omega_unit * s, steps);
                eprintln!("{name} {regime} (factors {:.0e}): energy error {error:.2e} of the initial kinetic energy, walls channel {dissipated:.3e}", factors.rolling);
                if regime == "elastic" {
                    assert_eq!(dissipated, 0.0, "{name} stays elastic");
                } else {
                    assert!(
                        dissipated > 0.1,
                        "{name}: the limits are passed: {dissipated}"
                    );
                }
                // Measured: 2e-7 to 2e-6 at full strength; 3e-5 to 1.1e-4 on the weak wall,
                // whose elastic cases carry 1e3 times less kinetic energy (4e-17 erg twisting)
                // while the absolute error (~5e-21 erg, the normal mode's leap-frog error and
                // the printed constants' 6 digits) stays. A missing or doubled torque or force
                // gives errors of order 1. Bound 3e-4.
                assert!(error < 3e-4, "{name} {regime}: {error:e}");
            }
        }
    }
}

/// Kinetic energy lost by a monomer thrown at a wall at `v`; returns (lost, tallied).
fn bounce_off(factors: WallFactors, v: DVec3) -> (f64, f64) {
    bounce_off_moving(undamped(), factors, v, DVec3::ZERO)
}

/// A monomer thrown at `v` relative to a wall that moves at `wall_velocity`. Returns the kinetic
/// energy it lost in the wall's frame and the dissipation tallied.
fn bounce_off_moving(
    law: ContactLaw,
    factors: WallFactors,
    v: DVec3,
    wall_velocity: DVec3,
) -> (f64, f64) {
    let side = Wall {
        velocity: wall_velocity,
        ..wall(&law, DVec3::ZERO, DVec3::X, factors)
    };
    // Starts 0.1 δ₀ clear of the wall, moving towards it.
    let m = {
        let mut m = Monomers::new(vec![DVec3::new(
            RADIUS + 0.1 * printed::delta0_wall(),
            0.0,
            0.0,
        )]);
        m.velocity[0] = v + wall_velocity;
        m
    };
    let dt = 2e-12;
    let mut e = CpuEngine::new(
        law,
        dt,
        m,
        vec![side],
        DEFAULT_PAIR_SLOTS,
        DEFAULT_WALL_SLOTS,
    )
    .unwrap();
    let mut touched = false;
    for _ in 0..2_000_000 {
        e.step().unwrap();
        let on = !e.contacts.walls_of(0).is_empty();
        touched |= on;
        if touched && !on {
            break;
        }
    }
    assert!(
        touched && e.contacts.walls_of(0).is_empty(),
        "left the wall"
    );
    // The monomer is free again, so its stored (half-step) velocity is its velocity.
    let after = 0.5 * printed::MASS * (e.monomers.velocity[0] - wall_velocity).length_squared()
        + 0.5 * printed::moment_of_inertia() * e.monomers.angular_velocity[0].length_squared();
    let before = 0.5 * printed::MASS * v.length_squared();
    (before - after, e.tally.total())
}

#[test]
fn a_monomer_bouncing_off_a_moving_damped_wall_loses_in_the_walls_frame_exactly_the_tallied_energy()
{
    // A wall moving at constant velocity is a static wall seen from its own frame (Galilean
    // invariance), so the kinetic energy lost relative to the wall is what the contact
    // dissipated: the JKR loop and sliding (walls channel, booked with the monomer's velocity
    // relative to the wall when the contact forms and breaks) and the viscoelastic damping.
    // 100 cm/s into the wall, above its damped sticking speed; 300 cm/s along it slides past
    // ζ_crit on the weak side wall; the wall advances at 200 cm/s, like a compressing wall.
    let law = law_with(Damping::Viscoelastic { t_vis: 1.25e-11 });
    let wall_velocity = DVec3::new(200.0, 0.0, 0.0);
    let (lost, tallied) =
        bounce_off_moving(law, WEAK, DVec3::new(-100.0, 300.0, 0.0), wall_velocity);
    let (lost_static, tallied_static) =
        bounce_off_moving(law, WEAK, DVec3::new(-100.0, 300.0, 0.0), DVec3::ZERO);
    let rel = (lost - tallied) / tallied;
    let rel_static = (lost_static - tallied_static) / tallied_static;
    let frames = lost / lost_static - 1.0;
    eprintln!(
        "moving damped wall: lost {lost:.6e} erg, tallied {tallied:.6e} erg ({rel:.2e}); \
         static: lost {lost_static:.6e}, tallied {tallied_static:.6e} ({rel_static:.2e}); \
         loss moving/static - 1 = {frames:.2e}"
    );
    // Measured -7.5e-7 (the leap-frog error of the collision at 2 ps, as in the static cases
    // above); bound 1e-5. Booking the contact's half-step work with the lab velocity instead of
    // the one relative to the wall gives -1.5e-4, with the damping force's sign flipped -6.6e-4.
    assert!(rel.abs() < 1e-5, "{rel:e}");
    assert!(rel_static.abs() < 1e-5, "{rel_static:e}");
    // The frame does not change the physics: the same loss as against a static wall, up to
    // the rounding of positions that now carry the wall's travel (measured 3.7e-13; bound
    // 1e-11). The static case's own balance is the same -7.5e-7.
    assert!(frames.abs() < 1e-11, "{frames:e}");
}

#[test]
fn a_monomer_sliding_off_a_weak_side_wall_loses_exactly_the_tallied_energy() {
    // 20 cm/s into the wall is above its sticking speed (12.3 cm/s from the wall's JKR loop),
    // 300 cm/s along it slides it past ζ_crit on the weak (1e-3) side wall.
    let (lost, tallied) = bounce_off(WEAK, DVec3::new(-20.0, 300.0, 0.0));
    let (lost_head_on, tallied_head_on) = bounce_off(WEAK, DVec3::new(-20.0, 0.0, 0.0));
    let rel = (lost - tallied) / tallied;
    let rel_head_on = (lost_head_on - tallied_head_on) / tallied_head_on;
    eprintln!("sliding off: lost {lost:.6e} erg, tallied {tallied:.6e} erg ({rel:.2e}); head-on: lost {lost_head_on:.6e}, tallied {tallied_head_on:.6e} ({rel_head_on:.2e})");
    assert!(
        tallied > 1.5 * tallied_head_on,
        "sliding dissipates on top of the JKR loop"
    );
    // Measured 1.7e-6 and 4.7e-6 (leap-frog error of the collision at 2 ps); bound 1e-5.
    assert!(rel.abs() < 1e-5);
    assert!(rel_head_on.abs() < 1e-5);
}

#[test]
fn inelastic_wall_rolling_turns_the_pointer_back_in_its_own_plane() {
    use dustdem::model::wall::wall_rolling_correction;
    // A pointer tilted from −n_w towards +x by 0.1 rad (|ξ| = 2r sin(0.05) ≫ ξ_crit) goes back
    // towards −n_w in the x–z plane until |ξ| = ξ_crit; the anchor moves with the contact
    // centre by r Δn₁.
    let normal = DVec3::Z;
    let n1 = DVec3::new(0.1f64.sin(), 0.0, -0.1f64.cos());
    let anchor = DVec3::new(1e-7, 2e-7, 0.0);
    let (corrected, moved) =
        wall_rolling_correction(n1, anchor, normal, RADIUS, printed::XI_CRIT).unwrap();
    let xi = (corrected + normal) * RADIUS;
    // sin θ from 1 − cos²θ with cos θ = 1 − (ξ_crit/r)²/2 = 1 − 5.6e-6 loses ~11 digits.
    assert!((xi.length() / printed::XI_CRIT - 1.0).abs() < 1e-9);
    assert!((corrected.length() - 1.0).abs() < 1e-15);
    assert_eq!(corrected.y, 0.0, "stays in the plane of n₁ and n_w");
    assert!(corrected.x > 0.0, "on the side it was tilted to");
    let expected_anchor = anchor + (corrected - n1) * RADIUS;
    assert!((moved - expected_anchor).length() < 1e-22);
    // A pointer turned right round (n₁ = +n_w: no tangential direction to follow) still gets a
    // unit pointer on the critical cone.
    let (flipped, _) =
        wall_rolling_correction(normal, anchor, normal, RADIUS, printed::XI_CRIT).unwrap();
    assert!(flipped.is_finite());
    let xi = (flipped + normal) * RADIUS;
    assert!((xi.length() / printed::XI_CRIT - 1.0).abs() < 1e-9);
    // Inside the limit nothing changes.
    let small = DVec3::new(1e-4, 0.0, -1.0).normalize();
    assert!(wall_rolling_correction(small, anchor, normal, RADIUS, printed::XI_CRIT).is_none());
}
