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

#[path = "../common/mod.rs"]
mod common;
#[path = "../gpu_support/mod.rs"]
mod gpu_support;

mod cases;
mod comparison;
mod mixed;
mod rust_twins;

use cases::cases;
use comparison::Comparison;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::layout::GpuDamping;
use dustdem::backend::gpu::shader::{self, FloatMode};
use dustdem::model::normal::D_MIN;
use dustdem::model::{rolling, sliding, twisting, wall, Damping};
use glam::DVec3;
use gpu_support::run_probe;
use rust_twins::expected;

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
