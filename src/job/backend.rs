//! Which backend runs a job: the choice (`--backend`), the GPU context it opens, the CPU
//! reference engine collisions and calibrations run on, and what `info` reports of the GPU.
//! The only module that names a backend.

use super::{JobOptions, RunError};
use crate::backend::cpu::CpuEngine;
use crate::backend::gpu::buffers::Sizes;
use crate::backend::gpu::context::{GpuContext, Requirements, ShaderF64};
use crate::backend::gpu::engine::GpuError;
use crate::config::{Config, ExperimentKind};
use crate::engine::EngineError;
use crate::model::ContactLaw;
use crate::state::{Monomers, Wall};

/// The guard that keeps the GPU probe quiet (a private `XDG_RUNTIME_DIR` where none is usable);
/// the command line takes it before it runs a command that looks for a GPU.
pub use crate::backend::gpu::context::PrivateRuntimeDir;

/// Which engine runs a compression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// The f64 CPU reference.
    Cpu,
    /// The WGSL engine on the best adapter with f64 (an error when there is none).
    Gpu,
    /// A hardware GPU when one fits, else the CPU. A software adapter (lavapipe) is not
    /// chosen: it runs the same shaders several times slower than the CPU reference
    /// (docs/guide/src/benchmarks.md); `Gpu` uses it anyway.
    Auto,
}

impl std::str::FromStr for Backend {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "cpu" => Ok(Backend::Cpu),
            "gpu" => Ok(Backend::Gpu),
            "auto" => Ok(Backend::Auto),
            other => Err(format!("backend `{other}`: expected cpu, gpu or auto")),
        }
    }
}

/// The arithmetic of a GPU run (`--precision`; the CPU reference is always f64).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrecisionChoice {
    /// f64 throughout: the CPU reference's bits; adapters without f64 are refused.
    Exact,
    /// f32 arithmetic with split centres and double-f32 pointers, wall points and tallies
    /// (DESIGN.md, "Precision"), even where the adapter has f64.
    Mixed,
    /// Exact where the adapter has f64, else mixed.
    Auto,
}

impl std::str::FromStr for PrecisionChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "exact" => Ok(PrecisionChoice::Exact),
            "mixed" => Ok(PrecisionChoice::Mixed),
            "auto" => Ok(PrecisionChoice::Auto),
            other => Err(format!(
                "precision `{other}`: expected exact, mixed or auto"
            )),
        }
    }
}

impl PrecisionChoice {
    /// The word `--precision` takes for this choice.
    pub fn as_str(self) -> &'static str {
        match self {
            PrecisionChoice::Exact => "exact",
            PrecisionChoice::Mixed => "mixed",
            PrecisionChoice::Auto => "auto",
        }
    }

    /// The device requirements that give this precision (`GpuContext::precision`).
    pub fn requirements(self) -> Requirements {
        let shader_f64 = match self {
            PrecisionChoice::Exact => ShaderF64::Required,
            PrecisionChoice::Mixed => ShaderF64::Refused,
            PrecisionChoice::Auto => ShaderF64::Optional,
        };
        Requirements {
            shader_f64,
            ..Requirements::default()
        }
    }
}

/// The f64 CPU reference engine, built from an initial state as every engine is (the `build`
/// argument of the experiments). Collisions and calibrations run on it: it is deterministic on
/// every machine, and a GPU would not speed up two monomers or a few hundred.
pub fn reference_engine(
    law: ContactLaw,
    dt: f64,
    monomers: Monomers,
    walls: Vec<Wall>,
    pair_slots: usize,
    wall_slots: usize,
) -> Result<CpuEngine, EngineError> {
    CpuEngine::new(law, dt, monomers, walls, pair_slots, wall_slots)
}

/// The GPU context a job runs on (`None`: the CPU reference), announced through the notice.
pub(super) fn choose_backend(options: &mut JobOptions) -> Result<Option<GpuContext>, RunError> {
    let requirements = options.precision.requirements();
    let context = match options.backend {
        Backend::Cpu => None,
        Backend::Gpu => {
            Some(GpuContext::new(&requirements).map_err(|e| EngineError::from(GpuError::from(e)))?)
        }
        Backend::Auto => match GpuContext::new(&requirements) {
            Ok(ctx) if ctx.summary().device_type == wgpu::DeviceType::Cpu => {
                (options.notice)(&format!(
                    "backend: cpu (f64 reference); the only adapter, {}, is a software \
                     renderer and slower (--backend gpu uses it anyway)",
                    ctx.summary().name
                ));
                return Ok(None);
            }
            found => found.ok(),
        },
    };
    match &context {
        None => (options.notice)("backend: cpu (f64 reference)"),
        Some(ctx) => (options.notice)(&format!(
            "backend: gpu ({}, {:?} float mode, {} precision)",
            ctx.summary().name,
            ctx.float_mode,
            ctx.precision().name()
        )),
    }
    Ok(context)
}

/// What `dustdem info` reports of the GPU backend, one line each: the memory N monomers need
/// under `config`, the adapter it would use and whether N fits there.
pub fn gpu_report(config: &Config, n: usize) -> Vec<String> {
    let walls = if config.experiment.kind == ExperimentKind::Omni {
        6
    } else {
        2
    };
    let sizes = Sizes::new(
        n,
        walls,
        config.integration.pair_slots,
        config.integration.wall_slots,
    );
    let (name, largest) = sizes.largest_binding();
    let mib = |b: u64| b as f64 / f64::from(1u32 << 20);
    let mut lines = vec![format!(
        "gpu memory for N = {n}: {:.1} MiB ({:.0} B per monomer), largest binding `{name}` \
         {:.1} MiB",
        mib(sizes.total_bytes()),
        sizes.bytes_per_monomer(),
        mib(largest)
    )];
    match GpuContext::new(&Requirements::default()) {
        Ok(ctx) => {
            lines.push(format!("gpu: {}", ctx.summary()));
            if ctx.summary().device_type == wgpu::DeviceType::Cpu {
                lines.push(
                    "gpu: software adapter: `--backend auto` runs on the cpu, `--backend gpu` here"
                        .to_string(),
                );
            }
            match sizes.check(&ctx.device.limits()) {
                Ok(()) => lines.push(format!("gpu: N = {n} fits")),
                Err(e) => lines.push(format!("gpu: N = {n} does not fit: {e}")),
            }
        }
        Err(e) => lines.push(format!("gpu: none usable ({e}); runs use the cpu backend")),
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_precision_asks_for_the_device_that_gives_it() {
        let asked = |text: &str| text.parse::<PrecisionChoice>().unwrap().requirements();
        assert_eq!(asked("exact").shader_f64, ShaderF64::Required);
        assert_eq!(asked("mixed").shader_f64, ShaderF64::Refused);
        // auto: f64 where offered, any adapter otherwise (context::unfit takes it).
        assert_eq!(asked("auto").shader_f64, ShaderF64::Optional);
        let error = "f32".parse::<PrecisionChoice>().unwrap_err();
        assert!(
            error.contains("`f32`") && error.contains("exact, mixed or auto"),
            "{error}"
        );
    }
}
