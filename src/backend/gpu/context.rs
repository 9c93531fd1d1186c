//! Adapter and device: what the simulation needs of the GPU, checked once at start-up.
//!
//! The engine's state is f64 (overlaps of 10⁻¹⁰ cm inside boxes of 10⁻² cm do not survive plain
//! f32), so the engine needs `SHADER_F64` ([`ShaderF64::Required`], the default). Passes compiled
//! at [`super::shader::Precision::Mixed`] need no f64 and run on a device made with
//! [`ShaderF64::Optional`] or [`ShaderF64::Refused`] (the latter makes lavapipe stand in for an
//! adapter without f64, such as every Metal one). Limits are
//! requested as the adapter offers them: wgpu's defaults (8 storage buffers per stage,
//! 128 MiB per binding) are WebGPU's lowest common denominator, and a Vulkan adapter usually
//! has more.

use super::shader::{FloatMode, Precision};
use std::fmt;
use std::sync::{Arc, Mutex};

pub use super::runtime_dir::PrivateRuntimeDir;

/// Features every f64 pass may rely on. Matches [`super::shader::CAPABILITIES`].
pub const REQUIRED_FEATURES: wgpu::Features = wgpu::Features::SHADER_F64;
/// Taken where offered, for the per-pass times of the benchmark (GpuEngine::profile_passes).
pub const TIMING_FEATURES: wgpu::Features =
    wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES);

/// Asked for when a Vulkan adapter offers it: SPIR-V passthrough carries the shaders whose
/// float operations are marked `NoContraction` ([`FloatMode::Exact`]).
pub const EXACT_FLOAT_FEATURES: wgpu::Features = wgpu::Features::PASSTHROUGH_SHADERS;

/// Whether a device is made with f64 in shaders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaderF64 {
    /// Adapters without `SHADER_F64` are unfit.
    Required,
    /// Asked for where the adapter offers it.
    Optional,
    /// Never asked for, even where offered: a device as an adapter without f64 would give.
    Refused,
}

/// Limits below which the passes cannot be laid out at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Requirements {
    /// Storage buffers one compute pass binds at once.
    pub min_storage_buffers_per_shader_stage: u32,
    /// Bytes of the largest array bound as one storage binding [B].
    pub min_storage_buffer_binding_size: u64,
    pub shader_f64: ShaderF64,
}

impl Default for Requirements {
    /// WebGPU's guaranteed minimums: 8 storage buffers per stage, 128 MiB per binding; f64
    /// required.
    fn default() -> Self {
        Requirements {
            min_storage_buffers_per_shader_stage: 8,
            min_storage_buffer_binding_size: 128 << 20,
            shader_f64: ShaderF64::Required,
        }
    }
}

/// Why no device could be made.
#[derive(Debug)]
pub enum ContextError {
    /// The Vulkan loader found no adapter at all.
    NoAdapter,
    /// Adapters exist, none fits; one line per adapter says why.
    NoSuitableAdapter(Vec<String>),
    RequestDevice {
        adapter: String,
        error: wgpu::RequestDeviceError,
    },
}

impl fmt::Display for ContextError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ContextError::NoAdapter => write!(
                f,
                "no Vulkan adapter found (for a software one: apt-get install mesa-vulkan-drivers \
                 libvulkan1)"
            ),
            ContextError::NoSuitableAdapter(reasons) => {
                write!(f, "no adapter has what the simulation needs:")?;
                for r in reasons {
                    write!(f, "\n  {r}")?;
                }
                Ok(())
            }
            ContextError::RequestDevice { adapter, error } => {
                write!(f, "{adapter}: device request failed: {error}")
            }
        }
    }
}

impl std::error::Error for ContextError {}

/// What an adapter is and offers, for logs and run metadata.
#[derive(Clone, Debug)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: wgpu::Backend,
    pub device_type: wgpu::DeviceType,
    pub driver: String,
    pub driver_info: String,
    pub features: wgpu::Features,
    pub limits: wgpu::Limits,
}

/// The summary of `adapter`.
pub fn adapter_summary(adapter: &wgpu::Adapter) -> AdapterSummary {
    let info = adapter.get_info();
    AdapterSummary {
        name: info.name,
        backend: info.backend,
        device_type: info.device_type,
        driver: info.driver,
        driver_info: info.driver_info,
        features: adapter.features(),
        limits: adapter.limits(),
    }
}

impl AdapterSummary {
    /// The float mode a device on this adapter gets.
    pub fn float_mode(&self) -> FloatMode {
        if self.backend == wgpu::Backend::Vulkan && self.features.contains(EXACT_FLOAT_FEATURES) {
            FloatMode::Exact
        } else {
            FloatMode::Relaxed
        }
    }
}

impl fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let l = &self.limits;
        let mib = |b: u64| b as f64 / f64::from(1u32 << 20);
        writeln!(
            f,
            "{} ({:?}, {:?}; driver {} {})",
            self.name, self.backend, self.device_type, self.driver, self.driver_info
        )?;
        writeln!(
            f,
            "  f64 in shaders: {}",
            if self.features.contains(wgpu::Features::SHADER_F64) {
                "yes"
            } else {
                "no"
            }
        )?;
        writeln!(
            f,
            "  float mode: {:?}{}",
            self.float_mode(),
            match self.float_mode() {
                FloatMode::Exact => " (SPIR-V passthrough, NoContraction: bit-exact f64)",
                FloatMode::Relaxed => " (WGSL: the driver may fuse and reassociate)",
            }
        )?;
        if super::quirks::recompiles_per_dispatch_with_uniforms(&self.driver, &self.driver_info) {
            writeln!(
                f,
                "  uniform buffers declared as storage (this lavapipe, before Mesa 23, recompiles \
                 and keeps a pass that reads uniforms at every dispatch)"
            )?;
        }
        writeln!(f, "  features: {:?}", self.features)?;
        writeln!(
            f,
            "  storage buffers per stage {}, storage binding {} B ({:.1} MiB), buffer {:.0} MiB, \
             uniform binding {:.0} KiB",
            l.max_storage_buffers_per_shader_stage,
            l.max_storage_buffer_binding_size,
            mib(l.max_storage_buffer_binding_size),
            mib(l.max_buffer_size),
            l.max_uniform_buffer_binding_size as f64 / 1024.0
        )?;
        write!(
            f,
            "  workgroup ≤ {} invocations ({}×{}×{}), ≤ {} workgroups per dimension, \
             {} B workgroup storage, bind groups {}, immediates {} B",
            l.max_compute_invocations_per_workgroup,
            l.max_compute_workgroup_size_x,
            l.max_compute_workgroup_size_y,
            l.max_compute_workgroup_size_z,
            l.max_compute_workgroups_per_dimension,
            l.max_compute_workgroup_storage_size,
            l.max_bind_groups,
            l.max_immediate_size
        )
    }
}

/// Adapter, device and queue of one simulation.
#[derive(Debug)]
pub struct GpuContext {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// How shaders reach this device; `Exact` wherever the adapter allows it.
    pub float_mode: FloatMode,
    /// Whether the device was made with `SHADER_F64` (f64 passes can run on it).
    pub shader_f64: bool,
    /// Why the device was lost, or the first error it reported outside any error scope
    /// (wgpu's default would panic): the engine turns it into an error at its next read.
    pub failure: Arc<Mutex<Option<String>>>,
}

/// wgpu's default instance without `VALIDATION_INDIRECT_CALL`. That validation (on in release
/// builds too) puts a dispatch of its own before every indirect dispatch, to clamp arguments
/// beyond the device's limits; ours cannot be: every indirect argument is written on the device
/// clamped to `work_groups_max`, the adapter's per-dimension limit (`push_work`, `push_pairs`),
/// and N itself is checked against that limit before any buffer exists. On lavapipe the extra
/// dispatches cost about 25 µs each, seven per step.
fn instance_descriptor() -> wgpu::InstanceDescriptor {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor
        .flags
        .remove(wgpu::InstanceFlags::VALIDATION_INDIRECT_CALL);
    descriptor
}

impl GpuContext {
    /// Picks the best adapter with `SHADER_F64` and the required limits, and makes a device
    /// with every limit the adapter offers.
    pub fn new(requirements: &Requirements) -> Result<Self, ContextError> {
        pollster::block_on(Self::new_async(requirements))
    }

    pub async fn new_async(requirements: &Requirements) -> Result<Self, ContextError> {
        let instance = wgpu::Instance::new(instance_descriptor());
        let adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        if adapters.is_empty() {
            return Err(ContextError::NoAdapter);
        }
        let mut reasons = Vec::new();
        let mut best: Option<wgpu::Adapter> = None;
        for adapter in adapters {
            let summary = adapter_summary(&adapter);
            let unfit = unfit(&summary, requirements);
            if !unfit.is_empty() {
                reasons.push(format!("{}: {}", summary.name, unfit.join("; ")));
                continue;
            }
            let better = best
                .as_ref()
                .is_none_or(|b| rank(summary.device_type) < rank(b.get_info().device_type));
            if better {
                best = Some(adapter);
            }
        }
        let adapter = best.ok_or(ContextError::NoSuitableAdapter(reasons))?;
        let float_mode = adapter_summary(&adapter).float_mode();
        let shader_f64 = match requirements.shader_f64 {
            ShaderF64::Required => true,
            ShaderF64::Optional => adapter.features().contains(REQUIRED_FEATURES),
            ShaderF64::Refused => false,
        };
        let features = match float_mode {
            FloatMode::Exact => EXACT_FLOAT_FEATURES,
            FloatMode::Relaxed => wgpu::Features::empty(),
        } | (adapter.features() & TIMING_FEATURES);
        let features = if shader_f64 {
            features | REQUIRED_FEATURES
        } else {
            features
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("dustdem"),
                required_features: features,
                required_limits: adapter.limits(),
                ..Default::default()
            })
            .await
            .map_err(|error| ContextError::RequestDevice {
                adapter: adapter.get_info().name,
                error,
            })?;
        let failure = Arc::new(Mutex::new(None));
        let lost = Arc::clone(&failure);
        device.set_device_lost_callback(move |reason, message| {
            record_failure(&lost, format!("device lost ({reason:?}): {message}"));
        });
        let errors = Arc::clone(&failure);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            record_failure(&errors, error.to_string());
        }));
        Ok(GpuContext {
            adapter,
            device,
            queue,
            float_mode,
            shader_f64,
            failure,
        })
    }

    /// The arithmetic an engine on this device runs: f64 where the device was made with
    /// `SHADER_F64`, else the mixed precision (`ShaderF64` decides which, `--precision`).
    pub fn precision(&self) -> Precision {
        if self.shader_f64 {
            Precision::Exact
        } else {
            Precision::Mixed
        }
    }

    pub fn summary(&self) -> AdapterSummary {
        adapter_summary(&self.adapter)
    }

    /// The recorded failure, if the device has failed.
    pub fn failure(&self) -> Option<String> {
        self.failure
            .lock()
            .map_or_else(|p| p.into_inner().clone(), |f| f.clone())
    }
}

/// Keeps the first failure: later ones are usually its consequences.
fn record_failure(slot: &Mutex<Option<String>>, message: String) {
    let mut slot = slot.lock().unwrap_or_else(|p| p.into_inner());
    if slot.is_none() {
        *slot = Some(message);
    }
}

/// What `adapter` lacks, one phrase per missing item (empty when it fits).
fn unfit(adapter: &AdapterSummary, requirements: &Requirements) -> Vec<String> {
    let mut missing = Vec::new();
    if requirements.shader_f64 == ShaderF64::Required
        && !adapter.features.contains(REQUIRED_FEATURES)
    {
        missing.push(format!(
            "lacks {:?} (f64 in shaders)",
            REQUIRED_FEATURES - adapter.features
        ));
    }
    let l = &adapter.limits;
    if l.max_storage_buffers_per_shader_stage < requirements.min_storage_buffers_per_shader_stage {
        missing.push(format!(
            "{} storage buffers per shader stage, needs {}",
            l.max_storage_buffers_per_shader_stage,
            requirements.min_storage_buffers_per_shader_stage
        ));
    }
    if l.max_storage_buffer_binding_size < requirements.min_storage_buffer_binding_size {
        missing.push(format!(
            "storage bindings of {} B, needs {} B",
            l.max_storage_buffer_binding_size, requirements.min_storage_buffer_binding_size
        ));
    }
    missing
}

/// Preference among fitting adapters: real GPUs before software rasterisers (the float mode
/// does not enter: every Vulkan adapter offers passthrough).
fn rank(device_type: wgpu::DeviceType) -> u8 {
    match device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

/// For GPU tests: a context, or `None` after a notice when none can be made and `CI` is unset.
///
/// CI installs lavapipe, so there a missing or unfit adapter is a failure: a test that skipped
/// silently would pass without having run.
pub fn context_for_tests() -> Option<GpuContext> {
    context_for_tests_with(ShaderF64::Required)
}

/// As [`context_for_tests`], with f64 in shaders as `shader_f64` says.
pub fn context_for_tests_with(shader_f64: ShaderF64) -> Option<GpuContext> {
    let requirements = Requirements {
        shader_f64,
        ..Requirements::default()
    };
    match GpuContext::new(&requirements) {
        Ok(context) => Some(context),
        Err(e) if std::env::var_os("CI").is_some() => {
            panic!("CI is set, so a GPU is expected (lavapipe), but: {e}")
        }
        Err(e) => {
            eprintln!("notice: GPU test not run: {e}");
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(features: wgpu::Features, limits: wgpu::Limits) -> AdapterSummary {
        AdapterSummary {
            name: "test".into(),
            backend: wgpu::Backend::Vulkan,
            device_type: wgpu::DeviceType::Cpu,
            driver: String::new(),
            driver_info: String::new(),
            features,
            limits,
        }
    }

    #[test]
    fn an_adapter_without_f64_is_unfit_and_says_so() {
        let why = unfit(
            &summary(wgpu::Features::empty(), wgpu::Limits::default()),
            &Requirements::default(),
        );
        assert_eq!(why.len(), 1);
        assert!(why[0].contains("SHADER_F64"), "{why:?}");
        let fits = unfit(
            &summary(wgpu::Features::SHADER_F64, wgpu::Limits::default()),
            &Requirements::default(),
        );
        assert!(fits.is_empty(), "{fits:?}");
        for shader_f64 in [ShaderF64::Optional, ShaderF64::Refused] {
            let needs = Requirements {
                shader_f64,
                ..Requirements::default()
            };
            let fits = unfit(
                &summary(wgpu::Features::empty(), wgpu::Limits::default()),
                &needs,
            );
            assert!(fits.is_empty(), "{shader_f64:?}: {fits:?}");
        }
    }

    #[test]
    fn a_device_made_refusing_f64_has_none() {
        let Some(ctx) = context_for_tests_with(ShaderF64::Refused) else {
            return;
        };
        assert!(!ctx.shader_f64);
        assert!(!ctx.device.features().contains(wgpu::Features::SHADER_F64));
        assert_eq!(ctx.precision(), Precision::Mixed);
    }

    #[test]
    fn small_limits_are_named() {
        let needs = Requirements {
            min_storage_buffers_per_shader_stage: 16,
            min_storage_buffer_binding_size: 1 << 30,
            shader_f64: ShaderF64::Required,
        };
        let why = unfit(
            &summary(wgpu::Features::SHADER_F64, wgpu::Limits::default()),
            &needs,
        )
        .join("; ");
        assert!(
            why.contains("storage buffers per shader stage") && why.contains("storage bindings"),
            "{why}"
        );
    }

    /// Prints what the adapter offers; fails under CI when there is none.
    #[test]
    fn adapter_summary_of_the_test_adapter() {
        let Some(ctx) = context_for_tests() else {
            return;
        };
        let summary = ctx.summary();
        println!("{summary}");
        assert!(summary.features.contains(REQUIRED_FEATURES));
        assert_eq!(ctx.device.limits(), summary.limits);
    }
}
