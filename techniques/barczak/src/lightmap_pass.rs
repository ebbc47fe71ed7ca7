//! The light-map pass on the GPU (Barczak 2006 §4.3.2, the first pass at render time).
//!
//! Reads: the light maps ([`crate::lightmap::LightMaps`], uploaded by [`LightMapPass::upload`]),
//! the patch leaves' geometry (made once from the database's receivers), the camera and the
//! G-buffer's depth.
//! Writes: `target` (Rgba16Float irradiance): cleared, then at every pixel showing a patch leaf
//! the leaf's light map, bilinear between texel centres and clamped inside the leaf; zero
//! elsewhere. One draw for all leaves.
//!
//! The subtraction of occluded partial lights (the second pass) is [`crate::light_draws`].

use bytemuck::{Pod, Zeroable};
use gibench_harness::gpu::GpuContext;
use gibench_harness::passes::{
    params_entry, shader_module, FrameUniforms, GBuffer, CAMERA_SLOT, HDR_FORMAT,
};
use gibench_harness::{wgpu, Result};

use crate::database::{ReceiverShape, VisibilityDatabase};
use crate::lightmap::LightMaps;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct LeafVertex {
    position: [f32; 3],
    leaf: u32,
    normal: [f32; 3],
    st: [f32; 2],
}

/// The patch leaves as GPU geometry, shared by the light-map and subtraction passes: leaf `t`
/// (its tile) is vertices `6t .. 6t + 6`, two triangles, each vertex with its position, tile,
/// the patch normal and its (s, t) in the leaf.
pub struct Leaves {
    /// (receiver, node) of each leaf, in tile order.
    pub tiles: Vec<(usize, usize)>,
    vertices: wgpu::Buffer,
}

impl Leaves {
    /// The leaves of every patch receiver of `db`.
    pub fn new(gpu: &GpuContext, db: &VisibilityDatabase) -> Leaves {
        let mut tiles = Vec::new();
        let mut vertices = Vec::new();
        for (r, receiver) in db.receivers.iter().enumerate() {
            let ReceiverShape::Patch(tree) = &receiver.shape else {
                continue;
            };
            for n in tree.leaves() {
                let tile = tiles.len() as u32;
                tiles.push((r, n));
                let c = tree.nodes[n].corners;
                let st = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
                for k in [0, 1, 2, 0, 2, 3] {
                    vertices.push(LeafVertex {
                        position: c[k].to_array(),
                        leaf: tile,
                        normal: tree.normal.to_array(),
                        st: st[k],
                    });
                }
            }
        }
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("barczak leaves"),
            size: (std::mem::size_of_val(vertices.as_slice()) as u64).max(4),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue
            .write_buffer(&buffer, 0, bytemuck::cast_slice(&vertices));
        Leaves {
            tiles,
            vertices: buffer,
        }
    }

    /// The vertex buffer.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.vertices
    }

    /// Its layout: 0 position, 1 tile, 2 normal, 3 (s, t).
    pub fn layout() -> wgpu::VertexBufferLayout<'static> {
        const ATTRIBUTES: [wgpu::VertexAttribute; 4] =
            wgpu::vertex_attr_array![0 => Float32x3, 1 => Uint32, 2 => Float32x3, 3 => Float32x2];
        wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<LeafVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &ATTRIBUTES,
        }
    }
}

/// A render pass into the one colour target `view`, cleared to zero first or kept: how every
/// Barczak pass draws into the irradiance.
pub(crate) fn color_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    view: &wgpu::TextureView,
    clear: bool,
) -> wgpu::RenderPass<'e> {
    target_pass(encoder, label, view, clear, None)
}

/// [`color_pass`] with a read-only depth attachment `depth` when given (the low-resolution
/// pass's edge mask).
pub(crate) fn target_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    view: &wgpu::TextureView,
    clear: bool,
    depth: Option<&wgpu::TextureView>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: if clear {
                    wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
                } else {
                    wgpu::LoadOp::Load
                },
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: None,
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// See the module docs.
pub struct LightMapPass {
    res: u32,
    leaves: std::sync::Arc<Leaves>,
    texels: wgpu::Buffer,
    group: wgpu::BindGroup,
    gbuffer_group: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
}

impl LightMapPass {
    /// The pass for `leaves` (of `db`), with maps of `maps.res`² texels.
    pub fn new(
        gpu: &GpuContext,
        uniforms: &FrameUniforms,
        gbuffer: &GBuffer,
        leaves: std::sync::Arc<Leaves>,
        maps: &LightMaps,
    ) -> Result<LightMapPass> {
        let device = &gpu.device;
        let res = maps.res;
        let texels = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("barczak light maps"),
            size: (leaves.tiles.len() as u64 * (res * res) as u64 * 16).max(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("barczak light-map params"),
            size: 16,
            usage: gibench_harness::passes::PARAMS_USAGE,
            mapped_at_creation: false,
        });
        gpu.queue
            .write_buffer(&params, 0, bytemuck::cast_slice(&[res, 0, 0, 0]));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("barczak light maps"),
            entries: &[
                params_entry(0, wgpu::ShaderStages::FRAGMENT),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("barczak light maps"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: texels.as_entire_binding(),
                },
            ],
        });
        let module = shader_module(
            device,
            "barczak light maps",
            include_str!("shaders/lightmap.wgsl"),
        );
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("barczak light maps"),
            bind_group_layouts: &[
                Some(&uniforms.view_layout),
                Some(&gbuffer.read_layout),
                Some(&layout),
            ],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("barczak light maps"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_leaf"),
                compilation_options: Default::default(),
                buffers: &[Some(Leaves::layout())],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_leaf"),
                compilation_options: Default::default(),
                targets: &[Some(HDR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        gpu.check_errors()?;
        let pass = LightMapPass {
            res,
            leaves,
            texels,
            group,
            gbuffer_group: gbuffer.read_group.clone(),
            pipeline,
        };
        pass.upload(gpu, maps);
        Ok(pass)
    }

    /// Writes `maps` (same leaves and resolution) to the GPU.
    pub fn upload(&self, gpu: &GpuContext, maps: &LightMaps) {
        let mut data: Vec<[f32; 4]> =
            Vec::with_capacity(self.leaves.tiles.len() * (self.res * self.res) as usize);
        for &(r, n) in &self.leaves.tiles {
            data.extend(maps.texels(r, n).iter().map(|t| [t.x, t.y, t.z, 0.0]));
        }
        gpu.queue
            .write_buffer(&self.texels, 0, bytemuck::cast_slice(&data));
    }

    /// Records the pass into `target` (see the module docs). Returns the draws made (1).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        uniforms: &FrameUniforms,
        target: &wgpu::TextureView,
    ) -> u32 {
        let mut pass = color_pass(encoder, "barczak light maps", target, true);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(
            0,
            uniforms.views.group(),
            &[uniforms.views.offset(CAMERA_SLOT)],
        );
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.set_bind_group(2, &self.group, &[]);
        pass.set_vertex_buffer(0, self.leaves.buffer().slice(..));
        pass.draw(0..6 * self.leaves.tiles.len() as u32, 0..1);
        1
    }
}
