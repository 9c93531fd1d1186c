//! Every byte between host and device passes here. The host side always speaks the exact
//! layout (f64, `layout.rs`); in the mixed precision the device holds the f32 layout of the
//! same declarations and `transcode` converts on the way (offsets and lengths included).

use super::GpuEngine;
use crate::backend::gpu::interface::Binding;
use crate::backend::gpu::shader::Precision;
use crate::backend::gpu::transcode::{ElementLayout, Transcoder};
use std::borrow::Cow;

impl GpuEngine {
    /// The device's layout of `binding` where it differs from the host's.
    fn transcoding(&self, binding: Binding) -> Option<&'static ElementLayout> {
        (self.precision == Precision::Mixed).then(|| Transcoder::engine().element(binding))
    }

    /// Device offset of host offset `exact` (an element boundary) in `binding`.
    pub(super) fn device_offset(&self, binding: Binding, exact: u64) -> u64 {
        self.transcoding(binding)
            .map_or(exact, |t| t.mixed_offset(exact))
    }

    /// Device bytes of `exact` host bytes of `binding`.
    pub(super) fn device_len(&self, binding: Binding, exact: u64) -> u64 {
        self.transcoding(binding)
            .map_or(exact, |t| t.mixed_bytes(exact))
    }

    /// Host bytes of `binding` as the device holds them.
    pub(super) fn encoded<'a>(&self, binding: Binding, host: &'a [u8]) -> Cow<'a, [u8]> {
        match self.transcoding(binding) {
            Some(t) => Cow::Owned(t.encode(host)),
            None => Cow::Borrowed(host),
        }
    }

    /// Device bytes of `binding` as the host reads them.
    pub(super) fn decoded(&self, binding: Binding, device: Vec<u8>) -> Vec<u8> {
        match self.transcoding(binding) {
            Some(t) => t.decode(&device),
            None => device,
        }
    }

    /// Writes `data` (host layout) at the start of `binding`.
    pub(super) fn write<T: bytemuck::Pod>(&self, binding: Binding, data: &[T]) {
        self.write_at(binding, 0, data);
    }

    /// Writes `data` (host layout) at host offset `exact_offset` of `binding`.
    pub(super) fn write_at<T: bytemuck::Pod>(
        &self,
        binding: Binding,
        exact_offset: u64,
        data: &[T],
    ) {
        if data.is_empty() {
            return;
        }
        let bytes = self.encoded(binding, bytemuck::cast_slice(data));
        self.ctx.queue.write_buffer(
            self.buffers.get(binding),
            self.device_offset(binding, exact_offset),
            &bytes,
        );
    }

    /// The first `count` values of `binding` (host layout), through a staging buffer.
    pub(super) fn read<T: bytemuck::Pod>(&self, binding: Binding, count: usize) -> Vec<T> {
        let exact = (count * std::mem::size_of::<T>()) as u64;
        if exact == 0 {
            return Vec::new();
        }
        let bytes = self.device_len(binding, exact);
        let padded = bytes.next_multiple_of(8);
        let staging = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("state readback"),
            size: padded,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(self.buffers.get(binding), 0, &staging, 0, padded);
        self.ctx.queue.submit([encoder.finish()]);
        // Full-state reads come after a successful read of the small block; a device failing
        // in between is a narrow race, reported here with what failed.
        let raw = self
            .map_counted(&staging, padded)
            .unwrap_or_else(|e| panic!("reading `{}` back from the GPU: {e}", binding.name()));
        let host = self.decoded(binding, raw[..bytes as usize].to_vec());
        bytemuck::pod_collect_to_vec(&host[..exact as usize])
    }
}
