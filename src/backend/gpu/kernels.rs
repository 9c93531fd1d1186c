//! Compute pipelines of the engine, built once: one per entry point, each with an explicit
//! layout holding only the bindings of shaders/engine/bindings.wgsl its entry point uses (naga
//! says which), and one bind group per entry point built once per engine. The engine declares
//! more bindings (54) than a device binds per stage (lavapipe: 32 storage buffers on Mesa 22);
//! no pass uses more than [`MAX_BINDINGS_PER_PASS`].

use super::buffers::{Buffers, MAX_BINDINGS_PER_PASS};
use super::context::GpuContext;
use super::layout::{ARGS_REBUILD, WORK_CONTACTS, WORK_PAIRS};
use super::quirks;
use super::shader::{assemble_pass_at, Assembled, FloatMode, ShaderError};
use super::spirv::entry_bindings;

pub use super::interface::Kernel;

impl Kernel {
    /// Where in the `work_args` buffer the indirect dispatch arguments of a pass dispatched
    /// over a work list (or, for the neighbour passes, sized by the drift) are (bytes), or
    /// `None` for a pass dispatched over the monomers.
    pub fn indirect_offset(self) -> Option<u64> {
        let list = match self {
            Kernel::Contacts | Kernel::ForcesCorrections | Kernel::WallContacts => WORK_CONTACTS,
            Kernel::IntegratePairs | Kernel::Forces | Kernel::ContactsPairTests => WORK_PAIRS,
            Kernel::Neighbours | Kernel::NeighboursList => ARGS_REBUILD,
            _ => return None,
        };
        Some(12 * list as u64)
    }
}

/// How the WGSL declares binding `binding`: `var<uniform>` (read-only data every invocation
/// reads at the same address; llvmpipe loads it once per SIMD group, where a storage load is a
/// loop over the lanes) or `var<storage, read_write>`.
pub fn buffer_binding_type(module: &naga::Module, binding: u32) -> wgpu::BufferBindingType {
    let space = module
        .global_variables
        .iter()
        .find(|(_, v)| v.binding.as_ref().map(|b| b.binding) == Some(binding))
        .map(|(_, v)| v.space)
        .unwrap_or_else(|| panic!("binding {binding} is not declared"));
    match space {
        naga::AddressSpace::Uniform => wgpu::BufferBindingType::Uniform,
        naga::AddressSpace::Storage { access } => wgpu::BufferBindingType::Storage {
            read_only: !access.contains(naga::StorageAccess::STORE),
        },
        other => panic!("binding {binding} is in {other:?}"),
    }
}

/// Binding numbers the entry point `entry` of an assembled pass uses, ascending.
pub fn used_bindings(pass: &Assembled, entry: &str) -> Result<Vec<u32>, ShaderError> {
    let (module, info) = pass.validate()?;
    Ok(entry_bindings(&module, &info, entry))
}

#[derive(Debug)]
pub struct Kernels {
    /// Per entry point (in [`Kernel::ALL`] order): its bindings and their layout.
    bindings: Vec<Vec<u32>>,
    layouts: Vec<wgpu::BindGroupLayout>,
    pipelines: Vec<wgpu::ComputePipeline>,
}

impl Kernels {
    /// The engine's kernels; `one_slot_chunk` compiles them for per-slot arrays held in one
    /// binding (`Sizes::one_slot_chunk`).
    pub fn new(ctx: &GpuContext, one_slot_chunk: bool) -> Result<Self, ShaderError> {
        let device = &ctx.device;
        // Each pass validated once: (name, text, naga module, analysis).
        type Validated = (Assembled, naga::Module, naga::valid::ModuleInfo);
        let mut passes: Vec<(&str, Validated)> = Vec::new();
        let summary = ctx.summary();
        let storage_uniforms =
            quirks::recompiles_per_dispatch_with_uniforms(&summary.driver, &summary.driver_info);
        let mut kernels = Kernels {
            bindings: Vec::new(),
            layouts: Vec::new(),
            pipelines: Vec::new(),
        };
        for kernel in Kernel::ALL {
            let (pass, entry) = (kernel.pass(), kernel.entry());
            if !passes.iter().any(|(p, _)| *p == pass) {
                let mut assembled = assemble_pass_at(pass, ctx.precision())?;
                if one_slot_chunk {
                    assembled = assembled.with_one_slot_chunk();
                }
                if storage_uniforms {
                    assembled = assembled.with_storage_uniforms();
                }
                let (module, info) = assembled.validate()?;
                passes.push((pass, (assembled, module, info)));
            }
            let (_, (assembled, naga_module, info)) =
                passes.iter().find(|(p, _)| *p == pass).expect("made");
            let module = &assembled.create_module_for(ctx, ctx.float_mode, Some(entry))?;
            // The same list the exact-mode SPIR-V is renumbered by (spirv::exact_spirv).
            let bindings = entry_bindings(naga_module, info, entry);
            debug_assert!(bindings.len() as u32 <= MAX_BINDINGS_PER_PASS);
            let entries: Vec<wgpu::BindGroupLayoutEntry> = bindings
                .iter()
                .map(|&binding| wgpu::BindGroupLayoutEntry {
                    binding,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: buffer_binding_type(naga_module, binding),
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                })
                .collect();
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(entry),
                entries: &entries,
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            kernels.pipelines.push(device.create_compute_pipeline(
                &wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&pipeline_layout),
                    module,
                    entry_point: Some(entry),
                    // The exact mode's SPIR-V has its overrides applied already.
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: match ctx.float_mode {
                            FloatMode::Relaxed => &assembled.overrides,
                            FloatMode::Exact => &[],
                        },
                        ..Default::default()
                    },
                    cache: None,
                },
            ));
            kernels.bindings.push(bindings);
            kernels.layouts.push(layout);
        }
        Ok(kernels)
    }

    pub fn pipeline(&self, kernel: Kernel) -> &wgpu::ComputePipeline {
        &self.pipelines[kernel as usize]
    }

    /// One bind group of `buffers` per entry point, in [`Kernel::ALL`] order (built once per
    /// engine).
    pub fn bind_groups(&self, device: &wgpu::Device, buffers: &Buffers) -> Vec<wgpu::BindGroup> {
        Kernel::ALL
            .iter()
            .enumerate()
            .map(|(k, kernel)| {
                let entry = kernel.entry();
                let entries: Vec<wgpu::BindGroupEntry> = self.bindings[k]
                    .iter()
                    .map(|&binding| wgpu::BindGroupEntry {
                        binding,
                        resource: buffers.bindings[binding as usize].as_entire_binding(),
                    })
                    .collect();
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(entry),
                    layout: &self.layouts[k],
                    entries: &entries,
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::gpu::interface::Binding;
    use crate::backend::gpu::shader::{assemble_pass, Precision};

    /// The bindings of every entry point at both precisions, from the shaders (no GPU needed).
    fn per_entry_point() -> Vec<(&'static str, Vec<u32>)> {
        Precision::ALL
            .iter()
            .flat_map(|&p| {
                Kernel::ALL.iter().map(move |k| {
                    let assembled = assemble_pass_at(k.pass(), p).unwrap();
                    (k.entry(), used_bindings(&assembled, k.entry()).unwrap())
                })
            })
            .collect()
    }

    #[test]
    fn no_pass_binds_more_than_the_stated_maximum_and_one_reaches_it() {
        let all = per_entry_point();
        for (entry, bindings) in &all {
            let names: Vec<&str> = bindings
                .iter()
                .map(|&b| Binding::ALL[b as usize].name())
                .collect();
            eprintln!("{entry}: {} bindings {names:?}", bindings.len());
        }
        let most = all.iter().map(|(_, b)| b.len()).max().unwrap() as u32;
        assert_eq!(most, MAX_BINDINGS_PER_PASS);
        // The engine as a whole declares more than one pass may bind.
        const _: () = assert!(Binding::COUNT > 32);
    }

    #[test]
    fn workgroup_sizes_are_the_ones_the_dispatches_are_sized_for() {
        use crate::backend::gpu::layout::{
            DIAG_THREADS, MONOMER_GROUP, PAIR_GROUP, REDUCE_BLOCK, WORK_GROUP,
        };
        for kernel in Kernel::ALL {
            let (pass, entry) = (kernel.pass(), kernel.entry());
            let (module, _) = assemble_pass(pass).unwrap().validate().unwrap();
            let size = module
                .entry_points
                .iter()
                .find(|e| e.name == entry)
                .unwrap()
                .workgroup_size[0] as usize;
            let expected = match kernel {
                // Walked over a list with a stride of groups × this size.
                Kernel::Contacts | Kernel::ForcesCorrections | Kernel::WallContacts => WORK_GROUP,
                Kernel::IntegratePairs | Kernel::Forces | Kernel::ContactsPairTests => PAIR_GROUP,
                // One workgroup, whatever its size.
                Kernel::ReduceWallsFinal => size,
                Kernel::ReduceDiagnostics | Kernel::RowSumsFinal => DIAG_THREADS,
                // One workgroup per block of the fixed summation order.
                Kernel::RowSums => REDUCE_BLOCK,
                // ⌈n / MONOMER_GROUP⌉ groups (the host's `groups`, the drift's rebuild size).
                _ => MONOMER_GROUP,
            };
            assert_eq!(size, expected, "{entry}");
        }
    }

    #[test]
    fn every_binding_is_used_by_some_pass() {
        let all = per_entry_point();
        for binding in Binding::ALL {
            let name = binding.name();
            assert!(
                all.iter().any(|(_, used)| used.contains(&(binding as u32))),
                "{name} is bound by no pass"
            );
        }
    }
}
