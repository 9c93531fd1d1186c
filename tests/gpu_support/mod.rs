//! What the GPU-vs-CPU tests share: a one-dispatch runner for probe
//! shaders that map flat f64 records to flat f64 records.

#![allow(dead_code)]

use dustdem::backend::gpu::context::GpuContext;
use wgpu::util::DeviceExt;

/// The probe shaders' uniform: number of records and the two record lengths (in f64s).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    cases: u32,
    in_stride: u32,
    out_stride: u32,
    _pad: u32,
}

/// Runs `module`'s entry point `main` (workgroup size 64, bindings: 0 uniform `Params`,
/// 1 read-only `array<f64>` inputs, 2 `array<f64>` outputs) once per record and reads the
/// outputs back. The layout is explicit: wgpu cannot reflect a SPIR-V passthrough module.
pub fn run_probe(
    ctx: &GpuContext,
    module: &wgpu::ShaderModule,
    inputs: &[f64],
    in_stride: usize,
    out_stride: usize,
) -> Vec<f64> {
    run_records(ctx, module, inputs, in_stride, out_stride, f64::NAN)
}

/// [`run_probe`] for a probe compiled at `Precision::Mixed` (records of f32).
pub fn run_probe_f32(
    ctx: &GpuContext,
    module: &wgpu::ShaderModule,
    inputs: &[f32],
    in_stride: usize,
    out_stride: usize,
) -> Vec<f32> {
    run_records(ctx, module, inputs, in_stride, out_stride, f32::NAN)
}

/// [`run_probe`] for a probe whose records are raw 32-bit words (f32 and i32 bits).
pub fn run_probe_u32(
    ctx: &GpuContext,
    module: &wgpu::ShaderModule,
    inputs: &[u32],
    in_stride: usize,
    out_stride: usize,
) -> Vec<u32> {
    run_records(
        ctx,
        module,
        inputs,
        in_stride,
        out_stride,
        f32::NAN.to_bits(),
    )
}

/// The runner for any record type; `nan` fills the outputs before the dispatch.
fn run_records<T: bytemuck::Pod>(
    ctx: &GpuContext,
    module: &wgpu::ShaderModule,
    inputs: &[T],
    in_stride: usize,
    out_stride: usize,
    nan: T,
) -> Vec<T> {
    assert_eq!(inputs.len() % in_stride, 0);
    let cases = inputs.len() / in_stride;
    let device = &ctx.device;
    let params = Params {
        cases: cases as u32,
        in_stride: in_stride as u32,
        out_stride: out_stride as u32,
        _pad: 0,
    };
    let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe params"),
        contents: bytemuck::bytes_of(&params),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe inputs"),
        contents: bytemuck::cast_slice(inputs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let out_bytes = (cases * out_stride * std::mem::size_of::<T>()) as u64;
    // NaN everywhere a probe forgot to write, so a gap cannot pass as a zero.
    let output = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("probe outputs"),
        contents: bytemuck::cast_slice(&vec![nan; cases * out_stride]),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("probe readback"),
        size: out_bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });

    let buffer = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("probe"),
        entries: &[
            buffer(0, wgpu::BufferBindingType::Uniform),
            buffer(1, wgpu::BufferBindingType::Storage { read_only: true }),
            buffer(2, wgpu::BufferBindingType::Storage { read_only: false }),
        ],
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("probe"),
        bind_group_layouts: &[Some(&bind_group_layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("probe"),
        layout: Some(&layout),
        module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("probe"),
        layout: &bind_group_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: params.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: output.as_entire_binding(),
            },
        ],
    });

    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(cases.div_ceil(64) as u32, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, out_bytes);
    ctx.queue.submit([encoder.finish()]);

    let slice = readback.slice(..);
    slice.map_async(wgpu::MapMode::Read, |r| {
        r.expect("mapping the probe readback")
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("waiting for the probe");
    let view = slice.get_mapped_range().expect("mapped probe readback");
    let values: Vec<T> = bytemuck::pod_collect_to_vec(&view);
    drop(view);
    readback.unmap();
    values
}
