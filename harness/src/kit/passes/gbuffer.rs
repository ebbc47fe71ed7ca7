//! The G-buffer pass.
//!
//! Reads: the scene's meshes, materials and textures; the camera and object uniforms.
//! Writes: `depth` (Depth32Float, reversed Z: 1 at the near plane, 0 = background), `normal`
//! (Rgba16Float: unit normal facing the camera, w = 1 where geometry was hit) and `albedo`
//! (Rgba8UnormSrgb: linear albedo, texture applied).
//!
//! Consumers bind [`GBuffer::read_layout`] / [`GBuffer::read_group`] (camera, depth, normal,
//! albedo) and reconstruct world positions with `world_from_depth` from `common.wgsl`.

use glam::Vec3;

use crate::gpu::GpuContext;
use crate::{Error, Result};

use super::{
    bind_buffer, render_target, shader_module, storage_entry, texture_entry, uniform_entry,
    FrameUniforms, GpuScene, Vertex,
};

pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const ALBEDO_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// The camera G-buffer and the pipeline that fills it.
pub struct GBuffer {
    pub size: [u32; 2],
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
    pub normal: wgpu::Texture,
    pub normal_view: wgpu::TextureView,
    pub albedo: wgpu::Texture,
    pub albedo_view: wgpu::TextureView,
    /// Layout for reading the G-buffer: 0 camera View, 1 depth, 2 normal, 3 albedo.
    pub read_layout: wgpu::BindGroupLayout,
    pub read_group: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
    export_pipeline: wgpu::ComputePipeline,
}

/// The G-buffer copied to the CPU (row-major, top row first).
#[derive(Clone, Debug)]
pub struct GBufferTexels {
    pub size: [u32; 2],
    /// World position per pixel; `None` for background.
    pub positions: Vec<Option<Vec3>>,
    pub normals: Vec<Vec3>,
    pub albedo: Vec<Vec3>,
}

/// A pipeline drawing the scene's meshes (geometry.wgsl) with the shared layouts.
/// A render pipeline drawing scene meshes with `geometry.wgsl`'s `vertex_entry` (and, if given,
/// fragment entry and colour targets) into a [`DEPTH_FORMAT`] reversed-Z depth target (compare
/// Greater, no culling). Groups: 0 a [`super::ViewSet`] view (dynamic offset), 1 the object
/// uniforms (drawn by [`GpuScene::draw`]), 2 the scene's materials.
pub fn scene_pipeline(
    device: &wgpu::Device,
    label: &str,
    scene: &GpuScene,
    uniforms: &FrameUniforms,
    vertex_entry: &str,
    fragment: Option<(&str, &[wgpu::TextureFormat])>,
) -> wgpu::RenderPipeline {
    let module = shader_module(device, label, include_str!("shaders/geometry.wgsl"));
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[
            Some(&uniforms.view_layout),
            Some(&uniforms.object_layout),
            Some(&scene.material_layout),
        ],
        immediate_size: 0,
    });
    let targets: Vec<Option<wgpu::ColorTargetState>> = fragment
        .map(|(_, f)| {
            f.iter()
                .map(|f| {
                    Some(wgpu::ColorTargetState {
                        format: *f,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })
                })
                .collect()
        })
        .unwrap_or_default();
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some(vertex_entry),
            compilation_options: Default::default(),
            buffers: &[Some(Vertex::LAYOUT)],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: fragment.map(|(entry, _)| wgpu::FragmentState {
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Begins a render pass into G-buffer-shaped targets (normal, albedo, reversed-Z depth), all
/// cleared: the camera's G-buffer and the reflective shadow map's faces share it.
pub fn begin_gbuffer_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    normal: &wgpu::TextureView,
    albedo: &wgpu::TextureView,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    let clear = wgpu::Operations {
        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
        store: wgpu::StoreOp::Store,
    };
    let color = |view| {
        Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: clear,
        })
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[color(normal), color(albedo)],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

impl GBuffer {
    pub fn new(gpu: &GpuContext, scene: &GpuScene, uniforms: &FrameUniforms) -> GBuffer {
        let device = &gpu.device;
        let size = uniforms.resolution;
        let depth = render_target(device, "gbuffer depth", size, DEPTH_FORMAT);
        let normal = render_target(device, "gbuffer normal", size, NORMAL_FORMAT);
        let albedo = render_target(device, "gbuffer albedo", size, ALBEDO_FORMAT);
        let (depth_view, normal_view, albedo_view) = (
            depth.create_view(&Default::default()),
            normal.create_view(&Default::default()),
            albedo.create_view(&Default::default()),
        );
        let all = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
        let d2 = wgpu::TextureViewDimension::D2;
        let read_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gbuffer read"),
            entries: &[
                uniform_entry(0, all, false),
                // Depth is read as an unfilterable float texture: GLSL cannot texelFetch a depth sampler.
                texture_entry(1, all, unfilterable, d2),
                texture_entry(2, all, unfilterable, d2),
                texture_entry(3, all, unfilterable, d2),
            ],
        });
        let read_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer read"),
            layout: &read_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniforms.camera_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&depth_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&normal_view),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&albedo_view),
                },
            ],
        });
        let pipeline = scene_pipeline(
            device,
            "gbuffer",
            scene,
            uniforms,
            "vs_main",
            Some(("fs_gbuffer", &[NORMAL_FORMAT, ALBEDO_FORMAT])),
        );
        let export_module = shader_module(
            device,
            "gbuffer export",
            include_str!("shaders/export.wgsl"),
        );
        let storage_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gbuffer export"),
            entries: &[storage_entry(0, false)],
        });
        let export_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer export"),
            bind_group_layouts: &[Some(&read_layout), Some(&storage_layout)],
            immediate_size: 0,
        });
        let export_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("gbuffer export"),
            layout: Some(&export_layout),
            module: &export_module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        GBuffer {
            size,
            depth,
            depth_view,
            normal,
            normal_view,
            albedo,
            albedo_view,
            read_layout,
            read_group,
            pipeline,
            export_pipeline,
        }
    }

    /// Records the G-buffer pass.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
    ) {
        let mut pass = begin_gbuffer_pass(
            encoder,
            "gbuffer",
            &self.normal_view,
            &self.albedo_view,
            &self.depth_view,
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(
            0,
            uniforms.views.group(),
            &[uniforms.views.offset(super::scene_gpu::CAMERA_SLOT)],
        );
        pass.set_bind_group(2, &scene.material_group, &[]);
        scene.draw(&mut pass, uniforms, 1, super::DrawSet::StaticAndMovers);
    }

    /// Copies the current G-buffer to the CPU (flushes the queue; not for timed frames).
    pub fn export(&self, gpu: &GpuContext) -> Result<GBufferTexels> {
        let device = &gpu.device;
        let [w, h] = self.size;
        let bytes = (w * h) as u64 * 48;
        let storage = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gbuffer export"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gbuffer readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer export"),
            layout: &self.export_pipeline.get_bind_group_layout(1),
            entries: &[bind_buffer(0, &storage)],
        });
        let mut enc = device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.export_pipeline);
            pass.set_bind_group(0, &self.read_group, &[]);
            pass.set_bind_group(1, &group, &[]);
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
        enc.copy_buffer_to_buffer(&storage, 0, &readback, 0, bytes);
        gpu.queue.submit([enc.finish()]);
        let slice = readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        gpu.flush()?;
        let data: Vec<f32> =
            bytemuck::pod_collect_to_vec(&gpu.mapped(&slice, "a readback buffer")?[..]);
        readback.unmap();
        if data.len() != (w * h * 12) as usize {
            return Err(Error::Gpu("G-buffer export returned the wrong size".into()));
        }
        let mut out = GBufferTexels {
            size: self.size,
            positions: Vec::new(),
            normals: Vec::new(),
            albedo: Vec::new(),
        };
        for t in data.chunks_exact(12) {
            out.positions
                .push((t[3] != 0.0).then(|| Vec3::new(t[0], t[1], t[2])));
            out.normals.push(Vec3::new(t[4], t[5], t[6]));
            out.albedo.push(Vec3::new(t[8], t[9], t[10]));
        }
        Ok(out)
    }
}
