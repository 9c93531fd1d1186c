//! "One definition, two twins": each `shaders/model/<m>.wgsl` mirrors `src/model/<m>.rs`
//! function for function and constant for constant, and every entry point of
//! `shaders/passes/` has a CPU function of the same name or is a GPU-only pass that a named
//! test holds to the CPU's end state (DESIGN.md, "The twins"). These tests hold the two sides in
//! step without a GPU; the probe test (tests/gpu_contact_law_probe/) and the per-pass parity
//! tests (tests/gpu_passes.rs) hold their results in step on one.

use super::layout;
use super::shader::{assemble, Source, MODEL, PASSES};
use crate::model::normal;
use std::collections::BTreeSet;

/// Model modules with no file in `src/model/`: `math` mirrors glam's DVec3 methods.
const NOT_IN_MODEL: &[&str] = &["math"];

/// Names of the functions declared at the start of a line as `<prefix>name(`.
fn declared(text: &str, prefix: &str) -> BTreeSet<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix(prefix))
        .filter_map(|rest| rest.split_once('('))
        .map(|(name, _)| name.trim().to_string())
        .collect()
}

/// Parameter names, in order, of the first `fn name(` in `text`.
fn parameters(text: &str, name: &str) -> Option<Vec<String>> {
    let open = format!("fn {name}(");
    let start = text.find(&open)? + open.len();
    let mut names = Vec::new();
    let mut depth = 0;
    let mut from = start;
    for (i, ch) in text[start..].char_indices() {
        let at = start + i;
        match ch {
            '(' | '<' => depth += 1,
            ')' if depth == 0 => {
                names.push(&text[from..at]);
                break;
            }
            ')' | '>' => depth -= 1,
            ',' if depth == 0 => {
                names.push(&text[from..at]);
                from = at + 1;
            }
            _ => {}
        }
    }
    Some(
        names
            .into_iter()
            .filter_map(|p| p.split(':').next())
            .map(|p| p.trim().to_string())
            .filter(|p| !p.is_empty())
            .collect(),
    )
}

fn rust_model_file(module: &str) -> String {
    let path = format!("{}/src/model/{module}.rs", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn modelled() -> impl Iterator<Item = &'static Source> {
    MODEL.iter().filter(|m| !NOT_IN_MODEL.contains(&m.name()))
}

#[test]
fn every_wgsl_function_has_a_rust_twin() {
    let mut missing = Vec::new();
    for module in modelled() {
        let rust = rust_model_file(module.name());
        let public = declared(&rust, "pub fn ");
        for name in declared(module.text, "fn ") {
            if !public.contains(&name) {
                missing.push(format!(
                    "{}: fn {name} has no `pub fn {name}(` in src/model/{}.rs",
                    module.path,
                    module.name()
                ));
            }
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

#[test]
fn every_rust_function_has_a_wgsl_twin() {
    let mut missing = Vec::new();
    for module in modelled() {
        let wgsl = declared(module.text, "fn ");
        let rust = rust_model_file(module.name());
        for name in declared(&rust, "pub fn ").union(&declared(&rust, "fn ")) {
            if !wgsl.contains(name) {
                missing.push(format!(
                    "src/model/{}.rs: fn {name} has no twin in {}",
                    module.name(),
                    module.path
                ));
            }
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

#[test]
fn twins_take_the_same_parameters_in_the_same_order() {
    let mut differ = Vec::new();
    for module in modelled() {
        let rust = rust_model_file(module.name());
        for name in declared(module.text, "fn ") {
            let wgsl = parameters(module.text, &name);
            let cpu = parameters(&rust, &name);
            if wgsl != cpu {
                differ.push(format!(
                    "{}: fn {name}{:?} vs src/model/{}.rs: {:?}",
                    module.path,
                    wgsl.unwrap_or_default(),
                    module.name(),
                    cpu.unwrap_or_default()
                ));
            }
        }
    }
    assert!(differ.is_empty(), "{}", differ.join("\n"));
}

#[test]
fn parameter_lists_are_read_across_lines_and_generics() {
    let text = "pub fn f(\n    a: DVec3,\n    b: Option<(f64, f64)>,\n    c: vec3<f64>,\n) -> (f64, f64) {";
    assert_eq!(parameters(text, "f").unwrap(), ["a", "b", "c"]);
    assert_eq!(
        parameters("fn g() -> f64", "g").unwrap(),
        Vec::<String>::new()
    );
    assert_eq!(parameters("fn g() -> f64", "h"), None);
}

#[test]
fn every_model_file_has_a_wgsl_module() {
    let dir = format!("{}/src/model", env!("CARGO_MANIFEST_DIR"));
    for entry in std::fs::read_dir(dir).unwrap() {
        let file = entry.unwrap().file_name().into_string().unwrap();
        let Some(name) = file.strip_suffix(".rs") else {
            continue;
        };
        if name != "mod" {
            assert!(
                MODEL.iter().any(|m| m.name() == name),
                "src/model/{file} has no shaders/model/{name}.wgsl"
            );
        }
    }
}

fn module(name: &str) -> naga::Module {
    let source = MODEL.iter().find(|m| m.name() == name).unwrap();
    let (module, _) = assemble(source, MODEL).unwrap().validate().unwrap();
    module
}

fn constant(module: &naga::Module, name: &str) -> naga::Literal {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL const {name}"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(literal) => literal,
        ref other => panic!("const {name} is not a literal: {other:?}"),
    }
}

#[test]
fn normal_constants_equal_their_rust_twins_to_the_bit() {
    let m = module("normal");
    for (name, rust) in [
        ("X_MIN", normal::X_MIN),
        ("Y_MIN", normal::Y_MIN),
        ("D_MIN", normal::D_MIN),
        ("X_AT_ZERO_OVERLAP", normal::X_AT_ZERO_OVERLAP),
    ] {
        match constant(&m, name) {
            naga::Literal::F64(v) => assert_eq!(
                v.to_bits(),
                rust.to_bits(),
                "{name}: WGSL {v:e} vs Rust {rust:e}"
            ),
            other => panic!("{name} is not an f64 literal: {other:?}"),
        }
    }
}

#[test]
fn damping_tags_and_layout_match_the_host_encoding() {
    let m = module("damping");
    for (name, rust) in [
        ("DAMPING_NONE", layout::DAMPING_NONE),
        ("DAMPING_VISCOUS", layout::DAMPING_VISCOUS),
        ("DAMPING_VISCOELASTIC", layout::DAMPING_VISCOELASTIC),
    ] {
        assert_eq!(constant(&m, name), naga::Literal::U32(rust), "{name}");
    }
    let (_, ty) = m
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some("Damping"))
        .expect("WGSL struct Damping");
    let naga::TypeInner::Struct { ref members, span } = ty.inner else {
        panic!("Damping is not a struct");
    };
    let offsets: Vec<_> = members
        .iter()
        .map(|m| (m.name.clone().unwrap(), m.offset))
        .collect();
    assert_eq!(
        offsets,
        [("kind".to_string(), 0), ("value".to_string(), 8)],
        "WGSL Damping fields"
    );
    assert_eq!(span as usize, std::mem::size_of::<layout::GpuDamping>());
    assert_eq!(std::mem::offset_of!(layout::GpuDamping, kind), 0);
    assert_eq!(std::mem::offset_of!(layout::GpuDamping, value), 8);
}

/// Where the CPU twins of the entry points are: the CPU backend's passes (the executor runs
/// each by its entry point's name), and the fixed reduction order in the state.
const CPU_TWIN_FILES: &[&str] = &[
    "src/backend/cpu/passes/integrate.rs",
    "src/backend/cpu/passes/neighbours.rs",
    "src/backend/cpu/passes/scan.rs",
    "src/backend/cpu/passes/contacts.rs",
    "src/backend/cpu/passes/forces.rs",
    "src/backend/cpu/passes/walls.rs",
    "src/backend/cpu/executor.rs",
    "src/state/reduction.rs",
    "src/state/rows.rs",
];

/// The tests that run each entry point and its CPU twin from the same state and compare what
/// they write: a test named after the entry point in tests/gpu_passes/by_pass.rs, except for
/// the read passes, whose twins are functions of the state, held by these (file, test).
const READ_PASS_TESTS: &[(&str, &str, &str)] = &[
    (
        "reduce_diagnostics",
        "tests/gpu_passes.rs",
        "reductions_match_their_cpu_twin_to_the_bit",
    ),
    (
        "row_sums",
        "tests/gpu_rows.rs",
        "row_kernels_match_their_cpu_twins_to_the_bit",
    ),
    (
        "row_sums_final",
        "tests/gpu_rows.rs",
        "row_kernels_match_their_cpu_twins_to_the_bit",
    ),
    (
        "row_profile",
        "tests/gpu_rows.rs",
        "row_kernels_match_their_cpu_twins_to_the_bit",
    ),
    (
        "row_profile_final",
        "tests/gpu_rows.rs",
        "row_kernels_match_their_cpu_twins_to_the_bit",
    ),
    (
        "row_raster",
        "tests/gpu_rows.rs",
        "row_kernels_match_their_cpu_twins_to_the_bit",
    ),
    (
        "row_area",
        "tests/gpu_rows.rs",
        "row_kernels_match_their_cpu_twins_to_the_bit",
    ),
];

/// Names of the functions marked `@compute` in `text`.
fn entry_points(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim_start().starts_with("@compute") {
            let declaration = lines.find(|l| l.trim_start().starts_with("fn ")).unwrap();
            names.extend(declared(declaration.trim_start(), "fn "));
        }
    }
    names
}

fn read(path: &str) -> String {
    let full = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("{full}: {e}"))
}

#[test]
fn every_entry_point_has_a_cpu_twin_and_a_pass_test() {
    let cpu: BTreeSet<String> = CPU_TWIN_FILES
        .iter()
        .flat_map(|f| {
            let text = read(f);
            declared(&text, "pub fn ")
                .union(&declared(&text, "    pub fn "))
                .cloned()
                .collect::<Vec<_>>()
        })
        .collect();
    let by_pass = read("tests/gpu_passes/by_pass.rs");
    let entries: Vec<String> = PASSES.iter().flat_map(|p| entry_points(p.text)).collect();
    assert_eq!(
        entries.len(),
        super::interface::Kernel::COUNT,
        "{entries:?}"
    );
    let mut wrong = Vec::new();
    for name in &entries {
        if !cpu.contains(name) {
            wrong.push(format!("{name}: no `pub fn {name}(` in {CPU_TWIN_FILES:?}"));
        }
        let held = match READ_PASS_TESTS.iter().find(|(n, _, _)| n == name) {
            Some((_, file, test)) => read(file).contains(&format!("fn {test}(")),
            None => by_pass.contains(&format!("\nfn {name}() {{")),
        };
        if !held {
            wrong.push(format!("{name}: no test runs it beside its twin"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The mixed mode's WGSL (shaders/mixed/) against src/mixed/: every function has a Rust twin,
/// a free function of the same name or a method `Type::m` written `type_m` (`DoubleF32::add_f32`
/// is `double_f32_add_f32`); `math32` mirrors glam's Vec3.
#[test]
fn every_mixed_wgsl_function_has_a_rust_twin() {
    use super::shader::MIXED;
    for module in MIXED.iter().filter(|m| m.name() != "math32") {
        let path = format!(
            "{}/src/mixed/{}.rs",
            env!("CARGO_MANIFEST_DIR"),
            module.name()
        );
        let rust = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let free = declared(&rust, "pub fn ");
        let methods = declared(&rust, "    pub fn ");
        let types: Vec<String> = rust
            .lines()
            .filter_map(|l| l.strip_prefix("impl "))
            .map(|t| t.trim_end_matches(" {").to_string())
            .collect();
        for name in declared(module.text, "fn ") {
            let twin = free.contains(&name)
                || types.iter().any(|t| {
                    let snake = snake_case(t);
                    name.strip_prefix(&format!("{snake}_"))
                        .is_some_and(|m| methods.contains(m))
                });
            assert!(twin, "{}: {name} has no twin in {path}", module.path);
        }
    }
}

/// `DoubleF32` → `double_f32`, `SplitPosition` → `split_position`.
fn snake_case(camel: &str) -> String {
    let mut out = String::new();
    for (i, c) in camel.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}
