//! Which f64 builtins the adapter computes correctly.
//!
//! naga accepts every WGSL float builtin on f64, but drivers need not implement them: Vulkan
//! leaves f64 transcendentals to extensions, and lavapipe returns garbage for some. The shared
//! modules may use only builtins this test holds bit-exact; the rest are measured and printed,
//! so a new driver's behaviour is known before anyone relies on it.

mod common;
mod gpu_support;

use common::SplitMix64;
use dustdem::backend::gpu::context::context_for_tests;
use dustdem::backend::gpu::shader::{assemble, FloatMode, Source, CAPABILITIES};
use gpu_support::run_probe;

const SAMPLES: usize = 256;

/// A builtin (or operator) as a WGSL expression in `a`, `b`, `c`, its Rust reference and a
/// generator of arguments inside its domain.
struct Builtin {
    name: &'static str,
    wgsl: &'static str,
    rust: fn(f64, f64, f64) -> f64,
    args: fn(&mut SplitMix64) -> [f64; 3],
    /// The shared modules rely on it: it must match the CPU to the bit.
    relied_on: bool,
}

fn wide(r: &mut SplitMix64) -> [f64; 3] {
    let s = |r: &mut SplitMix64| if r.unit() < 0.5 { -1.0 } else { 1.0 };
    [
        s(r) * r.log_uniform(1e-6, 1e6),
        s(r) * r.log_uniform(1e-6, 1e6),
        s(r) * r.log_uniform(1e-6, 1e6),
    ]
}
fn positive(r: &mut SplitMix64) -> [f64; 3] {
    [r.log_uniform(1e-6, 1e6), r.log_uniform(1e-6, 1e6), 0.0]
}
fn angle(r: &mut SplitMix64) -> [f64; 3] {
    [r.uniform(-10.0, 10.0), r.uniform(-10.0, 10.0), 0.0]
}
fn unit_interval(r: &mut SplitMix64) -> [f64; 3] {
    [r.uniform(-0.999, 0.999), r.uniform(0.0, 1.0), 0.0]
}
fn exponent(r: &mut SplitMix64) -> [f64; 3] {
    [r.uniform(-40.0, 40.0), 0.0, 0.0]
}
fn power(r: &mut SplitMix64) -> [f64; 3] {
    [r.uniform(0.1, 10.0), r.uniform(-5.0, 5.0), 0.0]
}
fn above_one(r: &mut SplitMix64) -> [f64; 3] {
    [r.uniform(1.0, 100.0), 0.0, 0.0]
}

fn signum_or_zero(x: f64) -> f64 {
    if x == 0.0 {
        x
    } else {
        x.signum()
    }
}

#[rustfmt::skip]
fn builtins() -> Vec<Builtin> {
    let b = |name, wgsl, rust, args, relied_on| Builtin { name, wgsl, rust, args, relied_on };
    vec![
        b("a + b", "a + b", |a, b, _| a + b, wide, true),
        b("a - b", "a - b", |a, b, _| a - b, wide, true),
        b("a * b", "a * b", |a, b, _| a * b, wide, true),
        b("a / b", "a / b", |a, b, _| a / b, wide, true),
        b("-a", "-a", |a, _, _| -a, wide, true),
        b("sqrt", "sqrt(a)", |a, _, _| a.sqrt(), positive, true),
        b("abs", "abs(a)", |a, _, _| a.abs(), wide, true),
        b("min", "min(a, b)", |a, b, _| a.min(b), wide, true),
        b("max", "max(a, b)", |a, b, _| a.max(b), wide, true),
        b("clamp", "clamp(a, min(b, c), max(b, c))", |a, b, c| a.clamp(b.min(c), b.max(c)), wide, false),
        b("select", "select(a, b, c > 0.0lf)", |a, b, c| if c > 0.0 { b } else { a }, wide, true),
        b("f64(u32)", "f64(u32(abs(a)))", |a, _, _| f64::from(a.abs() as u32), positive, true),
        b("f64(f32)", "f64(f32(a))", |a, _, _| a as f32 as f64, wide, false),
        b("fma", "fma(a, b, c)", |a, b, c| a.mul_add(b, c), wide, false),
        b("inverseSqrt", "inverseSqrt(a)", |a, _, _| 1.0 / a.sqrt(), positive, false),
        b("floor", "floor(a)", |a, _, _| a.floor(), wide, false),
        b("ceil", "ceil(a)", |a, _, _| a.ceil(), wide, false),
        b("trunc", "trunc(a)", |a, _, _| a.trunc(), wide, false),
        b("round", "round(a)", |a, _, _| a.round_ties_even(), wide, false),
        b("fract", "fract(a)", |a, _, _| a - a.floor(), wide, false),
        b("sign", "sign(a)", |a, _, _| signum_or_zero(a), wide, false),
        b("step", "step(a, b)", |a, b, _| if b >= a { 1.0 } else { 0.0 }, wide, false),
        b("mix", "mix(a, b, c)", |a, b, c| a * (1.0 - c) + b * c, unit_interval, false),
        b("exp", "exp(a)", |a, _, _| a.exp(), exponent, false),
        b("exp2", "exp2(a)", |a, _, _| a.exp2(), exponent, false),
        b("log", "log(a)", |a, _, _| a.ln(), positive, false),
        b("log2", "log2(a)", |a, _, _| a.log2(), positive, false),
        b("pow", "pow(a, b)", |a, b, _| a.powf(b), power, false),
        b("sin", "sin(a)", |a, _, _| a.sin(), angle, false),
        b("cos", "cos(a)", |a, _, _| a.cos(), angle, false),
        b("tan", "tan(a)", |a, _, _| a.tan(), angle, false),
        b("asin", "asin(a)", |a, _, _| a.asin(), unit_interval, false),
        b("acos", "acos(a)", |a, _, _| a.acos(), unit_interval, false),
        b("atan", "atan(a)", |a, _, _| a.atan(), angle, false),
        b("atan2", "atan2(a, b)", |a, b, _| a.atan2(b), angle, false),
        b("sinh", "sinh(a)", |a, _, _| a.sinh(), angle, false),
        b("cosh", "cosh(a)", |a, _, _| a.cosh(), angle, false),
        b("tanh", "tanh(a)", |a, _, _| a.tanh(), angle, false),
        b("asinh", "asinh(a)", |a, _, _| a.asinh(), angle, false),
        b("acosh", "acosh(a)", |a, _, _| a.acosh(), above_one, false),
        b("atanh", "atanh(a)", |a, _, _| a.atanh(), unit_interval, false),
        b("degrees", "degrees(a)", |a, _, _| a.to_degrees(), angle, false),
        b("radians", "radians(a)", |a, _, _| a.to_radians(), angle, false),
    ]
}

/// naga's verdict on the expression alone, with the device's capabilities.
fn naga_accepts(wgsl: &str) -> Result<(), String> {
    let source = format!("fn f(a: f64, b: f64, c: f64) -> f64 {{ return {wgsl}; }}");
    let module = naga::front::wgsl::parse_str(&source).map_err(|e| e.message().to_string())?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), CAPABILITIES)
        .validate(&module)
        .map(|_| ())
        .map_err(|e| e.as_inner().to_string())
}

/// A probe with one `case` per accepted builtin; record = [index, a, b, c], result = one f64.
fn probe_source(accepted: &[&Builtin]) -> String {
    let mut cases = String::new();
    for (i, b) in accepted.iter().enumerate() {
        cases.push_str(&format!("        case {i}u: {{ r = {}; }}\n", b.wgsl));
    }
    format!(
        "struct Params {{ cases: u32, in_stride: u32, out_stride: u32 }}
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> inputs: array<f64>;
@group(0) @binding(2) var<storage, read_write> outputs: array<f64>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if id.x >= params.cases {{
        return;
    }}
    let at = id.x * params.in_stride;
    let a = inputs[at + 1u];
    let b = inputs[at + 2u];
    let c = inputs[at + 3u];
    var r = 0.0lf;
    switch u32(inputs[at]) {{
{cases}        default: {{}}
    }}
    outputs[id.x * params.out_stride] = r;
}}
"
    )
}

/// Largest relative error and largest distance in units in the last place.
fn errors(gpu: f64, cpu: f64) -> (f64, u64) {
    if gpu.to_bits() == cpu.to_bits() || (gpu.is_nan() && cpu.is_nan()) || gpu == cpu {
        return (0.0, 0);
    }
    if !gpu.is_finite() || !cpu.is_finite() {
        return (f64::INFINITY, u64::MAX);
    }
    let ordered = |x: f64| {
        let bits = x.to_bits() as i64;
        if bits < 0 {
            i64::MIN - bits
        } else {
            bits
        }
    };
    let ulps = ordered(gpu).abs_diff(ordered(cpu));
    let rel = (gpu - cpu).abs() / cpu.abs().max(f64::MIN_POSITIVE);
    (rel, ulps)
}

#[test]
fn f64_builtins_against_rust() {
    let Some(ctx) = context_for_tests() else {
        return;
    };
    let all = builtins();
    let mut rejected = Vec::new();
    let mut accepted = Vec::new();
    for b in &all {
        match naga_accepts(b.wgsl) {
            Ok(()) => accepted.push(b),
            Err(e) => rejected.push((b.name, e)),
        }
    }

    let mut rng = SplitMix64(0xb111_7125);
    let mut inputs = Vec::new();
    let mut expected = Vec::new();
    for (i, b) in accepted.iter().enumerate() {
        for _ in 0..SAMPLES {
            let [x, y, z] = (b.args)(&mut rng);
            inputs.extend([i as f64, x, y, z]);
            expected.push((b.rust)(x, y, z));
        }
    }
    let text: &'static str = Box::leak(probe_source(&accepted).into_boxed_str());
    let source = Source {
        path: "f64 builtins probe (generated)",
        text,
    };
    let assembled = assemble(&source, &[]).unwrap_or_else(|e| panic!("{e}"));
    let modes: &[FloatMode] = match ctx.float_mode {
        FloatMode::Exact => &[FloatMode::Exact, FloatMode::Relaxed],
        FloatMode::Relaxed => &[FloatMode::Relaxed],
    };
    // Per mode, per builtin: (bit-identical samples, max relative error, max ulps).
    let mut results = Vec::new();
    for &mode in modes {
        let module = assembled
            .create_module_as(&ctx, mode)
            .unwrap_or_else(|e| panic!("{e}"));
        let gpu = run_probe(&ctx, &module, &inputs, 4, 1);
        let per_builtin: Vec<(usize, f64, u64)> = (0..accepted.len())
            .map(|i| {
                let range = i * SAMPLES..(i + 1) * SAMPLES;
                let (mut identical, mut rel, mut ulps) = (0, 0.0f64, 0u64);
                for (g, c) in gpu[range.clone()].iter().zip(&expected[range]) {
                    let (r, u) = errors(*g, *c);
                    identical += usize::from(u == 0);
                    rel = rel.max(r);
                    ulps = ulps.max(u);
                }
                (identical, rel, ulps)
            })
            .collect();
        results.push((mode, per_builtin));
    }

    println!(
        "f64 builtins on {}, {SAMPLES} samples each (identical / max rel / max ulps per mode)",
        ctx.summary().name
    );
    let mut inexact_relied_on = Vec::new();
    for (i, b) in accepted.iter().enumerate() {
        let mut line = format!("  {:<12}", b.name);
        let mut worst_ulps = 0;
        let mut worst_rel = 0.0f64;
        for (mode, per_builtin) in &results {
            let (identical, rel, ulps) = per_builtin[i];
            line.push_str(&format!(
                " | {mode:?}: {identical:>3} {rel:>9.2e} {ulps:>20}"
            ));
            worst_ulps = worst_ulps.max(ulps);
            worst_rel = worst_rel.max(rel);
            if b.relied_on && ulps != 0 {
                inexact_relied_on.push(format!("{} ({mode:?}): {ulps} ulps", b.name));
            }
        }
        let verdict = match (worst_ulps, worst_rel) {
            (0, _) => "bit-exact",
            (1..=4, _) => "within 4 ulps",
            (_, r) if r < 1e-12 => "close",
            (_, r) if r < 1e-3 => "f32-grade",
            _ => "UNRELIABLE",
        };
        println!("{line} | {verdict}");
    }
    for (name, why) in &rejected {
        println!("  {name:<12} rejected by naga: {why}");
    }
    assert!(
        inexact_relied_on.is_empty(),
        "builtins the shared modules rely on are not bit-exact here: {}",
        inexact_relied_on.join(", ")
    );
}
