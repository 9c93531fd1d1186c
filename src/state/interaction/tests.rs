//! The tangential step energies against the whole ones across a correction.

use super::*;
use crate::material::Material;
use crate::model::ModelOptions;

/// Two monomers pressed together, moving and spinning, with a contact rolled, slid and
/// twisted past every limit.
fn rolled_contact() -> (ContactLaw, Monomers, PairContact) {
    let law = ContactLaw::new(&Material::silicate(), &ModelOptions::default());
    let r = law.radius;
    let mut m = Monomers::new(vec![DVec3::ZERO, DVec3::new(2.0 * r - 3e-8, 1e-9, 0.0)]);
    m.velocity = vec![DVec3::new(3.0, -1.0, 2.0), DVec3::new(-2.0, 0.5, 1.0)];
    m.angular_velocity = vec![DVec3::new(1e4, 2e4, -3e4), DVec3::new(-2e4, 1e4, 5e3)];
    let tilt = DVec3::new(0.0, 0.6, 0.8) * 0.05;
    let c = PairContact {
        partner: 1,
        n1: (DVec3::X + tilt).normalize(),
        n2: (-DVec3::X + tilt * 0.3).normalize(),
        twist: 3.0 * law.pair.phi_crit,
    };
    (law, m, c)
}

#[test]
fn a_correction_drops_the_tangential_step_energy_by_what_it_drops_the_whole_one() {
    let (law, m, before) = rolled_contact();
    let k = &law.pair;
    let (p, v, w) = (&m.position, &m.velocity, &m.angular_velocity);
    let frame = pair_frame(p[0], p[1], v[0], v[1]);
    let (n1, n2) = rolling::rolling_correction(before.n1, before.n2, k.reduced_radius, k.xi_crit)
        .expect("rolled past the limit");
    let twist = twisting::twisting_correction(before.twist, k.phi_crit).expect("twisted");
    let after = PairContact {
        n1,
        n2,
        twist,
        ..before
    };
    let dt = 3e-10;
    let whole =
        pair_step_energy(&law, &m, dt, 0, &before) - pair_step_energy(&law, &m, dt, 0, &after);
    let tangential = pair_tangential_step_energy(&law, &frame, w[0], w[1], dt, &before)
        - pair_tangential_step_energy(&law, &frame, w[0], w[1], dt, &after);
    // The JKR and damping terms cancel exactly in the whole drop except for their rounding,
    // a few units in the last place of the whole energy.
    let scale = pair_step_energy(&law, &m, dt, 0, &before).abs();
    assert!(
        tangential > 1e3 * f64::EPSILON * scale,
        "{tangential:e} against {scale:e}"
    );
    assert!(
        (whole - tangential).abs() <= 16.0 * f64::EPSILON * scale,
        "whole {whole:e}, tangential {tangential:e}, scale {scale:e}"
    );
}

#[test]
fn a_wall_correction_drops_the_tangential_step_energy_by_what_it_drops_the_whole_one() {
    use crate::model::WallFactors;
    let law = ContactLaw::new(&Material::silicate(), &ModelOptions::default());
    let r = law.radius;
    let k = law.wall_constants(WallFactors::FULL);
    // The bottom wall moving up at 1 m/s and sideways at 0.3 m/s under a monomer pressed into it, sliding and
    // spinning, its contact slid and twisted past the limits.
    let wall = Wall {
        name: "bottom".into(),
        point: DVec3::new(0.0, 0.0, -r + 2.0 * k.delta0),
        normal: DVec3::Z,
        velocity: DVec3::new(30.0, 0.0, 100.0),
        constants: k,
    };
    let mut m = Monomers::new(vec![DVec3::ZERO]);
    m.velocity = vec![DVec3::new(5.0, -2.0, 1.0)];
    m.angular_velocity = vec![DVec3::new(3e4, -1e4, 2e4)];
    let x = m.position[0];
    let before = WallContact {
        wall: 0,
        n1: -DVec3::Z,
        anchor: x - DVec3::Z * r + DVec3::new(40.0, -30.0, 0.0) * k.zeta_crit,
        twist: -2.0 * k.phi_crit,
    };
    let zeta = wall_law::wall_sliding_displacement(x, before.n1, r, before.anchor, DVec3::Z);
    let after = WallContact {
        anchor: wall_law::wall_sliding_correction(before.anchor, zeta, k.zeta_crit)
            .expect("slid past the limit"),
        twist: twisting::twisting_correction(before.twist, k.phi_crit).expect("twisted"),
        ..before
    };
    let dt = 3e-10;
    let whole = |c: &WallContact| wall_step_energy(&law, &m, dt, 0, &wall, c);
    let motion = WallMotion {
        x,
        v: m.velocity[0],
        w: m.angular_velocity[0],
    };
    let part = |c: &WallContact| wall_tangential_step_energy(&law, &motion, &wall, dt, c);
    let (drop, tangential) = (whole(&before) - whole(&after), part(&before) - part(&after));
    let scale = whole(&before).abs();
    assert!(
        tangential > 1e3 * f64::EPSILON * scale,
        "{tangential:e} against {scale:e}"
    );
    assert!(
        (drop - tangential).abs() <= 16.0 * f64::EPSILON * scale,
        "whole {drop:e}, tangential {tangential:e}, scale {scale:e}"
    );
}
