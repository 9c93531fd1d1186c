//! Every WGSL contact-law function against its Rust twin, on lavapipe or whatever adapter the
//! machine has.
//!
//! 10⁴ seeded records cover the physical range: overlaps from beyond the break (−δ_c) to six δ₀
//! with the Newton solve's hard cases next to the branch end, pointers from aligned to opposite
//! (both sides of every inelastic limit), rotation vectors up to 0.3 rad, both contact kinds
//! and two parameter sets. The first records are hand-picked edge cases (exact limits, zero
//! rotation, a pointer exactly along the wall normal, signed zeros).
//!
//! The twins use only + − × ÷ √ and comparisons in f64, in the same order. In
//! [`FloatMode::Exact`] (float operations marked `NoContraction`) they must agree to the bit:
//! [`TOLERANCE`] is zero, because anything looser hides real slips (a wrong θ¹⁰ coefficient in
//! rotate_pointer's series moves it by only 7·10⁻¹⁶). In [`FloatMode::Relaxed`] (plain WGSL) the
//! driver may fuse and reassociate: a few ulps, which the JKR Newton solve next to its double
//! root at the branch end turns into up to √ulp; the test allows [`RELAXED_TOLERANCE`] there.
//! In both modes every inelastic correction must fire on exactly the same records.

mod common;
mod gpu_support;

use common::SplitMix64;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::layout::GpuDamping;
use dustdem::backend::gpu::shader::{self, FloatMode};
use dustdem::material::{ContactConstants, Material, TwistingStiffness, WallTwisting};
use dustdem::model::normal::{D_MIN, X_AT_ZERO_OVERLAP, X_MIN};
use dustdem::model::{
    damping, normal, pointer, rolling, sliding, twisting, wall, ContactLaw, Damping, ModelOptions,
};
use glam::{DQuat, DVec3};
use gpu_support::run_probe;
use std::collections::BTreeMap;
use std::f64::consts::PI;

const CASES: usize = 10_000;
const SEED: u64 = 0x5eed_d057_de30;
/// Largest accepted |GPU − CPU| / max|CPU component| of any result, in the exact mode.
const TOLERANCE: f64 = 0.0;
/// The same in the relaxed mode: √ε, the conditioning of the JKR root at the branch end.
const RELAXED_TOLERANCE: f64 = 1.5e-8;

/// One input record; [`Case::write`] lays it out in the order the probe shader reads it.
#[derive(Clone, Copy, Debug)]
struct Case {
    x: f64,
    d: f64,
    f_c: f64,
    delta0: f64,
    damping: Damping,
    a: f64,
    e_star: f64,
    poisson: f64,
    n: DVec3,
    w: DVec3,
    n1: DVec3,
    n2: DVec3,
    reduced_radius: f64,
    k_r: f64,
    xi_crit: f64,
    nc: DVec3,
    s1: DVec3,
    s2: DVec3,
    r1: f64,
    r2: f64,
    distance: f64,
    k_s: f64,
    zeta_crit: f64,
    twist: f64,
    k_t: f64,
    phi_crit: f64,
    omega_rel: DVec3,
    dt: f64,
    position: DVec3,
    wall_point: DVec3,
    normal: DVec3,
    r: f64,
    wn1: DVec3,
    p: DVec3,
    wall_k_s: f64,
    wall_xi_crit: f64,
    wall_zeta_crit: f64,
    unit: DVec3,
    any: DVec3,
}

impl Case {
    fn write(&self, out: &mut Vec<f64>) {
        let v3 = |v: DVec3, out: &mut Vec<f64>| out.extend([v.x, v.y, v.z]);
        out.extend([self.x, self.d, self.f_c, self.delta0]);
        let damping = GpuDamping::from(self.damping);
        out.extend([f64::from(damping.kind), damping.value]);
        out.extend([self.a, self.e_star, self.poisson]);
        v3(self.n, out);
        v3(self.w, out);
        v3(self.n1, out);
        v3(self.n2, out);
        out.extend([self.reduced_radius, self.k_r, self.xi_crit]);
        v3(self.nc, out);
        v3(self.s1, out);
        v3(self.s2, out);
        out.extend([self.r1, self.r2, self.distance, self.k_s, self.zeta_crit]);
        out.extend([self.twist, self.k_t, self.phi_crit]);
        v3(self.omega_rel, out);
        out.push(self.dt);
        v3(self.position, out);
        v3(self.wall_point, out);
        v3(self.normal, out);
        out.push(self.r);
        v3(self.wn1, out);
        v3(self.p, out);
        out.extend([self.wall_k_s, self.wall_xi_crit, self.wall_zeta_crit]);
        v3(self.unit, out);
        v3(self.any, out);
    }
}

/// Expected outputs: values in the shader's write order, grouped by the call that made them.
#[derive(Default)]
struct Record {
    values: Vec<f64>,
    groups: Vec<(&'static str, std::ops::Range<usize>)>,
}

impl Record {
    fn put_all(&mut self, name: &'static str, v: &[f64]) {
        let start = self.values.len();
        self.values.extend_from_slice(v);
        self.groups.push((name, start..self.values.len()));
    }
    fn put(&mut self, name: &'static str, v: f64) {
        self.put_all(name, &[v]);
    }
    fn put3(&mut self, name: &'static str, v: DVec3) {
        self.put_all(name, &v.to_array());
    }
    /// Option<T> as the WGSL struct has it: a `changed` flag (compared exactly, under its own
    /// name) and the corrected values, or the inputs when unchanged.
    fn put_option(
        &mut self,
        name: &'static str,
        flag: &'static str,
        v: Option<&[f64]>,
        or: &[f64],
    ) {
        self.put(flag, if v.is_some() { 1.0 } else { 0.0 });
        self.put_all(name, v.unwrap_or(or));
    }
}

/// The Rust twins on one record, in the probe shader's order.
fn expected(c: &Case) -> Record {
    let mut r = Record::default();
    r.put("jkr_overlap_ratio", normal::jkr_overlap_ratio(c.x));
    r.put(
        "jkr_contact_radius_ratio",
        normal::jkr_contact_radius_ratio(c.d),
    );
    r.put("jkr_force", normal::jkr_force(c.x, c.f_c));
    r.put("jkr_potential", normal::jkr_potential(c.x, c.f_c, c.delta0));
    r.put(
        "jkr_potential_at_overlap",
        normal::jkr_potential_at_overlap(c.d, c.f_c, c.delta0),
    );
    r.put(
        "damping_coefficient",
        damping::damping_coefficient(&c.damping, c.a, c.e_star, c.poisson),
    );
    r.put3("rotate_pointer", pointer::rotate_pointer(c.n, c.w));

    let xi = rolling::rolling_displacement(c.n1, c.n2, c.reduced_radius);
    r.put3("rolling_displacement", xi);
    r.put3(
        "rolling_torque",
        rolling::rolling_torque(c.n1, xi, c.reduced_radius, c.k_r),
    );
    r.put("rolling_potential", rolling::rolling_potential(xi, c.k_r));
    let rc = rolling::rolling_correction(c.n1, c.n2, c.reduced_radius, c.xi_crit);
    let pair = |(a, b): (DVec3, DVec3)| [a.x, a.y, a.z, b.x, b.y, b.z];
    r.put_option(
        "rolling_correction",
        "rolling_correction (fired)",
        rc.map(pair).as_ref().map(|v| &v[..]),
        &pair((c.n1, c.n2)),
    );

    let zeta = sliding::sliding_displacement(c.s1, c.s2, c.nc, c.r1, c.r2);
    r.put3("sliding_displacement", zeta);
    r.put3(
        "sliding_force",
        sliding::sliding_force(zeta, c.s1, c.s2, c.nc, c.r1, c.r2, c.distance, c.k_s),
    );
    r.put3(
        "sliding_torque",
        sliding::sliding_torque(c.s1, zeta, c.r1, c.k_s, 1.0),
    );
    r.put3(
        "sliding_torque",
        sliding::sliding_torque(c.s2, zeta, c.r2, c.k_s, -1.0),
    );
    r.put("sliding_potential", sliding::sliding_potential(zeta, c.k_s));
    let sc = sliding::sliding_correction(c.s1, c.s2, c.nc, c.r1, c.r2, c.zeta_crit);
    r.put_option(
        "sliding_correction",
        "sliding_correction (fired)",
        sc.map(pair).as_ref().map(|v| &v[..]),
        &pair((c.s1, c.s2)),
    );

    r.put3(
        "twisting_torque",
        twisting::twisting_torque(c.twist, c.nc, c.k_t),
    );
    r.put(
        "twisting_potential",
        twisting::twisting_potential(c.twist, c.k_t),
    );
    r.put(
        "twist_increment",
        twisting::twist_increment(c.omega_rel, c.nc, c.dt),
    );
    let tc = twisting::twisting_correction(c.twist, c.phi_crit);
    r.put_option(
        "twisting_correction",
        "twisting_correction (fired)",
        tc.map(|t| [t]).as_ref().map(|v| &v[..]),
        &[c.twist],
    );

    r.put(
        "wall_overlap",
        wall::wall_overlap(c.position, c.wall_point, c.normal, c.r),
    );
    r.put3(
        "wall_rolling_displacement",
        wall::wall_rolling_displacement(c.wn1, c.normal, c.r),
    );
    let wrc = wall::wall_rolling_correction(c.wn1, c.p, c.normal, c.r, c.wall_xi_crit);
    r.put_option(
        "wall_rolling_correction",
        "wall_rolling_correction (fired)",
        wrc.map(pair).as_ref().map(|v| &v[..]),
        &pair((c.wn1, c.p)),
    );
    let wall_zeta = wall::wall_sliding_displacement(c.position, c.wn1, c.r, c.p, c.normal);
    r.put3("wall_sliding_displacement", wall_zeta);
    r.put3(
        "wall_sliding_force",
        wall::wall_sliding_force(wall_zeta, c.wall_k_s),
    );
    let wsc = wall::wall_sliding_correction(c.p, wall_zeta, c.wall_zeta_crit);
    r.put_option(
        "wall_sliding_correction",
        "wall_sliding_correction (fired)",
        wsc.map(|v| v.to_array()).as_ref().map(|v| &v[..]),
        &c.p.to_array(),
    );

    r.put3(
        "any_orthonormal_vector (glam)",
        c.unit.any_orthonormal_vector(),
    );
    r.put3("vec_normalize (glam normalize)", c.any.normalize());
    r
}

fn random_unit(rng: &mut SplitMix64) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let l2 = v.length_squared();
        if l2 > 1e-4 && l2 <= 1.0 {
            return v.normalize();
        }
    }
}

/// `v` turned by `angle` about a random axis perpendicular to it.
fn tilt(rng: &mut SplitMix64, v: DVec3, angle: f64) -> DVec3 {
    let axis = v.cross(random_unit(rng)).normalize();
    (DQuat::from_axis_angle(axis, angle) * v).normalize()
}

/// Record `i`'s value of one field: the `i`-th edge case while there are any, else `random`.
fn edge_or<T: Copy>(i: usize, edges: &[T], random: impl FnOnce() -> T) -> T {
    edges.get(i).copied().unwrap_or_else(random)
}

/// Signed zeros and axis-aligned normals: the unit vectors whose any_orthonormal_vector
/// depends on the sign of a zero z.
const AXIS_EDGES: [DVec3; 8] = [
    DVec3::new(1.0, 0.0, -0.0),
    DVec3::new(0.0, 1.0, -0.0),
    DVec3::new(1.0, 0.0, 0.0),
    DVec3::new(0.0, -1.0, 0.0),
    DVec3::new(0.0, 0.0, 1.0),
    DVec3::new(0.0, 0.0, -1.0),
    DVec3::new(0.6, 0.8, -0.0),
    DVec3::new(-0.6, 0.8, 0.0),
];

fn cases() -> Vec<Case> {
    let material = Material::silicate();
    let laws = [
        ContactLaw::new(&material, &ModelOptions::default()),
        // The paper's calibrated modifiers, another k_t (and the wall's own), viscoelastic
        // damping.
        ContactLaw::new(
            &material,
            &ModelOptions {
                rolling_modifier: 8.0,
                sliding_modifier: 2.5,
                twisting_modifier: 1.0,
                twisting_stiffness: TwistingStiffness::ReducedShear,
                wall_twisting: WallTwisting::WallContactRadius,
                damping: Damping::Viscoelastic { t_vis: 5e-12 },
            },
        ),
    ];
    let mut rng = SplitMix64(SEED);
    (0..CASES)
        .map(|i| {
            let law = &laws[i % 2];
            let c: ContactConstants = if (i / 2) % 2 == 0 { law.pair } else { law.wall };
            let rng = &mut rng;

            let x = edge_or(i, &[X_MIN, X_AT_ZERO_OVERLAP, 1.0, 2.5], || {
                rng.uniform(X_MIN, 2.5)
            });
            let d = edge_or(
                i,
                &[
                    D_MIN,
                    D_MIN + 1e-16,
                    D_MIN + 1e-15,
                    D_MIN + 1e-12,
                    D_MIN + 1e-8,
                    D_MIN - 1e-16,
                    -1.0,
                    0.0,
                    -0.0,
                    1.0,
                    6.0,
                ],
                || match rng.unit() {
                    // The branch end, where the quartic's slope vanishes and Newton slows.
                    u if u < 0.2 => D_MIN + rng.log_uniform(1e-15, 1e-1),
                    // Stretched past the break: the linear continuation.
                    u if u < 0.3 => rng.uniform(1.05 * D_MIN, D_MIN),
                    _ => rng.uniform(D_MIN, 6.0),
                },
            );
            let damping = match i % 3 {
                0 => Damping::None,
                1 => Damping::Viscous {
                    kappa: rng.log_uniform(1e-8, 1e-4),
                },
                _ => Damping::Viscoelastic {
                    t_vis: rng.log_uniform(1e-13, 1e-10),
                },
            };

            let n = random_unit(rng);
            let w = edge_or(
                i,
                &[
                    DVec3::ZERO,
                    DVec3::new(1e-9, 0.0, 0.0),
                    DVec3::new(0.0, 0.3, 0.0),
                    DVec3::new(0.0, 0.0, -0.3),
                ],
                || {
                    let magnitude = match rng.unit() {
                        u if u < 0.1 => 0.0,
                        u if u < 0.5 => rng.log_uniform(1e-12, 0.3),
                        _ => rng.uniform(0.0, 0.3),
                    };
                    random_unit(rng) * magnitude
                },
            );

            // Rolling: n₂ = −n₁ turned by θ, |ξ| ≈ Rθ; ξ_crit/R is 3e-3..7e-3.
            let n1 = random_unit(rng);
            let theta = edge_or(i, &[0.0, PI, c.xi_crit / c.reduced_radius], || {
                rng.log_uniform(1e-6, PI)
            });
            let n2 = tilt(rng, -n1, theta);

            // Sliding: pointers tilted off ±n_c; ζ_crit/r is about 1e-2.
            let nc = random_unit(rng);
            let (t1, t2) = edge_or(i, &[(0.0, 0.0), (1e-3, 0.0), (0.0, 0.5)], || {
                (rng.log_uniform(1e-7, 1.0), rng.log_uniform(1e-7, 1.0))
            });
            let s1 = tilt(rng, nc, t1);
            let s2 = tilt(rng, -nc, t2);
            let (r1, r2) = if i % 4 == 3 {
                (
                    material.radius * rng.uniform(0.5, 1.5),
                    material.radius * rng.uniform(0.5, 1.5),
                )
            } else {
                (material.radius, material.radius)
            };
            let distance = r1 + r2 - d * c.delta0;

            // Twisting: φ up to three times φ_crit, ω_rel up to 10⁷ rad/s.
            let twist = edge_or(
                i,
                &[
                    0.0,
                    c.phi_crit,
                    -c.phi_crit,
                    -0.0,
                    c.phi_crit * (1.0 + 1e-15),
                ],
                || c.phi_crit * rng.uniform(-3.0, 3.0),
            );
            let omega_rel = random_unit(rng) * rng.log_uniform(1.0, 1e7);
            let dt = 3e-10 * rng.uniform(0.5, 1.5);

            // Wall: a monomer of radius r at overlap d_w δ₀ from a plane through wall_point.
            let wc = law.wall;
            let normal = edge_or(i, &AXIS_EDGES, || random_unit(rng));
            let r = material.radius;
            let position = DVec3::new(
                rng.uniform(-0.05, 0.05),
                rng.uniform(-0.05, 0.05),
                rng.uniform(-0.05, 0.05),
            );
            let d_w = rng.uniform(1.05 * D_MIN, 5.0);
            let along = random_unit(rng) * rng.uniform(0.0, 1e-3);
            let along = along - normal * along.dot(normal);
            let wall_point = position - normal * (r - d_w * wc.delta0) + along;
            // Edge cases first: pointer exactly onto the wall (no correction), exactly off it
            // (the any_orthonormal_vector branch), then random tilts off −n_w.
            let wn1 = if i < AXIS_EDGES.len() {
                normal
            } else if i < 2 * AXIS_EDGES.len() {
                -normal
            } else {
                let angle = rng.log_uniform(1e-6, PI / 2.0);
                tilt(rng, -normal, angle)
            };
            let p =
                position + wn1 * r - random_unit(rng) * wc.zeta_crit * rng.log_uniform(1e-2, 3.0);

            let unit = edge_or(i, &AXIS_EDGES, || random_unit(rng));
            let any = random_unit(rng) * rng.log_uniform(1e-10, 1e10);

            Case {
                x,
                d,
                f_c: c.f_c,
                delta0: c.delta0,
                damping,
                a: x * c.a0,
                e_star: law.e_star,
                poisson: law.poisson,
                n,
                w,
                n1,
                n2,
                reduced_radius: c.reduced_radius,
                k_r: c.k_r,
                xi_crit: c.xi_crit,
                nc,
                s1,
                s2,
                r1,
                r2,
                distance,
                k_s: c.k_s,
                zeta_crit: c.zeta_crit,
                twist,
                k_t: c.k_t,
                phi_crit: c.phi_crit,
                omega_rel,
                dt,
                position,
                wall_point,
                normal,
                r,
                wn1,
                p,
                wall_k_s: wc.k_s,
                wall_xi_crit: wc.xi_crit,
                wall_zeta_crit: wc.zeta_crit,
                unit,
                any,
            }
        })
        .collect()
}

/// |gpu − cpu| relative to the largest |cpu| component: 0 when bit-identical or NaN on both
/// sides, infinite when only one side is NaN.
fn relative_difference(gpu: &[f64], cpu: &[f64]) -> f64 {
    if gpu.iter().zip(cpu).all(|(g, c)| g.to_bits() == c.to_bits()) {
        return 0.0;
    }
    let scale = cpu.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let diff = gpu
        .iter()
        .zip(cpu)
        .fold(0.0f64, |m, (g, c)| m.max((g - c).abs()));
    if diff.is_nan() {
        f64::INFINITY
    } else if diff == 0.0 {
        // Only signed zeros differ.
        0.0
    } else {
        diff / scale
    }
}

#[derive(Default)]
struct Tally {
    results: usize,
    identical: usize,
    worst: f64,
    worst_case: usize,
}

/// One mode's run compared with the Rust twins.
struct Comparison {
    tallies: BTreeMap<&'static str, Tally>,
    flag_mismatches: Vec<String>,
}

impl Comparison {
    fn new(gpu: &[f64], expected: &[Record], in_stride: usize) -> Self {
        let written = expected[0].values.len();
        let mut tallies: BTreeMap<&'static str, Tally> = BTreeMap::new();
        let mut flag_mismatches = Vec::new();
        for (i, (record, rust)) in gpu.chunks(written + 2).zip(expected).enumerate() {
            assert_eq!(
                (record[0] as usize, record[1] as usize),
                (in_stride, written),
                "record {i}: the probe read/wrote a different number of values than the test \
                 laid out"
            );
            let values = &record[2..];
            for (name, range) in &rust.groups {
                let (g, c) = (&values[range.clone()], &rust.values[range.clone()]);
                if name.ends_with("(fired)") && g != c {
                    flag_mismatches.push(format!("record {i}: {name} GPU {g:?} CPU {c:?}"));
                }
                let rel = relative_difference(g, c);
                let t = tallies.entry(name).or_default();
                t.results += 1;
                t.identical += usize::from(rel == 0.0);
                if rel > t.worst {
                    t.worst = rel;
                    t.worst_case = i;
                }
            }
        }
        Comparison {
            tallies,
            flag_mismatches,
        }
    }

    fn print(&self, title: &str) {
        println!("{title}");
        println!(
            "  {:<34} {:>8} {:>10} {:>11}  worst record",
            "function", "results", "identical", "max rel"
        );
        for (name, t) in &self.tallies {
            println!(
                "  {name:<34} {:>8} {:>10} {:>11.3e}  {}",
                t.results, t.identical, t.worst, t.worst_case
            );
        }
    }

    fn check(&self, mode: FloatMode, tolerance: f64) {
        assert!(
            self.flag_mismatches.is_empty(),
            "{mode:?}: inelastic corrections fired on different records:\n{}",
            self.flag_mismatches.join("\n")
        );
        let over: Vec<_> = self
            .tallies
            .iter()
            .filter(|(_, t)| t.worst > tolerance)
            .map(|(name, t)| format!("{name}: {:.3e} (record {})", t.worst, t.worst_case))
            .collect();
        assert!(
            over.is_empty(),
            "{mode:?}: GPU and CPU twins differ by more than {tolerance:e}:\n{}",
            over.join("\n")
        );
    }
}

#[test]
fn contact_law_twins_agree_on_the_gpu() {
    let Some(ctx) = context_for_tests() else {
        return;
    };
    if std::env::var_os("CI").is_some() {
        assert_eq!(
            ctx.float_mode,
            FloatMode::Exact,
            "CI runs on lavapipe (Vulkan), which offers the exact mode"
        );
    }
    let cases = cases();
    let expected: Vec<Record> = cases.iter().map(expected).collect();
    let mut inputs = Vec::new();
    let mut in_stride = 0;
    for c in &cases {
        let before = inputs.len();
        c.write(&mut inputs);
        in_stride = inputs.len() - before;
    }
    // Two leading slots: the probe's own count of values read and written.
    let out_stride = 2 + expected[0].values.len();

    let assembled = shader::assemble_pass("contact_law_probe").unwrap_or_else(|e| panic!("{e}"));
    let modes: &[(FloatMode, f64)] = match ctx.float_mode {
        FloatMode::Exact => &[
            (FloatMode::Exact, TOLERANCE),
            (FloatMode::Relaxed, RELAXED_TOLERANCE),
        ],
        FloatMode::Relaxed => &[(FloatMode::Relaxed, RELAXED_TOLERANCE)],
    };
    let mut comparisons = Vec::new();
    for &(mode, tolerance) in modes {
        let module = assembled
            .create_module_as(&ctx, mode)
            .unwrap_or_else(|e| panic!("{e}"));
        let started = std::time::Instant::now();
        let gpu = run_probe(&ctx, &module, &inputs, in_stride, out_stride);
        let comparison = Comparison::new(&gpu, &expected, in_stride);
        comparison.print(&format!(
            "{mode:?} mode: {} records on {} in {:.2?}",
            cases.len(),
            ctx.summary().name,
            started.elapsed()
        ));
        comparisons.push((mode, tolerance, comparison));
    }
    for (mode, tolerance, comparison) in &comparisons {
        comparison.check(*mode, *tolerance);
    }
}

/// Every inelastic branch and edge case is actually reached by the records (on the CPU side,
/// so this runs without a GPU): a probe that never fires a correction proves nothing about it.
#[test]
fn the_records_reach_every_branch() {
    let cases = cases();
    let count = |f: &dyn Fn(&Case) -> bool| cases.iter().filter(|c| f(c)).count();
    let both = |name: &str, fired: usize| {
        assert!(
            fired > 100 && fired < CASES - 100,
            "{name}: fires on {fired} of {CASES} records; both branches need many"
        );
    };
    both(
        "rolling_correction",
        count(&|c| rolling::rolling_correction(c.n1, c.n2, c.reduced_radius, c.xi_crit).is_some()),
    );
    both(
        "sliding_correction",
        count(&|c| {
            sliding::sliding_correction(c.s1, c.s2, c.nc, c.r1, c.r2, c.zeta_crit).is_some()
        }),
    );
    both(
        "twisting_correction",
        count(&|c| twisting::twisting_correction(c.twist, c.phi_crit).is_some()),
    );
    both(
        "wall_rolling_correction",
        count(&|c| {
            wall::wall_rolling_correction(c.wn1, c.p, c.normal, c.r, c.wall_xi_crit).is_some()
        }),
    );
    both(
        "wall_sliding_correction",
        count(&|c| {
            let zeta = wall::wall_sliding_displacement(c.position, c.wn1, c.r, c.p, c.normal);
            wall::wall_sliding_correction(c.p, zeta, c.wall_zeta_crit).is_some()
        }),
    );
    both("d below the branch end", count(&|c| c.d < D_MIN));
    both("zero rotation", count(&|c| c.w == DVec3::ZERO));
    assert!(
        count(&|c| c.w.length() > 0.29) > 10,
        "rotations up to 0.3 rad"
    );
    assert!(count(&|c| c.d > 5.0) > 100, "overlaps of several δ₀");
    // The tangential-free wall pointer, with the normal's z = −0 and +0.
    let degenerate = |c: &Case| {
        let t = c.wn1 - c.normal * c.wn1.dot(c.normal);
        t.length() == 0.0
            && wall::wall_rolling_correction(c.wn1, c.p, c.normal, c.r, c.wall_xi_crit).is_some()
    };
    assert!(count(&|c| degenerate(c) && c.normal.z.is_sign_negative() && c.normal.z == 0.0) >= 2);
    assert!(count(&|c| degenerate(c) && c.normal.z.is_sign_positive() && c.normal.z == 0.0) >= 2);
}
