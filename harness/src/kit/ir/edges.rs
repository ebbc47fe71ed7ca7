//! **Edge mask** for a low-resolution illumination pass (Barczak 2006 §4.3.3).
//!
//! Reads: the G-buffer (positions from depth, normals).
//! Writes (owns): `mask`, one `u32` per pixel (row-major): 1 where the pixel is an edge, 0
//! elsewhere and on background.
//!
//! Illumination on planar surfaces varies slowly, so a technique may compute it at low
//! resolution and interpolate; that leaks across object boundaries, so edges are found and
//! recomputed at full resolution. A pixel is an edge when, for one of its eight neighbours
//! `step` pixels away (clamped to the image), the neighbour shows background, its normal differs
//! (cosine below `normal_cos`), or it lies off the pixel's plane by more than `plane_distance`
//! times their distance: "regions where the plane equations of the underlying surfaces change",
//! stepping several pixels so that the interpolation's footprint is masked too. The thesis
//! writes the mask as depth for an early depth test; here it is a buffer any pass can read.

use bytemuck::{Pod, Zeroable};

use crate::gpu::GpuContext;
use crate::kit::passes::{
    bind_buffer, compute_pipeline, params_buffer, params_entry, storage_entry, GBuffer,
};
use crate::measure::roofline::StageCost;
use crate::{Error, Result};

/// What counts as an edge (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeSettings {
    /// Neighbour distance in pixels (≥ 1).
    pub step: u32,
    /// Normals whose cosine is below this differ.
    pub normal_cos: f32,
    /// A neighbour farther than this × its distance from the pixel's plane is off it.
    pub plane_distance: f32,
}

impl Default for EdgeSettings {
    /// Step 3, normals 18° apart, 2 % off the plane.
    fn default() -> Self {
        EdgeSettings {
            step: 3,
            normal_cos: 0.95,
            plane_distance: 0.02,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsData {
    counts: [u32; 4],
    limits: [f32; 4],
}

/// The edge-mask pass (see the module docs).
pub struct EdgeMask {
    pub settings: EdgeSettings,
    /// The pass's declared minimum cost per frame ([`crate::measure::roofline`]), from the
    /// image's size.
    pub cost: StageCost,
    size: [u32; 2],
    mask: wgpu::Buffer,
    group: wgpu::BindGroup,
    gbuffer_group: wgpu::BindGroup,
    pipeline: wgpu::ComputePipeline,
}

impl EdgeMask {
    /// The pass over `gbuffer`. Errors name the setting out of range.
    pub fn new(gpu: &GpuContext, gbuffer: &GBuffer, settings: EdgeSettings) -> Result<EdgeMask> {
        if !(1..=64).contains(&settings.step) {
            return Err(Error::param(
                "edge-step",
                format!("expected 1..=64 pixels (got {})", settings.step),
            ));
        }
        if !(settings.normal_cos.is_finite()
            && settings.plane_distance.is_finite()
            && settings.plane_distance >= 0.0)
        {
            return Err(Error::param(
                "edge-thresholds",
                "expected finite thresholds, the plane distance ≥ 0",
            ));
        }
        let device = &gpu.device;
        let [w, h] = gbuffer.size;
        let mask = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("edge mask"),
            size: (w as u64 * h as u64 * 4).max(4),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let params = params_buffer(
            gpu,
            "edge mask params",
            &ParamsData {
                counts: [settings.step, 0, 0, 0],
                limits: [settings.normal_cos, settings.plane_distance, 0.0, 0.0],
            },
        );
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("edge mask"),
            entries: &[
                params_entry(0, wgpu::ShaderStages::COMPUTE),
                storage_entry(1, false),
            ],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("edge mask"),
            layout: &layout,
            entries: &[bind_buffer(0, &params), bind_buffer(1, &mask)],
        });
        let pipeline = compute_pipeline(
            device,
            "edge mask",
            include_str!("shaders/edges.wgsl"),
            &[&gbuffer.read_layout, &layout],
            "main",
        );
        gpu.check_errors()?;
        // Per pixel its depth (4 bytes) and normal (Rgba16Float, 8) read once (a neighbour's
        // are its own pixel's: the minimum reads each once) and its mask word written (4); its
        // position rebuilt from depth (32 operations, once: the neighbours' positions are their
        // own pixels'), and per neighbour the offset from it (3), its distance off the plane
        // (5) and its squared length against it (6), the normals' dot product against the
        // threshold (6): 20, eight neighbours (a pixel inside a surface, most of them, tests
        // all eight; an edge may stop sooner) — 192.
        let cost = StageCost::per_element(w as u64 * h as u64, 12, 4, 32 + 8 * 20);
        Ok(EdgeMask {
            cost,
            settings,
            size: gbuffer.size,
            mask,
            group,
            gbuffer_group: gbuffer.read_group.clone(),
            pipeline,
        })
    }

    /// Records the pass.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("edge mask"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.gbuffer_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.dispatch_workgroups(self.size[0].div_ceil(8), self.size[1].div_ceil(8), 1);
    }

    /// The mask buffer (one `u32` per pixel, row-major).
    pub fn mask(&self) -> &wgpu::Buffer {
        &self.mask
    }

    /// The mask copied to the CPU after the queued work (for tests and inspection: it waits for
    /// the GPU and makes a staging buffer, so not for a frame loop).
    pub fn read(&self, gpu: &GpuContext) -> Result<Vec<u32>> {
        let data: Vec<u32> =
            bytemuck::pod_collect_to_vec(&crate::gpu::image_io::read_buffer(gpu, &self.mask)?);
        let [w, h] = self.size;
        Ok(data[..(w * h) as usize].to_vec())
    }
}
