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
use gibench_harness::kit::passes::{
    bind_buffer, params_entry, read_storage_entry, shader_module, FrameUniforms, GBuffer,
    CAMERA_SLOT, HDR_FORMAT,
};
use gibench_harness::scene::charts::polygon_area;
use gibench_harness::{wgpu, Error, Result};
use glam::Vec3;

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

// The light draws pull these from storage as nine words each (shaders/light_draws.wgsl).
const _: () = assert!(std::mem::size_of::<LeafVertex>() == 9 * 4);

/// The patch leaves as GPU geometry, shared by the light-map and subtraction passes: leaf `t`
/// (its tile) is the vertices [`Leaves::ranges`]`[t]`, a triangle list, each vertex with its
/// position, tile, the patch normal and its (s, t) in the leaf. A patch whose rectangle is its
/// surface gives each leaf two triangles; a chart gives each leaf its triangles clipped to the
/// leaf (nothing where they leave the leaf empty).
pub struct Leaves {
    /// (receiver, node) of each leaf, in tile order.
    pub tiles: Vec<(usize, usize)>,
    /// Each tile's vertices.
    pub ranges: Vec<std::ops::Range<u32>>,
    vertices: wgpu::Buffer,
}

/// The polygon `poly` (points in a leaf's (s, t)) clipped to the unit square.
fn clip_to_unit_square(mut poly: Vec<[f32; 2]>) -> Vec<[f32; 2]> {
    for (axis, keep_above) in [(0, true), (0, false), (1, true), (1, false)] {
        let inside = |p: &[f32; 2]| {
            if keep_above {
                p[axis] >= 0.0
            } else {
                p[axis] <= 1.0
            }
        };
        let bound = if keep_above { 0.0 } else { 1.0 };
        let mut next = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            if inside(&p) {
                next.push(p);
            }
            if inside(&p) != inside(&q) {
                let f = (bound - p[axis]) / (q[axis] - p[axis]);
                next.push([p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])]);
            }
        }
        poly = next;
        if poly.len() < 3 {
            return Vec::new();
        }
    }
    poly
}

/// The triangles of a leaf with `corners` (a rectangle, in order) that `surface` covers, as
/// (s, t) in the leaf, three points each: the leaf's two triangles when `surface` is empty.
pub fn leaf_triangles(corners: [Vec3; 4], surface: &[[Vec3; 3]]) -> Vec<[f32; 2]> {
    let st = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    if surface.is_empty() {
        return [0, 1, 2, 0, 2, 3].iter().map(|&k| st[k]).collect();
    }
    let [a, b, _, d] = corners;
    let (u, v) = (b - a, d - a);
    let (uu, vv) = (u.length_squared(), v.length_squared());
    let mut out = Vec::new();
    for tri in surface {
        let flat = tri
            .iter()
            .map(|p| [(*p - a).dot(u) / uu, (*p - a).dot(v) / vv])
            .collect();
        let poly = clip_to_unit_square(flat);
        // Pieces with no area (a triangle touching the leaf along an edge) are left out.
        let points: Vec<glam::Vec2> = poly.iter().map(|p| glam::Vec2::from(*p)).collect();
        if polygon_area(&points).abs() <= 5e-10 {
            continue;
        }
        for i in 1..poly.len().saturating_sub(1) {
            out.extend([poly[0], poly[i], poly[i + 1]]);
        }
    }
    out
}

impl Leaves {
    /// The leaves of every patch receiver of `db`.
    pub fn new(gpu: &GpuContext, db: &VisibilityDatabase) -> Leaves {
        let mut tiles = Vec::new();
        let mut ranges = Vec::new();
        let mut vertices = Vec::new();
        for (r, receiver) in db.receivers.iter().enumerate() {
            let ReceiverShape::Patch(tree) = &receiver.shape else {
                continue;
            };
            for n in tree.leaves() {
                let tile = tiles.len() as u32;
                tiles.push((r, n));
                let [a, b, c, d] = tree.nodes[n].corners;
                let start = vertices.len() as u32;
                for st in leaf_triangles([a, b, c, d], &tree.surface) {
                    let position = a.lerp(b, st[0]).lerp(d.lerp(c, st[0]), st[1]);
                    vertices.push(LeafVertex {
                        position: position.to_array(),
                        leaf: tile,
                        normal: tree.normal.to_array(),
                        st,
                    });
                }
                ranges.push(start..vertices.len() as u32);
            }
        }
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("barczak leaves"),
            size: (std::mem::size_of_val(vertices.as_slice()) as u64).max(4),
            // Drawn from by the light-map pass, pulled from by the light draws.
            usage: wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue
            .write_buffer(&buffer, 0, bytemuck::cast_slice(&vertices));
        Leaves {
            tiles,
            ranges,
            vertices: buffer,
        }
    }

    /// How many vertices all tiles have.
    pub fn vertex_count(&self) -> u32 {
        self.ranges.last().map_or(0, |r| r.end)
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

/// The bytes of the light-map buffer for `leaves` leaves of `res`² texels; an error naming
/// `light-map-res` when that is more than `limit` (what the device binds).
pub fn buffer_size(leaves: usize, res: u32, limit: u64) -> Result<u64> {
    let size = (leaves as u64 * (res * res) as u64 * 12).max(16);
    if size > limit {
        return Err(Error::param(
            "light-map-res",
            format!(
                "{res}² texels on each of {leaves} leaves need a {} MB light-map buffer, more than this device binds ({} MB); use a lower light-map-res",
                size >> 20,
                limit >> 20
            ),
        ));
    }
    Ok(size)
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
        let size = buffer_size(leaves.tiles.len(), res, gpu.max_storage_buffer())?;
        let texels = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("barczak light maps"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("barczak light-map params"),
            size: 16,
            usage: gibench_harness::kit::passes::PARAMS_USAGE,
            mapped_at_creation: false,
        });
        gpu.queue
            .write_buffer(&params, 0, bytemuck::cast_slice(&[res, 0, 0, 0]));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("barczak light maps"),
            entries: &[
                params_entry(0, wgpu::ShaderStages::FRAGMENT),
                read_storage_entry(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("barczak light maps"),
            layout: &layout,
            entries: &[bind_buffer(0, &params), bind_buffer(1, &texels)],
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
        let mut data: Vec<[f32; 3]> =
            Vec::with_capacity(self.leaves.tiles.len() * (self.res * self.res) as usize);
        for &(r, n) in &self.leaves.tiles {
            data.extend(maps.texels(r, n).iter().map(|t| t.to_array()));
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
        pass.draw(0..self.leaves.vertex_count(), 0..1);
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::visibility::PatchTree;

    fn area(st: &[[f32; 2]]) -> f32 {
        st.chunks(3)
            .map(|t| {
                let (a, b, c) = (t[0], t[1], t[2]);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
            })
            .sum()
    }

    /// A chart's triangles clipped to the leaves of its 2 × 2 split: every piece inside its
    /// leaf and wound the same way, the pieces' areas adding up to the triangles', and the
    /// L-shaped chart's empty quarter given nothing; a rectangle patch's leaf is two triangles
    /// covering it.
    #[test]
    fn chart_triangles_are_cut_to_each_leaf() {
        let v = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        let corners = [v(0.0, 0.0), v(2.0, 0.0), v(2.0, 2.0), v(0.0, 2.0)];
        // [0,2] × [0,1] and [0,1] × [1,2], the long triangles crossing the leaves' edges.
        let surface = vec![
            [v(0.0, 0.0), v(2.0, 0.0), v(2.0, 1.0)],
            [v(0.0, 0.0), v(2.0, 1.0), v(0.0, 1.0)],
            [v(0.0, 1.0), v(1.0, 1.0), v(1.0, 2.0)],
            [v(0.0, 1.0), v(1.0, 2.0), v(0.0, 2.0)],
        ];
        let tree = PatchTree::new(0, corners, Vec3::Z, 1).with_surface(surface);
        let mut total = 0.0;
        for n in tree.leaves() {
            let c = tree.nodes[n].corners;
            let st = leaf_triangles(c, &tree.surface);
            assert_eq!(st.len() % 3, 0);
            let inside = |x: f32| (-1e-6..=1.0 + 1e-6).contains(&x);
            assert!(st.iter().all(|p| inside(p[0]) && inside(p[1])));
            for t in st.chunks(3) {
                assert!(area(t) >= -1e-6, "a piece turned over");
            }
            // Each leaf is 1 × 1 scene units, so (s, t) area is scene area.
            let a = area(&st);
            if c[0] == v(1.0, 1.0) {
                assert_eq!(st.len(), 0, "the empty quarter got {a}");
            } else {
                assert!((a - 1.0).abs() < 1e-5, "leaf at {}: {a}", c[0]);
            }
            total += a;
        }
        assert!((total - 3.0).abs() < 1e-4, "{total}");
        let whole = leaf_triangles(corners, &[]);
        assert_eq!(whole.len(), 6);
        assert!((area(&whole) - 1.0).abs() < 1e-6);
    }
}
