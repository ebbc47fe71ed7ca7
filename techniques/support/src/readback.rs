//! Reading GPU results back: a storage buffer's floats, a texture's RGB.

use gibench_harness::glam::Vec3;
use gibench_harness::gpu::GpuContext;
use gibench_harness::wgpu;

/// The bytes of `buffer` (COPY_SRC), after every submitted command.
pub fn read_bytes(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<u8> {
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    gpu.queue.submit([enc.finish()]);
    let slice = staging.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    gpu.flush().unwrap();
    let bytes = slice.get_mapped_range().unwrap().to_vec();
    staging.unmap();
    bytes
}

/// The floats of `buffer` (COPY_SRC), after every submitted command.
pub fn read_f32(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<f32> {
    bytemuck::pod_collect_to_vec(&read_bytes(gpu, buffer))
}

/// The RGB of every texel of `texture`, row by row.
pub fn read_rgb(gpu: &GpuContext, texture: &wgpu::Texture) -> Vec<Vec3> {
    gibench_harness::image_io::read_rgb_f32(gpu, texture)
        .unwrap()
        .into_iter()
        .map(Vec3::from)
        .collect()
}
