//! Every pass and probe reaches every backend's compiler: naga writes it as SPIR-V (Vulkan),
//! HLSL (DX12) and MSL (Metal), so a construct one of them cannot take fails here, on a machine
//! without that hardware.
//!
//! At `Precision::Exact` (f64) SPIR-V and HLSL must take every pass. Metal has no f64 (naga's
//! MSL writer stops at an f64 type as unreachable), so an f64 pass is never written as MSL: on
//! Metal the passes run at `Precision::Mixed`, and there all three writers must take every pass,
//! whose types must hold no f64.

use dustdem::backend::gpu::shader::{self, Precision, Source};

fn every_pass() -> impl Iterator<Item = &'static Source> {
    shader::PASSES.iter().chain(shader::PROBES)
}

/// A pass assembled at one precision and validated, with whether its assembled source (the
/// pass and the modules it imports) names f64.
struct Validated {
    module: naga::Module,
    info: naga::valid::ModuleInfo,
    source_names_f64: bool,
}

/// The pass at `precision`, validated, with its overrides applied as the engine's pipelines
/// apply them: once with their defaults and once for per-slot arrays in one binding.
fn validated(pass: &Source, precision: Precision) -> Vec<Validated> {
    let assembled = shader::assemble(pass, &shader::modules_at(precision))
        .unwrap_or_else(|e| panic!("{e}"))
        .with_precision(precision);
    [assembled.clone(), assembled.with_one_slot_chunk()]
        .iter()
        .map(|a| {
            let (module, info) = a.validate().unwrap_or_else(|e| panic!("{e}"));
            let (module, info) = a
                .with_overrides_applied(&module, &info, None)
                .unwrap_or_else(|e| panic!("{e}"));
            let source_names_f64 = a.source.contains("f64");
            Validated {
                module,
                info,
                source_names_f64,
            }
        })
        .collect()
}

fn hlsl(module: &naga::Module, info: &naga::valid::ModuleInfo) -> Result<String, String> {
    let options = naga::back::hlsl::Options {
        shader_model: naga::back::hlsl::ShaderModel::V6_0,
        ..Default::default()
    };
    let mut text = String::new();
    let pipeline = naga::back::hlsl::PipelineOptions::default();
    let mut writer = naga::back::hlsl::Writer::new(&mut text, &options, &pipeline);
    writer
        .write(module, info, None)
        .map(|_| ())
        .map_err(|e| e.to_string())?;
    Ok(text)
}

fn msl(module: &naga::Module, info: &naga::valid::ModuleInfo) -> Result<String, String> {
    let options = naga::back::msl::Options {
        lang_version: (2, 4),
        ..Default::default()
    };
    let pipeline = naga::back::msl::PipelineOptions::default();
    naga::back::msl::write_string(module, info, &options, &pipeline)
        .map(|(text, _)| text)
        .map_err(|e| e.to_string())
}

fn spirv(module: &naga::Module, info: &naga::valid::ModuleInfo) -> Result<Vec<u32>, String> {
    naga::back::spv::write_vec(module, info, &naga::back::spv::Options::default(), None)
        .map_err(|e| e.to_string())
}

/// Whether any type of `module` is or holds an f64 scalar.
fn has_f64(module: &naga::Module) -> bool {
    let f64 = naga::Scalar::F64;
    module.types.iter().any(|(_, ty)| match ty.inner {
        naga::TypeInner::Scalar(s) => s == f64,
        naga::TypeInner::Vector { scalar, .. } | naga::TypeInner::Matrix { scalar, .. } => {
            scalar == f64
        }
        _ => false,
    })
}

#[test]
fn every_exact_pass_translates_for_vulkan_and_dx12() {
    for (pass, v) in every_pass().flat_map(|p| {
        validated(p, Precision::Exact)
            .into_iter()
            .map(move |v| (p, v))
    }) {
        let words =
            spirv(&v.module, &v.info).unwrap_or_else(|e| panic!("{}: SPIR-V: {e}", pass.path));
        assert!(words.len() > 100, "{}", pass.path);
        hlsl(&v.module, &v.info).unwrap_or_else(|e| panic!("{}: HLSL: {e}", pass.path));
        // Passes whose assembled source is written in f64 (their own text or the exact engine
        // modules they import) keep it; the probe of the f32 representations has none.
        assert_eq!(
            has_f64(&v.module),
            v.source_names_f64,
            "{}: f64 types",
            pass.path
        );
    }
}

#[test]
fn every_mixed_pass_translates_for_vulkan_dx12_and_metal() {
    for (pass, v) in every_pass().flat_map(|p| {
        validated(p, Precision::Mixed)
            .into_iter()
            .map(move |v| (p, v))
    }) {
        assert!(!has_f64(&v.module), "{}: f64 in a mixed pass", pass.path);
        spirv(&v.module, &v.info).unwrap_or_else(|e| panic!("{}: SPIR-V: {e}", pass.path));
        hlsl(&v.module, &v.info).unwrap_or_else(|e| panic!("{}: HLSL: {e}", pass.path));
        let metal = msl(&v.module, &v.info).unwrap_or_else(|e| panic!("{}: MSL: {e}", pass.path));
        assert!(
            metal.contains("kernel void"),
            "{}: no kernel in the MSL",
            pass.path
        );
    }
}
