//! The PRT draw of complex meshes on the GPU (Barczak 2006 §4.4).
//!
//! Reads: each mover's transfer ([`crate::prt::transfer`], uploaded once), its lighting
//! environment ([`PrtPass::set_lighting`], every frame), the movers' meshes and transforms
//! (the harness's `GpuScene` and object uniforms) and the G-buffer's depth.
//! Writes: `target` where a mover is what the camera sees: per vertex Σₖ Tₖ Lₖ (clamped at 0),
//! interpolated. One draw per mover.

use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::passes::{
    bind_buffer, read_storage_entry, shader_module, FrameUniforms, GBuffer, GpuScene, Vertex,
    CAMERA_SLOT, HDR_FORMAT,
};
use gibench_harness::{wgpu, Error, Result};
use glam::Vec3;

use crate::prt::COEFFS;

struct MoverData {
    lighting: wgpu::Buffer,
    group: wgpu::BindGroup,
}

/// See the module docs.
pub struct PrtPass {
    movers: Vec<MoverData>,
    gbuffer_group: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
}

impl PrtPass {
    /// The pass for movers with `transfers` (one list per mover, one entry per vertex of its
    /// mesh). Errors when the adapter cannot read storage buffers in vertex shaders.
    pub fn new(
        gpu: &GpuContext,
        uniforms: &FrameUniforms,
        gbuffer: &GBuffer,
        transfers: &[Vec<[f32; COEFFS]>],
    ) -> Result<PrtPass> {
        let device = &gpu.device;
        if device.limits().max_storage_buffers_per_shader_stage < 2 {
            return Err(Error::Invalid(
                "barczak's PRT draw reads its transfer in the vertex shader; this adapter has too few storage buffers per stage".into(),
            ));
        }
        let vertex = wgpu::ShaderStages::VERTEX;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("barczak prt"),
            entries: &[read_storage_entry(0, vertex), read_storage_entry(1, vertex)],
        });
        let movers = transfers
            .iter()
            .map(|t| {
                let transfer = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("barczak prt transfer"),
                    size: (std::mem::size_of_val(t.as_slice()) as u64).max(4),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                gpu.queue
                    .write_buffer(&transfer, 0, bytemuck::cast_slice(t.as_slice()));
                let lighting = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("barczak prt lighting"),
                    size: (COEFFS * 16) as u64,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("barczak prt"),
                    layout: &layout,
                    entries: &[bind_buffer(0, &transfer), bind_buffer(1, &lighting)],
                });
                MoverData { lighting, group }
            })
            .collect();
        let module = shader_module(device, "barczak prt", include_str!("shaders/prt.wgsl"));
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("barczak prt"),
            bind_group_layouts: &[
                Some(&uniforms.view_layout),
                Some(&uniforms.object_layout),
                Some(&gbuffer.read_layout),
                Some(&layout),
            ],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("barczak prt"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_prt"),
                compilation_options: Default::default(),
                buffers: &[Some(Vertex::LAYOUT)],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_prt"),
                compilation_options: Default::default(),
                targets: &[Some(HDR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        gpu.check_errors()?;
        Ok(PrtPass {
            movers,
            gbuffer_group: gbuffer.read_group.clone(),
            pipeline,
        })
    }

    /// Sets mover `k`'s lighting environment ([`crate::prt::lighting`]).
    pub fn set_lighting(&self, gpu: &GpuContext, k: usize, lighting: &[Vec3; COEFFS]) {
        let data: Vec<[f32; 4]> = lighting.iter().map(|c| [c.x, c.y, c.z, 0.0]).collect();
        gpu.queue
            .write_buffer(&self.movers[k].lighting, 0, bytemuck::cast_slice(&data));
    }

    /// Records one draw per mover into `target` (kept). Returns the draws made.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        target: &wgpu::TextureView,
    ) -> u32 {
        let mut pass = crate::lightmap_pass::color_pass(encoder, "barczak prt", target, false);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(
            0,
            uniforms.views.group(),
            &[uniforms.views.offset(CAMERA_SLOT)],
        );
        pass.set_bind_group(2, &self.gbuffer_group, &[]);
        let mut draws = 0;
        for (k, (mesh, data)) in scene.movers.iter().zip(&self.movers).enumerate() {
            pass.set_bind_group(1, &uniforms.object_group, &[uniforms.object_offset(k + 1)]);
            pass.set_bind_group(3, &data.group, &[]);
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.index_count, 0, 0..1);
            draws += 1;
        }
        draws
    }
}
