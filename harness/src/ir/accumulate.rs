//! **Accumulation**: the irradiance of a [`VplStore`]'s VPLs, with visibility from a
//! [`ShadowAtlas`], gathered into the interleaved split G-buffer.
//!
//! Reads: [`Interleave`]'s split position and normal, the VPL store, the atlas (any format:
//! rasterised depth or a float atlas written by another pass).
//! Writes: `split_irradiance`. The VPL in slot k lights the split tile `k mod T` (T = n·m
//! tiles; Laine et al. 2007 §5.1), scaled by T; its contribution to a receiver is
//! E = Φ/π · cos θ_v cos θ_r / max(r², d²) · V, with d the clamp distance against the 1/r²
//! singularity.

use bytemuck::{Pod, Zeroable};

use super::atlas::ShadowAtlas;
use super::interleave::{Interleave, INTERLEAVE_WGSL};
use super::store::VplStore;
use crate::gpu::GpuContext;
use crate::passes::{shader_module, uniform_entry};
use crate::Result;

/// GPU layout of `AccumulateParams` in `accumulate.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsData {
    distances: [f32; 4],
}

/// The accumulate pass over one store and one atlas (see the module docs).
pub struct Accumulation {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    /// Kept alive for the bind group.
    _params: wgpu::Buffer,
}

impl Accumulation {
    /// Builds the pass for `store` and `atlas` over `interleave`'s split buffers, clamping
    /// 1/r² at `clamp_distance` (scene units).
    pub fn new(
        gpu: &GpuContext,
        interleave: &Interleave,
        store: &VplStore,
        atlas: &ShadowAtlas,
        clamp_distance: f32,
    ) -> Result<Accumulation> {
        let device = &gpu.device;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulate params"),
            size: std::mem::size_of::<ParamsData>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue.write_buffer(
            &params,
            0,
            bytemuck::bytes_of(&ParamsData {
                distances: [clamp_distance, 0.0, 0.0, 0.0],
            }),
        );
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("accumulate"),
            entries: &[
                VplStore::layout_entry(0, false),
                uniform_entry(1, wgpu::ShaderStages::COMPUTE, false),
            ],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("accumulate"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: store.buffer().as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: params.as_entire_binding(),
                },
            ],
        });
        let source = format!(
            "{INTERLEAVE_WGSL}\n{}\n{}\n{}",
            VplStore::wgsl(1, 0, false),
            ShadowAtlas::wgsl(2),
            include_str!("shaders/accumulate.wgsl")
        );
        let module = shader_module(device, "vpl accumulate", &source);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("vpl accumulate"),
            bind_group_layouts: &[
                Some(interleave.split_layout()),
                Some(&layout),
                Some(atlas.layout()),
            ],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("vpl accumulate"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("accumulate"),
            compilation_options: Default::default(),
            cache: None,
        });
        gpu.check_errors()?;
        Ok(Accumulation {
            pipeline,
            group,
            _params: params,
        })
    }

    /// Records the accumulation (the atlas must be the one this pass was built with).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        interleave: &Interleave,
        atlas: &ShadowAtlas,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("accumulate"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, interleave.split_group(), &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.set_bind_group(2, atlas.group(), &[]);
        interleave.dispatch_split_size(&mut pass);
    }
}
