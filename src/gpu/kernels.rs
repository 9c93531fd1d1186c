//! Compute pipelines of the engine, built once: one per entry point, all with the same explicit
//! layout (one bind group of read-write storage buffers, shaders/engine/bindings.wgsl), so the
//! step script binds the state once per compute pass.

use super::buffers::{Buffers, BINDINGS};
use super::context::GpuContext;
use super::shader::{assemble_pass, ShaderError};

/// Entry points in step order, with the pass file (without `.wgsl`) that holds each.
pub const ENTRY_POINTS: [(&str, &str); 15] = [
    ("integrate", "integrate_kick"),
    ("integrate", "integrate"),
    ("integrate", "integrate_drift"),
    ("neighbours", "neighbours_clear"),
    ("neighbours", "neighbours"),
    ("neighbours", "neighbours_list"),
    ("contacts", "contacts"),
    ("forces", "forces"),
    ("walls", "wall_forces"),
    ("reduce", "reduce_walls"),
    ("reduce", "reduce_walls_final"),
    ("reduce", "reduce_diagnostics"),
    ("integrate", "integrate_start"),
    ("integrate", "integrate_clear_work"),
    ("contacts", "contacts_clear_tally"),
];

/// Index of an entry point in [`ENTRY_POINTS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    IntegrateKick = 0,
    Integrate,
    IntegrateDrift,
    NeighboursClear,
    Neighbours,
    NeighboursList,
    Contacts,
    Forces,
    WallForces,
    ReduceWalls,
    ReduceWallsFinal,
    ReduceDiagnostics,
    IntegrateStart,
    IntegrateClearWork,
    ContactsClearTally,
}

#[derive(Debug)]
pub struct Kernels {
    pub layout: wgpu::BindGroupLayout,
    pipelines: Vec<wgpu::ComputePipeline>,
}

impl Kernels {
    pub fn new(ctx: &GpuContext) -> Result<Self, ShaderError> {
        let device = &ctx.device;
        let entries: Vec<wgpu::BindGroupLayoutEntry> = (0..BINDINGS.len() as u32)
            .map(|binding| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("engine state"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("engine"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let mut modules: Vec<(&str, wgpu::ShaderModule)> = Vec::new();
        let mut pipelines = Vec::new();
        for (pass, entry) in ENTRY_POINTS {
            if !modules.iter().any(|(p, _)| *p == pass) {
                let module = assemble_pass(pass)?.create_module(ctx)?;
                modules.push((pass, module));
            }
            let module = &modules.iter().find(|(p, _)| *p == pass).expect("made").1;
            pipelines.push(
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&pipeline_layout),
                    module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                }),
            );
        }
        Ok(Kernels { layout, pipelines })
    }

    pub fn pipeline(&self, kernel: Kernel) -> &wgpu::ComputePipeline {
        &self.pipelines[kernel as usize]
    }

    /// The bind group of `buffers` (built once per engine).
    pub fn bind_group(&self, device: &wgpu::Device, buffers: &Buffers) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .bindings
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("engine state"),
            layout: &self.layout,
            entries: &entries,
        })
    }
}
