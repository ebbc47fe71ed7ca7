//! Reading GPU results back: a storage buffer's floats, a texture's RGB.

use gibench_harness::glam::Vec3;
use gibench_harness::gpu::GpuContext;
use gibench_harness::wgpu;

/// The bytes of `buffer` (COPY_SRC), after every submitted command.
pub fn read_bytes(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<u8> {
    gibench_harness::gpu::image_io::read_buffer(gpu, buffer).expect("buffer read-back")
}

/// The floats of `buffer` (COPY_SRC), after every submitted command.
pub fn read_f32(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Vec<f32> {
    bytemuck::pod_collect_to_vec(&read_bytes(gpu, buffer))
}

/// The RGB of every texel of `texture`, row by row.
pub fn read_rgb(gpu: &GpuContext, texture: &wgpu::Texture) -> Vec<Vec3> {
    gibench_harness::gpu::image_io::read_rgb_f32(gpu, texture)
        .unwrap()
        .into_iter()
        .map(Vec3::from)
        .collect()
}
