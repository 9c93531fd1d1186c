//! The precision budget of an f32 engine, measured: what plain f32 loses and what the mixed
//! mode's representations (`dustdem::mixed`) keep, for the quantities the contact law is most
//! sensitive to (DESIGN.md, "Precision", quotes the printed tables).
//!
//! Silica monomers of Seizinger et al. (2012): r = 0.6 µm, so δ₀ = 1.7·10⁻⁸ cm, δ_c = 1.4·10⁻⁸
//! cm, ξ_crit = 2·10⁻⁷ cm, in a 100 µm box, with 0.3 ns steps. Each check asserts the chosen
//! representation's error against a budget (a fraction of the scale it must resolve) and that
//! plain f32 misses that budget, so the choice is forced by the numbers, not by taste.

use dustdem::material::{ContactConstants, Material, TwistingStiffness};
use dustdem::mixed::double_f32::DoubleF32;
use dustdem::mixed::split::{pair_overlap, Separation, SplitPosition};
use dustdem::mixed::split_pointer::{rotate_split_pointer, SplitUnit};
use dustdem::model::pointer::rotate_pointer;
use dustdem::rng::Rng;
use glam::{DVec3, Vec3};

const BOX: f64 = 1e-2;
const DT: f64 = 0.3e-9;

fn pair() -> ContactConstants {
    let m = Material::silicate();
    ContactConstants::new(&m, m.radius / 2.0, TwistingStiffness::Printed)
}

fn unit(rng: &mut Rng) -> DVec3 {
    loop {
        let v = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

/// Worst |overlap error| / δ₀ of 10⁴ pairs anywhere in the box, overlaps from −δ_c to 6δ₀.
#[test]
fn overlaps_need_split_positions() {
    let k = pair();
    let r = Material::silicate().radius;
    let two_r = 2.0 * r;
    let mut rng = Rng::new(0x0f32);
    let (mut plain, mut relative, mut split) = (0.0f64, 0.0f64, 0.0f64);
    for _ in 0..10_000 {
        let delta = -k.delta_c + rng.uniform() * (6.0 * k.delta0 + k.delta_c);
        let a = DVec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * BOX;
        let b = a + unit(&mut rng) * (two_r - delta);
        let truth = two_r - (b - a).length();
        // Plain f32 absolute positions.
        let d32 = (b.as_vec3() - a.as_vec3()).length();
        plain = plain.max((f64::from(two_r as f32 - d32) - truth).abs());
        // The exact separation rounded to f32 (the best a plain f32 pair vector can do).
        let rel = (b - a).as_vec3().length();
        relative = relative.max((f64::from(two_r as f32 - rel) - truth).abs());
        // Split positions.
        let s = Separation::between(&SplitPosition::from_f64(a), &SplitPosition::from_f64(b));
        let o = pair_overlap(&s, two_r as f32, DoubleF32::from_f64(two_r * two_r));
        split = split.max((f64::from(o) - truth).abs());
    }
    println!("overlap error / δ₀ (10⁴ pairs, 100 µm box, −δ_c … 6δ₀):");
    println!("  plain f32 positions      {:.2e}", plain / k.delta0);
    println!("  f32 separation vector    {:.2e}", relative / k.delta0);
    println!("  split positions          {:.2e}", split / k.delta0);
    // Budget: the break overlap δ_c to 10⁻⁴ (Must-show tolerance of the mixed mode).
    let budget = 1e-4 * k.delta_c;
    assert!(split < budget / 10.0, "split: {split:e} cm");
    assert!(
        relative > budget && plain > 100.0 * budget,
        "plain f32 would do"
    );
}

/// A wall's position after 10⁵ steps at 1 cm/s (3·10⁻¹⁰ cm each, a third of ulp(10⁻² cm)).
#[test]
fn the_wall_position_needs_more_than_f32() {
    let (start, step, n) = (BOX, 1.0 * DT, 100_000);
    let mut plain = start as f32;
    let mut double = DoubleF32::from_f64(start);
    let mut split = SplitPosition::from_f64(DVec3::splat(start));
    for _ in 0..n {
        plain += step as f32;
        double = double.add_f32(step as f32);
        split.advance(Vec3::splat(step as f32));
    }
    let moved = step * n as f64;
    let err = |p: f64| ((p - start) - moved).abs() / moved;
    println!("wall travel error after 10⁵ steps of 1 cm/s × 0.3 ns (relative to its travel):");
    println!("  plain f32                {:.2e}", err(f64::from(plain)));
    println!("  double-f32               {:.2e}", err(double.to_f64()));
    println!("  split position           {:.2e}", err(split.to_f64().x));
    // The step itself is an f32 (rounded once, 3e-8 relative); the sum must add nothing more
    // than 1e-6 of the travel, so the wall moves at its speed to 1e-6.
    assert!(err(double.to_f64()) < 1e-6 && err(split.to_f64().x) < 1e-6);
    assert!(err(f64::from(plain)) > 0.5, "plain f32 moves the wall");
}

/// A monomer moving at constant speed for 10⁵ steps: its position error against f64, as a
/// fraction of δ₀, at a quasi-static (1 cm/s) and a dynamic (10 m/s) speed.
#[test]
fn monomer_steps_keep_their_sub_nanometre_motion() {
    let k = pair();
    let start = DVec3::new(3.1e-3, 7.3e-3, 5.9e-3);
    for speed in [1.0, 1000.0] {
        let v = DVec3::new(0.6, -0.48, 0.64) * speed;
        let dx = (v * DT).as_vec3();
        let mut plain = start.as_vec3();
        let mut split = SplitPosition::from_f64(start);
        let mut offset_only = SplitPosition::from_f64(start);
        for _ in 0..100_000 {
            plain += dx;
            split.advance(dx);
            // The same without the low part (a plain f32 offset).
            offset_only.offset_lo = Vec3::ZERO;
            offset_only.advance(dx);
            offset_only.offset_lo = Vec3::ZERO;
        }
        let truth = start + dx.as_dvec3() * 1e5;
        let e_plain = (plain.as_dvec3() - truth).length() / k.delta0;
        let e_split = (split.to_f64() - truth).length() / k.delta0;
        let e_offset = (offset_only.to_f64() - truth).length() / k.delta0;
        println!(
            "position error / δ₀ after 10⁵ steps at {speed} cm/s: plain f32 {e_plain:.2e}, \
             f32 offset {e_offset:.2e}, double-f32 offset {e_split:.2e}"
        );
        assert!(e_split < 1e-6, "{speed} cm/s: split {e_split:e}");
        assert!(e_plain > 1e-2, "{speed} cm/s: plain f32 {e_plain:e}");
    }
}

/// rotate_pointer in f32, the same operations as the f64 twin.
fn rotate_pointer_f32(n: Vec3, w: Vec3) -> Vec3 {
    let t2 = w.length_squared();
    if t2 == 0.0 {
        return n;
    }
    let sinc = 1.0 - t2 * (1.0 / 6.0) * (1.0 - t2 * 0.05 * (1.0 - t2 * (1.0 / 42.0)));
    let cosc = 0.5 * (1.0 - t2 * (1.0 / 12.0) * (1.0 - t2 * (1.0 / 30.0)));
    let cos = 1.0 - t2 * cosc;
    let rotated = n * cos + w.cross(n) * sinc + w * (w.dot(n) * cosc);
    rotated.normalize()
}

/// A contact pointer turned by ω·dt every step for 10⁵ steps: the rolling displacement error
/// R·|Δn| against ξ_crit, for a slow (10⁻⁶ rad per step, rolling at ~0.2 cm/s) and a fast
/// (10⁻³ rad) turn.
#[test]
fn pointer_rotations_stay_far_below_the_critical_rolling_length() {
    let k = pair();
    let mut rng = Rng::new(0x9017);
    println!("pointer after 10⁵ rotations, R·|n_f32 − n_f64| / ξ_crit:");
    let mut worst_plain = 0.0f64;
    for angle in [1e-6, 1e-4, 1e-3] {
        let (mut plain, mut split) = (0.0f64, 0.0f64);
        for _ in 0..4 {
            let axis = unit(&mut rng);
            // The rotation vector as the f32 engine has it; the f64 track turns by the same.
            let w32 = (axis * angle).as_vec3();
            let w = w32.as_dvec3();
            let mut n64 = unit(&mut rng);
            let mut n32 = n64.as_vec3();
            let mut ns = SplitUnit::from_f64(n64);
            for _ in 0..100_000 {
                n64 = rotate_pointer(n64, w);
                n32 = rotate_pointer_f32(n32, w32);
                ns = rotate_split_pointer(ns, w32);
            }
            let off = |n: DVec3| (n - n64).length() * k.reduced_radius / k.xi_crit;
            plain = plain.max(off(n32.as_dvec3()));
            split = split.max(off(ns.to_f64()));
        }
        println!("  {angle:.0e} rad per step: plain f32 {plain:.2e}, split {split:.2e}");
        // Budget: ξ_crit, where rolling turns inelastic, to 10⁻³ after 10⁵ steps (the fastest
        // turn, 10⁻³ rad per step, is a surface speed of 2 m/s kept up for 100 rad).
        assert!(split < 1e-3, "{angle} rad: split {split:e}");
        worst_plain = worst_plain.max(plain);
    }
    assert!(
        worst_plain > 1e-2,
        "plain f32 pointers would do: {worst_plain:e}"
    );
}

/// Sums over 10⁵ monomers (a wall's force) and over 10⁶ steps (an energy tally): plain f32
/// against a double-f32 accumulator, relative to the f64 sum.
#[test]
fn accumulators_need_double_f32() {
    let k = pair();
    let mut rng = Rng::new(0x5a3);
    let forces: Vec<f32> = (0..100_000)
        .map(|_| (k.f_c * (rng.uniform() * 2.0 - 0.5)) as f32)
        .collect();
    let exact: f64 = forces.iter().map(|&f| f64::from(f)).sum();
    let plain: f32 = forces.iter().sum();
    let double = forces.iter().fold(DoubleF32::ZERO, |s, &f| s.add_f32(f));
    let e_force = |s: f64| ((s - exact) / exact).abs();
    // An energy tally: 10⁶ increments of a few 10⁻¹⁹ erg (one step's dissipation in a contact)
    // onto a total that grows to 10⁻¹².
    let increments: Vec<f32> = (0..1_000_000)
        .map(|_| (1e-18 * rng.uniform()) as f32)
        .collect();
    let total: f64 = increments.iter().map(|&e| f64::from(e)).sum();
    let mut plain_tally = 1e-12f32;
    let mut double_tally = DoubleF32::from_f64(1e-12);
    for &e in &increments {
        plain_tally += e;
        double_tally = double_tally.add_f32(e);
    }
    let e_tally = |s: f64| ((s - 1e-12 - total) / total).abs();
    println!("sums relative to f64 (force over 10⁵ monomers; 10⁶ energy increments):");
    println!(
        "  plain f32                {:.2e}   {:.2e}",
        e_force(f64::from(plain)),
        e_tally(f64::from(plain_tally))
    );
    println!(
        "  double-f32               {:.2e}   {:.2e}",
        e_force(double.to_f64()),
        e_tally(double_tally.to_f64())
    );
    // Budget: the energy balance of a compression to 1e-4 of the work done.
    assert!(e_force(double.to_f64()) < 1e-8 && e_tally(double_tally.to_f64()) < 1e-8);
    assert!(
        e_tally(f64::from(plain_tally)) > 1e-4,
        "plain f32 keeps the tally"
    );
}
