//! **Atlas rasteriser**: renders chosen slots of a depth [`ShadowAtlas`] from a chosen
//! [`DrawSet`] by triangle rasterisation.
//!
//! Reads: the VPLs of the slots to render (a CPU list, or a [`VplStore`] a GPU pass wrote), the
//! scene's meshes ([`GpuScene`]) and object
//! transforms ([`FrameUniforms`]).
//! Writes: its own per-slot view uniforms (uploaded inside the call, so their cost is part of
//! the caller's `vpl-shadow-maps` stage) and those slots' blocks of the atlas. With
//! [`AtlasClear::Whole`] the whole atlas is cleared first (every map empty); with
//! [`AtlasClear::RenderedSlots`] only the rendered slots' blocks are cleared, and every other
//! map is kept as it was.
//!
//! Paraboloid maps are rendered with the VPL's frame in the vertex shader (Brabec et al. 2002)
//! and back-hemisphere fragments discarded; cube maps with one 90° view per face; octahedral
//! maps (Barczak 2006 §4.2) with one pass per octahedron face into the same square, the face's
//! projection in the vertex shader, fragments outside its triangle (widened by a sliver, so
//! neighbouring faces leave no crack) discarded (Barczak clips with user clip planes, which
//! wgpu's GL backend lacks) and the exact distance written as depth. A caller may name the
//! faces to draw per map ([`AtlasRasteriser::render_faces`]; Barczak §4.2.2 skips the
//! octahedral faces holding no occluder, [`super::face_cull`]); the others stay cleared.
//!
//! VPLs a GPU pass wrote into a [`VplStore`] (imperfect shadow maps' RSM-sampled VPLs) are
//! rendered with [`StoreViews`]: a compute pass writes each slot's paraboloid view from the store
//! into the same view uniforms, inside the same stage, with no readback.

use bytemuck::{Pod, Zeroable};
use glam::Mat4;

use super::atlas::{AtlasFormat, MapKind, ShadowAtlas};
use super::store::VplStore;
use crate::cpu::vpl::{frame_from_normal, Vpl};
use crate::gpu::GpuContext;
use crate::kit::passes::{
    bind_buffer, compute_pipeline, cube_face_matrix, shader_module, storage_entry, Bindings, Bound,
    DrawSet, FrameUniforms, GpuScene, Vertex,
};
use crate::measure::roofline::StageCost;
use crate::{Error, Result};

/// What the rasteriser clears before rendering.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AtlasClear {
    /// The whole atlas (every map not rendered now becomes empty).
    Whole,
    /// Only the blocks of the slots rendered now; other maps are kept.
    RenderedSlots,
}

/// GPU layout of `VplView` in `vpl_shadow.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ViewData {
    view_proj: [f32; 16],
    position: [f32; 4],
    tangent: [f32; 4],
    bitangent: [f32; 4],
    normal: [f32; 4],
}

/// Uniform slots are this far apart (the largest minimum dynamic-offset alignment in practice).
const VIEW_STRIDE: u64 = 256;

/// Renders VPL maps into a depth atlas (see the module docs).
pub struct AtlasRasteriser {
    kind: MapKind,
    draw_set: DrawSet,
    capacity: u32,
    view_buffer: wgpu::Buffer,
    /// The view uniforms' CPU copy (allocated once): rendered slots are written into it and
    /// uploaded in one write covering them.
    mirror: std::cell::RefCell<Vec<u8>>,
    view_group: wgpu::BindGroup,
    map_pipeline: wgpu::RenderPipeline,
    clear_pipeline: wgpu::RenderPipeline,
}

impl AtlasRasteriser {
    /// A rasteriser for `atlas` (which must have a depth format) drawing `draw_set`.
    pub fn new(
        gpu: &GpuContext,
        atlas: &ShadowAtlas,
        uniforms: &FrameUniforms,
        draw_set: DrawSet,
    ) -> Result<AtlasRasteriser> {
        let device = &gpu.device;
        let settings = atlas.settings;
        if !settings.format.is_depth() {
            return Err(Error::Invalid(format!(
                "the atlas rasteriser renders depth atlases; this atlas is {:?}",
                settings.format
            )));
        }
        let format = settings.format.texture_format();
        let faces = settings.kind.faces() as u64;
        let view_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vpl views"),
            size: settings.capacity as u64 * faces * VIEW_STRIDE,
            // STORAGE: written by [`StoreViews`] for GPU-written VPLs.
            usage: wgpu::BufferUsages::UNIFORM
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let first_view = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &view_buffer,
            offset: 0,
            size: wgpu::BufferSize::new(std::mem::size_of::<ViewData>() as u64),
        });
        let Bound {
            layout: view_layout,
            group: view_group,
        } = Bindings::new("vpl views", wgpu::ShaderStages::VERTEX_FRAGMENT)
            .dynamic_uniform(first_view)
            .build(device);
        let module = shader_module(
            device,
            "vpl shadow maps",
            include_str!("shaders/vpl_shadow.wgsl"),
        );
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("vpl shadow maps"),
            bind_group_layouts: &[Some(&view_layout), Some(&uniforms.object_layout)],
            immediate_size: 0,
        });
        let position_only = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        };
        let depth_state = |compare| wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        };
        let (vs, fs) = match settings.kind {
            MapKind::Paraboloid => ("vs_paraboloid", Some("fs_paraboloid")),
            MapKind::Cube => ("vs_cube", None),
            MapKind::Octahedral => ("vs_octahedral", Some("fs_octahedral")),
        };
        let map_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("vpl shadow map"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers: &[Some(position_only.clone())],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(depth_state(wgpu::CompareFunction::Greater)),
            multisample: Default::default(),
            fragment: fs.map(|entry| wgpu::FragmentState {
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        let clear_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("vpl tile clear"),
            bind_group_layouts: &[],
            immediate_size: 0,
        });
        let clear_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("vpl tile clear"),
            layout: Some(&clear_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_clear"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(depth_state(wgpu::CompareFunction::Always)),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        gpu.check_errors()?;
        Ok(AtlasRasteriser {
            kind: settings.kind,
            draw_set,
            capacity: settings.capacity,
            mirror: std::cell::RefCell::new(vec![0; view_buffer.size() as usize]),
            view_buffer,
            view_group,
            map_pipeline,
            clear_pipeline,
        })
    }

    /// The declared minimum cost of one map ([`crate::measure::roofline`]), for its caller to
    /// compute once and multiply by the maps a frame renders: the draw set's positions and
    /// indices read once per map and every vertex moved into the VPL's frame once
    /// ([`GpuScene::depth_draw_cost`]: a cube map's six faces or an octahedral map's four can
    /// share one read and one transform per vertex), and every texel of the map's block written
    /// once (cleared or drawn: 2 or 4 bytes by the atlas's depth format). Fragments hidden behind
    /// nearer ones and a cube face's or octahedral face's re-projection are not counted.
    pub fn map_cost(&self, scene: &GpuScene, atlas: &ShadowAtlas) -> StageCost {
        let (_, [w, h]) = atlas.block(0);
        let depth_bytes = match atlas.settings.format {
            AtlasFormat::Depth16 => 2,
            AtlasFormat::Depth32 | AtlasFormat::Float32 => 4,
        };
        scene
            .depth_draw_cost(self.draw_set)
            .plus(StageCost::per_element(
                w as u64 * h as u64,
                0,
                depth_bytes,
                0,
            ))
    }

    /// Writes the view(s) of `vpl` for `slot` into the CPU copy `mirror`.
    fn write_view(&self, mirror: &mut [u8], atlas: &ShadowAtlas, slot: u32, vpl: &Vpl) {
        let (t, b) = frame_from_normal(vpl.normal);
        let eye = vpl.position + vpl.normal * atlas.lift;
        let faces = self.kind.faces() as usize;
        let start = slot as usize * faces * VIEW_STRIDE as usize;
        let bytes = &mut mirror[start..start + faces * VIEW_STRIDE as usize];
        for f in 0..faces {
            let view_proj = match self.kind {
                MapKind::Cube => cube_face_matrix(eye, f, atlas.near),
                MapKind::Paraboloid | MapKind::Octahedral => Mat4::IDENTITY,
            };
            // Octahedral face f's quadrant: (sx, sy) = (±1, ±1).
            let (sx, sy) = match self.kind {
                MapKind::Octahedral => (
                    if f & 1 == 0 { 1.0 } else { -1.0 },
                    if f & 2 == 0 { 1.0 } else { -1.0 },
                ),
                _ => (0.0, 0.0),
            };
            let d = ViewData {
                view_proj: view_proj.to_cols_array(),
                position: eye.extend(atlas.far).to_array(),
                tangent: t.extend(sx).to_array(),
                bitangent: b.extend(sy).to_array(),
                normal: vpl.normal.extend(atlas.near).to_array(),
            };
            let o = f * VIEW_STRIDE as usize;
            bytes[o..o + std::mem::size_of::<ViewData>()].copy_from_slice(bytemuck::bytes_of(&d));
        }
    }

    /// Uploads the views of `vpls` (slot, VPL) and records their maps into `atlas` after the
    /// clear `clear` asks for. Slots beyond the capacity are skipped. Returns the number of
    /// maps rendered.
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        vpls: &[(u32, Vpl)],
        clear: AtlasClear,
    ) -> u32 {
        self.render_faces(gpu, encoder, atlas, scene, uniforms, vpls, &[], clear)
            .0
    }

    /// [`render`](Self::render) drawing map `k` only into the faces whose bits are set in
    /// `faces[k]` (bit f: face f; [`face_cull::Occluders`](super::face_cull::Occluders) finds
    /// them for octahedral maps); a face not drawn is left cleared. `faces` shorter than `vpls`
    /// draws every face of the maps past its end. Returns the maps and the faces rendered.
    #[allow(clippy::too_many_arguments)]
    pub fn render_faces(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        vpls: &[(u32, Vpl)],
        faces: &[u8],
        clear: AtlasClear,
    ) -> (u32, u32) {
        let kept = || {
            (vpls.iter().enumerate())
                .filter(|(_, (s, _))| *s < self.capacity)
                .map(|(k, (s, v))| (k, *s, v))
        };
        // One upload covering every slot rendered (per-slot writes cost about 1 ms each on
        // lavapipe: 8x the maps themselves at 256 VPLs).
        let mut mirror = self.mirror.borrow_mut();
        let (mut lo, mut hi) = (u32::MAX, 0);
        for (_, slot, vpl) in kept() {
            self.write_view(&mut mirror, atlas, slot, vpl);
            (lo, hi) = (lo.min(slot), hi.max(slot));
        }
        if lo <= hi {
            let slot_bytes = self.kind.faces() as usize * VIEW_STRIDE as usize;
            let range = lo as usize * slot_bytes..(hi as usize + 1) * slot_bytes;
            gpu.queue
                .write_buffer(&self.view_buffer, range.start as u64, &mirror[range]);
        }
        self.draw(
            encoder,
            atlas,
            scene,
            uniforms,
            kept().map(|(k, s, _)| (s, faces.get(k).copied().unwrap_or(u8::MAX))),
            clear,
        )
    }

    /// Records the maps of slots `0..count` of the store `views` reads (clamped to the
    /// capacity) into `atlas`, clearing it whole: first the compute pass that writes their views
    /// from the store, then the maps. Returns the number of maps rendered.
    pub fn render_store(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        views: &StoreViews,
        count: u32,
    ) -> u32 {
        let count = count.min(self.capacity);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("vpl views from the store"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&views.pipeline);
            pass.set_bind_group(0, &views.group, &[]);
            pass.dispatch_workgroups(count.div_ceil(64), 1, 1);
        }
        let slots = (0..count).map(|s| (s, u8::MAX));
        self.draw(encoder, atlas, scene, uniforms, slots, AtlasClear::Whole)
            .0
    }

    /// Records the maps of `slots` (slot, faces to draw), whose views are in place, after the
    /// clear `clear` asks for. Returns the maps and the faces recorded.
    fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        atlas: &ShadowAtlas,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        slots: impl Iterator<Item = (u32, u8)>,
        clear: AtlasClear,
    ) -> (u32, u32) {
        let load = match clear {
            AtlasClear::Whole => wgpu::LoadOp::Clear(0.0),
            AtlasClear::RenderedSlots => wgpu::LoadOp::Load,
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("vpl shadow maps"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: atlas.view(),
                depth_ops: Some(wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let s = atlas.settings.size;
        let faces = self.kind.faces();
        let (mut count, mut drawn) = (0, 0);
        for (slot, mask) in slots {
            count += 1;
            if clear == AtlasClear::RenderedSlots {
                let ([x, y], [w, h]) = atlas.block(slot);
                pass.set_viewport(x as f32, y as f32, w as f32, h as f32, 0.0, 1.0);
                pass.set_scissor_rect(x, y, w, h);
                pass.set_pipeline(&self.clear_pipeline);
                pass.draw(0..3, 0..1);
            }
            pass.set_pipeline(&self.map_pipeline);
            for f in (0..faces).filter(|f| mask & (1 << f) != 0) {
                drawn += 1;
                let [x, y] = atlas.face_origin(slot, f);
                pass.set_viewport(x as f32, y as f32, s as f32, s as f32, 0.0, 1.0);
                pass.set_scissor_rect(x, y, s, s);
                let offset = ((slot * faces + f) as u64 * VIEW_STRIDE) as u32;
                pass.set_bind_group(0, &self.view_group, &[offset]);
                scene.draw(&mut pass, uniforms, 1, self.draw_set);
            }
        }
        (count, drawn)
    }

    /// The compute pass that writes the views of the VPLs in `store` for
    /// [`AtlasRasteriser::render_store`] (paraboloid maps only: a cube map's six views would
    /// need the face matrices on the GPU, which nothing uses yet).
    pub fn store_views(
        &self,
        gpu: &GpuContext,
        atlas: &ShadowAtlas,
        store: &VplStore,
    ) -> Result<StoreViews> {
        if self.kind != MapKind::Paraboloid {
            return Err(Error::param(
                "vpl-map",
                "maps of VPLs written on the GPU are paraboloid only",
            ));
        }
        let device = &gpu.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("vpl views from the store"),
            entries: &[VplStore::layout_entry(0, false), storage_entry(1, false)],
        });
        let source = format!(
            "const LIFT: f32 = {:.9e};\nconst FAR: f32 = {:.9e};\n{}\n{}",
            atlas.lift,
            atlas.far,
            VplStore::wgsl(0, 0, false),
            include_str!("shaders/store_views.wgsl")
        );
        let pipeline = compute_pipeline(
            device,
            "vpl views from the store",
            &source,
            &[&layout],
            "write_views",
        );
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vpl views from the store"),
            layout: &layout,
            entries: &[
                bind_buffer(0, store.buffer()),
                bind_buffer(1, &self.view_buffer),
            ],
        });
        gpu.check_errors()?;
        Ok(StoreViews { pipeline, group })
    }
}

/// The pass writing paraboloid views of GPU-written VPLs into an [`AtlasRasteriser`]'s view
/// uniforms ([`AtlasRasteriser::store_views`]).
pub struct StoreViews {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
}
