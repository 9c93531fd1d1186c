//! The crafted state every pass starts from (contacts in every state), the GPU engine holding
//! it, and the comparisons of GPU results with the CPU's.

use crate::common::*;
use dustdem::backend::cpu::CpuEngine;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::engine::GpuEngine;
use dustdem::backend::gpu::shader::FloatMode;
use dustdem::model::{Damping, WallFactors};
use dustdem::state::{ContactTable, Dissipation, Monomers, PairContact, Wall, WallContact};
use glam::{DQuat, DVec3};

const TALLY_TOLERANCE: f64 = 1e-12;

/// Unit vector perpendicular to `n`, chosen by `k`.
pub(crate) fn perpendicular(n: DVec3, k: usize) -> DVec3 {
    let a = n.any_orthonormal_vector();
    let b = n.cross(a);
    let angle = k as f64 * 0.7;
    a * angle.cos() + b * angle.sin()
}

pub(crate) fn turn(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    (DQuat::from_axis_angle(axis, angle) * v).normalize()
}

/// The crafted state and what it contains.
pub(crate) struct Crafted {
    pub(crate) cpu: CpuEngine,
}

pub(crate) fn crafted() -> Crafted {
    let law = law_with(Damping::Viscous { kappa: 1e-6 });
    let dt = 1e-10;
    let r = law.radius;
    let pos = tree_aggregate(&law, 500, 21);
    let mut m = Monomers::new(pos.clone());
    let mut rng = SplitMix64(5);
    for i in 0..m.len() {
        m.velocity[i] = rng.unit_vector() * (20.0 * rng.unit());
        m.angular_velocity[i] = rng.unit_vector() * (20.0 / r * rng.unit());
    }
    let mut zs: Vec<f64> = pos.iter().map(|p| p.z).collect();
    zs.sort_by(f64::total_cmp);
    let mut xs: Vec<f64> = pos.iter().map(|p| p.x).collect();
    xs.sort_by(f64::total_cmp);
    let end = law.wall_constants(WallFactors::FULL);
    let side = law.wall_constants(WallFactors {
        rolling: 0.5,
        sliding: 0.5,
        twisting: 0.5,
    });
    let walls = vec![
        Wall {
            name: "bottom".into(),
            point: DVec3::new(0.0, 0.0, zs[6] - r + 0.5 * end.delta0),
            normal: DVec3::Z,
            velocity: DVec3::ZERO,
            constants: end,
        },
        Wall {
            name: "x+".into(),
            point: DVec3::new(xs[xs.len() - 7] + r - 0.5 * side.delta0, 0.0, 0.0),
            normal: -DVec3::X,
            velocity: DVec3::new(-30.0, 0.0, 0.0),
            constants: side,
        },
    ];
    let mut cpu = CpuEngine::new(law, dt, m, walls, 12, 3).unwrap();
    cpu.run(2).unwrap();

    // Edit the contact table.
    let k = law.pair;
    let s = &mut cpu.state;
    let t = &mut s.contacts;
    let p = &s.monomers.position;
    let mut counter = 0usize;
    for i in 0..p.len() {
        let mut slot = 0;
        while slot < t.pair_count[i] as usize {
            let idx = i * t.pair_slots + slot;
            let mut c = t.pair[idx];
            let nc = (p[i] - p[c.partner as usize]).normalize();
            let axis = perpendicular(nc, counter);
            match counter % 7 {
                // Rolling past ξ_crit: turn n₁ alone.
                0 => c.n1 = turn(c.n1, axis, 3.0 * k.xi_crit / k.reduced_radius),
                // Sliding past ζ_crit: turn both pointers the same way.
                1 => {
                    let angle = 3.0 * k.zeta_crit / r;
                    c.n1 = turn(c.n1, axis, angle);
                    c.n2 = turn(c.n2, axis, angle);
                }
                2 => c.twist = 1.5 * k.phi_crit,
                3 => c.twist = -2.0 * k.phi_crit,
                // Elastic: small rolling and twist.
                4 => {
                    c.n1 = turn(c.n1, axis, 0.2 * k.xi_crit / k.reduced_radius);
                    c.twist = 0.3 * k.phi_crit;
                }
                // Missing from the table: the contacts pass forms it again.
                5 => {
                    let last = i * t.pair_slots + t.pair_count[i] as usize - 1;
                    t.pair[idx] = t.pair[last];
                    t.pair_count[i] -= 1;
                    counter += 1;
                    continue;
                }
                _ => {}
            }
            t.pair[idx] = c;
            counter += 1;
            slot += 1;
        }
    }
    // Stretched past −δ_c: pairs a little too far apart, entered as contacts.
    let mut stretched = 0;
    'outer: for i in 0..p.len() {
        for j in i + 1..p.len() {
            let d = (p[i] - p[j]).length();
            if d > 2.0 * r + k.delta_c && d < 2.2 * r && (t.pair_count[i] as usize) < t.pair_slots {
                let nc = (p[i] - p[j]) / d;
                let idx = i * t.pair_slots + t.pair_count[i] as usize;
                t.pair[idx] = PairContact {
                    partner: j as u32,
                    n1: -nc,
                    n2: nc,
                    twist: 0.0,
                };
                t.pair_count[i] += 1;
                stretched += 1;
                if stretched == 8 {
                    break 'outer;
                }
            }
        }
    }
    assert!(stretched > 0, "no pair to stretch");
    // Wall contacts: limits, and one too far from its wall.
    let mut w_counter = 0usize;
    for i in 0..p.len() {
        for slot in 0..t.wall_count[i] as usize {
            let idx = i * t.wall_slots + slot;
            let mut c = t.wall[idx];
            let wall = &s.walls[c.wall as usize];
            let kw = wall.constants;
            let axis = perpendicular(wall.normal, w_counter);
            match w_counter % 4 {
                0 => c.n1 = turn(c.n1, axis, 3.0 * kw.xi_crit / r),
                1 => c.anchor += axis * (3.0 * kw.zeta_crit),
                2 => c.twist = -1.5 * kw.phi_crit,
                _ => {}
            }
            t.wall[idx] = c;
            w_counter += 1;
        }
    }
    assert!(w_counter >= 4, "only {w_counter} wall contacts");
    // A monomer far above the floor that still has a floor contact: it breaks.
    let far = (0..p.len())
        .find(|&i| t.wall_count[i] == 0 && p[i].z > zs[6] + 10.0 * r)
        .unwrap();
    let floor = &s.walls[0];
    t.wall[far * t.wall_slots] = WallContact {
        wall: 0,
        n1: -floor.normal,
        anchor: p[far] - floor.normal * r,
        twist: 0.0,
    };
    t.wall_count[far] = 1;
    // A floor contact missing from the table: formed again.
    let touching = (0..p.len())
        .find(|&i| t.wall_count[i] == 1 && t.wall[i * t.wall_slots].wall == 0 && i != far)
        .unwrap();
    t.wall_count[touching] = 0;
    Crafted { cpu }
}

pub(crate) fn gpu_of(state: &CpuEngine) -> Option<GpuEngine> {
    gpu_laid_out(state, false)
}

/// The engine holding `state`, with its per-slot arrays split over three bindings if `split`.
pub(crate) fn gpu_laid_out(state: &CpuEngine, split: bool) -> Option<GpuEngine> {
    let ctx = context_for_tests()?;
    Some(
        GpuEngine::with_state_laid_out(
            ctx,
            state.law,
            state.dt,
            &state.monomers,
            &state.contacts,
            state.walls.clone(),
            split,
        )
        .unwrap(),
    )
}

pub(crate) fn exact(gpu: &GpuEngine) -> bool {
    gpu.ctx.float_mode == FloatMode::Exact
}

/// Largest |a − b| / max(|a|, |b|, floor) over the components, 0 when bit-identical.
fn rel(a: DVec3, b: DVec3, floor: f64) -> f64 {
    let d = (a - b).abs().max_element();
    if d == 0.0 {
        0.0
    } else {
        d / a.abs().max(b.abs()).max_element().max(floor)
    }
}

pub(crate) fn worst(a: &[DVec3], b: &[DVec3], floor: f64) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| rel(*x, *y, floor))
        .fold(0.0, f64::max)
}

/// Contact tables equal slot for slot (partners, pointers, twist, anchors) up to `tol`.
pub(crate) fn tables_match(cpu: &ContactTable, gpu: &ContactTable, tol: f64) -> f64 {
    assert_eq!(cpu.pair_count, gpu.pair_count, "pair contact counts");
    assert_eq!(cpu.wall_count, gpu.wall_count, "wall contact counts");
    let mut w = 0.0f64;
    for i in 0..cpu.pair_count.len() {
        for (a, b) in cpu.pairs_of(i).iter().zip(gpu.pairs_of(i)) {
            assert_eq!(a.partner, b.partner, "partner of monomer {i}");
            w = w.max(rel(a.n1, b.n1, 1.0)).max(rel(a.n2, b.n2, 1.0));
            w = w.max((a.twist - b.twist).abs());
        }
        for (a, b) in cpu.walls_of(i).iter().zip(gpu.walls_of(i)) {
            assert_eq!(a.wall, b.wall, "wall of monomer {i}");
            w = w
                .max(rel(a.n1, b.n1, 1.0))
                .max(rel(a.anchor, b.anchor, 0.0));
            w = w.max((a.twist - b.twist).abs());
        }
    }
    assert!(w <= tol, "contact history differs by {w:e}");
    w
}

pub(crate) fn gpu_tally(gpu: &GpuEngine) -> (Dissipation, f64) {
    let mut d = Dissipation::default();
    let mut work = 0.0;
    for t in gpu.monomer_tallies() {
        d.breaking += t[0];
        d.forming += t[1];
        d.damping += t[2];
        d.rolling += t[3];
        d.sliding += t[4];
        d.twisting += t[5];
        d.walls += t[6];
        work += t[7];
    }
    (d, work)
}

pub(crate) fn assert_channel(name: &str, cpu: f64, gpu: f64) {
    let err = (cpu - gpu).abs() / cpu.abs().max(f64::MIN_POSITIVE);
    eprintln!("  {name}: cpu {cpu:.9e} gpu {gpu:.9e} (rel {err:.1e})");
    assert!(cpu != 0.0, "{name}: the state exercises it");
    assert!(err <= TALLY_TOLERANCE, "{name}: {cpu:e} vs {gpu:e}");
}
