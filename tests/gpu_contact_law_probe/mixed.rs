//! The contact law at `Precision::Mixed` (f32 arithmetic) on a device made without
//! `SHADER_F64`, as on Metal or most integrated GPUs: the same probe shader, its text derived
//! to f32, on the same records rounded to f32, against the f64 Rust twins on those rounded
//! records. What differs is f32 arithmetic alone, and the table this prints is the contact
//! law's precision budget in the mixed mode (DESIGN.md, "Precision").
//!
//! Each result's error is measured against the scale that decides what it does, not against
//! its own size (a force crossing zero has no relative error worth the name): forces against
//! the pull-off force F_c, overlaps against δ₀, energies against F_c δ₀ or the potential at the
//! inelastic limit, tangential displacements against their critical lengths ξ_crit, ζ_crit,
//! φ_crit, torques against the torque at the limit, unit vectors against 1.
//!
//! Bounds by conditioning, with ε = 2⁻²⁴ (f32's half ulp):
//! - well-conditioned formulas (a few operations, no cancellation): 128ε = 7.6·10⁻⁶;
//! - the JKR inversion and what uses it: the root at the branch end is a double root, so an
//!   error of ε in d moves x by √ε: 8√ε = 2.0·10⁻³ (the f64 mode's relaxed bound is the same
//!   argument at f64's ε);
//! - functions of absolute positions (`wall_overlap`, `wall_sliding_displacement`) are not held
//!   to a bound: f32 cannot carry a 10⁻⁸ cm overlap on a 10⁻² cm coordinate, which is why the
//!   mixed engine evaluates them from split positions (`dustdem::mixed::split`); their error
//!   is printed.
//!
//! A wall pointer along the wall normal (an edge case of the records) has no tangential
//! direction to be corrected in; those records are counted and left out of
//! `wall_rolling_correction`'s comparison.
//!
//! An inelastic correction that fires on one side only is a record whose criterion lies within
//! f32's resolution of its limit; such records are counted (and must be under 1 %) and their
//! corrected values left out of that function's comparison.

use super::comparison::relative_difference;
use super::{cases, expected, Case, Record};
use dustdem::backend::gpu::context::{context_for_tests_with, ShaderF64};
use dustdem::backend::gpu::shader::{self, Precision, ShaderError};
use dustdem::model::Damping;
use glam::DVec3;
use std::collections::BTreeMap;

const EPS: f64 = 1.0 / 16_777_216.0;

/// The record with every input rounded to the nearest f32.
fn on_f32_grid(c: &Case) -> Case {
    let r = |x: f64| f64::from(x as f32);
    let v = |x: DVec3| x.as_vec3().as_dvec3();
    let damping = match c.damping {
        Damping::None => Damping::None,
        Damping::Viscous { kappa } => Damping::Viscous { kappa: r(kappa) },
        Damping::Viscoelastic { t_vis } => Damping::Viscoelastic { t_vis: r(t_vis) },
    };
    Case {
        x: r(c.x),
        d: r(c.d),
        f_c: r(c.f_c),
        delta0: r(c.delta0),
        damping,
        a: r(c.a),
        e_star: r(c.e_star),
        poisson: r(c.poisson),
        n: v(c.n),
        w: v(c.w),
        n1: v(c.n1),
        n2: v(c.n2),
        reduced_radius: r(c.reduced_radius),
        k_r: r(c.k_r),
        xi_crit: r(c.xi_crit),
        nc: v(c.nc),
        s1: v(c.s1),
        s2: v(c.s2),
        r1: r(c.r1),
        r2: r(c.r2),
        distance: r(c.distance),
        k_s: r(c.k_s),
        zeta_crit: r(c.zeta_crit),
        twist: r(c.twist),
        k_t: r(c.k_t),
        phi_crit: r(c.phi_crit),
        omega_rel: v(c.omega_rel),
        dt: r(c.dt),
        position: v(c.position),
        wall_point: v(c.wall_point),
        normal: v(c.normal),
        r: r(c.r),
        wn1: v(c.wn1),
        p: v(c.p),
        wall_k_s: r(c.wall_k_s),
        wall_xi_crit: r(c.wall_xi_crit),
        wall_zeta_crit: r(c.wall_zeta_crit),
        unit: v(c.unit),
        any: v(c.any),
    }
}

/// The scale `function`'s error is measured against on record `c` (`None`: its own largest
/// component, for quantities that never cross zero). Displacement-driven quantities are scaled
/// by the larger of their critical length and the record's own displacement (records reach
/// far past the limits).
fn scale(function: &str, c: &Case) -> Option<f64> {
    let xi = ((c.n1 + c.n2).length() * c.reduced_radius).max(c.xi_crit);
    let zeta = c.zeta_crit.max(sliding_length(c));
    let phi = c.phi_crit.max(c.twist.abs());
    Some(match function {
        "jkr_overlap_ratio" | "jkr_contact_radius_ratio" => 1.0,
        "jkr_force" => c.f_c,
        "jkr_potential" | "jkr_potential_at_overlap" => c.f_c * c.delta0,
        "rotate_pointer"
        | "rolling_correction"
        | "sliding_correction"
        | "wall_rolling_correction"
        | "any_orthonormal_vector (glam)"
        | "vec_normalize (glam normalize)" => 1.0,
        "rolling_displacement" => xi,
        "rolling_torque" => c.reduced_radius * c.k_r * xi,
        "rolling_potential" => 0.5 * c.k_r * xi * xi,
        "sliding_displacement" => zeta,
        "sliding_force" => c.k_s * zeta,
        "sliding_torque" => c.r1.max(c.r2) * c.k_s * zeta,
        "sliding_potential" => 0.5 * c.k_s * zeta * zeta,
        "twisting_torque" => c.k_t * phi,
        "twisting_potential" => 0.5 * c.k_t * phi * phi,
        "twist_increment" | "twisting_correction" => c.phi_crit,
        "wall_overlap" => c.delta0,
        "wall_rolling_displacement" => c.wall_xi_crit,
        "wall_sliding_displacement" | "wall_sliding_correction" => c.wall_zeta_crit,
        "wall_sliding_force" => c.wall_k_s * c.wall_zeta_crit,
        _ => return None,
    })
}

/// |ζ| of the record, as the Rust twin computes it.
fn sliding_length(c: &Case) -> f64 {
    dustdem::model::sliding::sliding_displacement(c.s1, c.s2, c.nc, c.r1, c.r2).length()
}

/// The condition number of `function` on record `c`: how many times its error may exceed ε
/// relative to its scale, from the sizes of the terms it adds (a sum's rounding is ε times the
/// sum of its terms' magnitudes) or the lengths it takes the difference of.
fn condition(function: &str, c: &Case) -> f64 {
    let x = c.x;
    let xi = (c.n1 + c.n2).length() * c.reduced_radius;
    let zeta = sliding_length(c);
    match function {
        // 4F_c(x³ − x^{3/2}); 4(1.2x⁵ − 2x^{7/2} + 0.5x²) less its value at x₀; 3x² − 2√x.
        "jkr_force" => 4.0 * (x.powi(3) + x.powf(1.5)),
        "jkr_potential" => 4.0 * (1.2 * x.powi(5) + 2.0 * x.powf(3.5) + 0.5 * x * x) + 1.0,
        "jkr_overlap_ratio" => 3.0 * x * x + 2.0 * x.sqrt(),
        // Sums of unit pointers times a radius, against the displacement they leave.
        "rolling_displacement" | "rolling_torque" | "rolling_potential" => {
            c.reduced_radius / c.xi_crit.max(xi)
        }
        "wall_rolling_displacement" => c.r / c.wall_xi_crit,
        // sin θ = √(1 − cos²θ) with cos θ = 1 − q²/2, q = ξ_crit/r: an error of ε in cos θ is
        // one of ε/q in sin θ.
        "wall_rolling_correction" => c.r / c.wall_xi_crit,
        "sliding_displacement" | "sliding_force" | "sliding_torque" | "sliding_potential" => {
            c.r1.max(c.r2) / c.zeta_crit.max(zeta)
        }
        _ => 1.0,
    }
}

/// The bound on `function`'s error relative to its scale on record `c`, `None` where it is
/// only reported.
fn bound(function: &str, c: &Case) -> Option<f64> {
    match function {
        "wall_overlap"
        | "wall_sliding_displacement"
        | "wall_sliding_force"
        | "wall_sliding_correction" => None,
        "jkr_contact_radius_ratio" | "jkr_potential_at_overlap" => Some(8.0 * EPS.sqrt()),
        _ => Some(16.0 * EPS * condition(function, c)),
    }
}

/// A wall pointer along the wall normal to within f32's rounding: its rolling correction may
/// turn it in any tangential direction (the exact case takes any_orthonormal_vector), and
/// after rounding to f32 both codes take the direction of rounding noise.
fn along_the_normal(c: &Case) -> bool {
    (c.wn1 - c.normal * c.wn1.dot(c.normal)).length() < 1e-6
}

/// The flag group of a corrected-value group (`rolling_correction` → its `(fired)` flag).
fn flag_of(function: &str) -> String {
    format!("{function} (fired)")
}

/// `function`'s error on one record: against its scale, or relative to its own size.
fn error_of(function: &str, gpu: &[f64], cpu: &[f64], c: &Case) -> f64 {
    match scale(function, c) {
        Some(scale) => {
            let diff = gpu
                .iter()
                .zip(cpu)
                .fold(0.0f64, |m, (g, c)| m.max((g - c).abs()));
            if diff.is_nan() {
                f64::INFINITY
            } else {
                diff / scale
            }
        }
        None => relative_difference(gpu, cpu),
    }
}

/// The comparison of one run: per function the largest error / scale, the largest error /
/// bound and its record; corrections firing on one side only; degenerate wall pointers.
#[derive(Default)]
struct Summary {
    worst: BTreeMap<&'static str, (f64, f64, usize)>,
    flips: BTreeMap<String, usize>,
    degenerate: usize,
}

impl Summary {
    fn add(&mut self, i: usize, values: &[f64], rust: &Record, c: &Case) {
        let group = |name: &str| rust.groups.iter().find(|(n, _)| *n == name);
        for (name, range) in &rust.groups {
            let (g, cpu) = (&values[range.clone()], &rust.values[range.clone()]);
            if name.ends_with("(fired)") {
                if g != cpu {
                    *self.flips.entry(name.to_string()).or_default() += 1;
                }
                continue;
            }
            if *name == "wall_rolling_correction" && along_the_normal(c) {
                self.degenerate += 1;
                continue;
            }
            if let Some((_, flag)) = group(&flag_of(name)) {
                if values[flag.clone()] != rust.values[flag.clone()] {
                    continue;
                }
            }
            let rel = error_of(name, g, cpu, c);
            let of_bound = bound(name, c).map(|b| rel / b);
            let entry = self.worst.entry(name).or_default();
            // The worst record: by error / bound, or by error where only reported.
            let (key, old_key) = match of_bound {
                Some(r) => (r, entry.1),
                None => (rel, entry.0),
            };
            if key > old_key || i == 0 {
                entry.2 = i;
            }
            entry.0 = entry.0.max(rel);
            entry.1 = entry.1.max(of_bound.unwrap_or(0.0));
        }
    }

    /// Prints the table and fails on an error beyond its bound or flips on 1 % of records.
    fn print_and_check(&self, adapter: &str, records: usize, any: &Case) {
        println!("f32 contact law on {adapter} (SHADER_F64 refused), {records} records:");
        println!(
            "  {:<34} {:>11} {:>13}  worst record",
            "function", "error", "error / bound"
        );
        let mut over = Vec::new();
        for (name, (rel, of_bound, at)) in &self.worst {
            let shown = match bound(name, any) {
                Some(_) => format!("{of_bound:.3}"),
                None => "reported".to_string(),
            };
            println!("  {name:<34} {rel:>11.3e} {shown:>13}  {at}");
            if *of_bound > 1.0 {
                over.push(format!("{name}: {of_bound:.3} of its bound (record {at})"));
            }
        }
        println!("  corrections firing on one side only: {:?}", self.flips);
        println!(
            "  wall pointers along the normal (correction direction arbitrary): {}",
            self.degenerate
        );
        assert!(
            over.is_empty(),
            "f32 beyond its bound:\n{}",
            over.join("\n")
        );
        for (name, n) in &self.flips {
            assert!(*n * 100 < records, "{name} flips on {n} records");
        }
    }
}

#[test]
fn the_contact_law_in_f32_on_a_device_without_f64() {
    let Some(ctx) = context_for_tests_with(ShaderF64::Refused) else {
        return;
    };
    assert!(!ctx.shader_f64);
    let probe = shader::assemble_pass("contact_law_probe").unwrap_or_else(|e| panic!("{e}"));
    // The f64 text is refused on this device; its f32 derivation runs.
    assert!(matches!(
        probe.create_module(&ctx),
        Err(ShaderError::F64Unavailable { .. })
    ));
    let module = probe
        .with_precision(Precision::Mixed)
        .create_module(&ctx)
        .unwrap_or_else(|e| panic!("{e}"));

    let cases: Vec<Case> = cases().iter().map(on_f32_grid).collect();
    let expected: Vec<Record> = cases.iter().map(expected).collect();
    let mut inputs = Vec::new();
    for c in &cases {
        c.write(&mut inputs);
    }
    let in_stride = inputs.len() / cases.len();
    let written = expected[0].values.len();
    let inputs: Vec<f32> = inputs.iter().map(|&x| x as f32).collect();
    let gpu = super::gpu_support::run_probe_f32(&ctx, &module, &inputs, in_stride, written + 2);

    let mut summary = Summary::default();
    for (i, (record, rust)) in gpu.chunks(written + 2).zip(&expected).enumerate() {
        assert_eq!(
            (record[0] as usize, record[1] as usize),
            (in_stride, written),
            "record {i}: the probe read/wrote another layout"
        );
        let values: Vec<f64> = record[2..].iter().map(|&v| f64::from(v)).collect();
        summary.add(i, &values, rust, &cases[i]);
    }
    summary.print_and_check(&ctx.summary().name, cases.len(), &cases[0]);
}
