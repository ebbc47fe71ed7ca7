//! Lights drawn over the patch leaves, up to K per draw (Barczak 2006 §4.3.2–4.3.5), for each
//! optimisation level ([`Level`]).
//!
//! Reads: the visibility database (each leaf's light states), the light samples in a
//! [`VplStore`] (slot = light index) and their maps in a [`ShadowAtlas`], the leaves' geometry
//! ([`Leaves`]), the camera and the G-buffer's depth.
//! Writes: `target`, at every pixel of a leaf:
//! * [`Level::Full`] — subtracts the contributions of the leaf's *partial* lights that the shadow
//!   maps find occluded, after [`super::lightmap_pass`] drew the light maps there (together:
//!   every light with its visibility);
//! * [`Level::VisibilityDetermination`] — no light maps: adds the leaf's unblocked lights without
//!   a lookup and its partial lights with one; blocked lights and lights behind are skipped;
//! * [`Level::Naive`] — adds every light with a lookup on every leaf (brute force).
//!
//! Passes: elements, each a set of leaves with the lights they share (one per leaf, merged by
//! Figure 4-10's optimiser when `optimise` is on; lights needing lookups and lights not needing
//! them are separate elements); each element is drawn ⌈lights / K⌉ times, a pass handling up to
//! K lights (the thesis' X800 had room for 7 per pass; K ≤ 16 here). Every triangle a pass emits
//! names its leaf triangle's first vertex and the pass's light record (read-only storage,
//! portable to GL; the vertex shader pulls the leaf's vertices), so [`Submission::Merged`]
//! submits all the passes of a render pass as one draw, in the passes' order (blending keeps
//! it): the same triangles, the same lights per fragment, without the thesis' per-pass draw
//! cost (docs/roofline.md); [`Submission::Passes`] issues one draw per pass.
//! Buffers are sized once for the worst case (Naive without merging), so no frame allocates.

use std::ops::Range;
use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::ir::atlas::ShadowAtlas;
use gibench_harness::kit::ir::store::VplStore;
use gibench_harness::kit::passes::{
    dynamic_storage_entry, read_storage_entry, shader_module, Bindings, Bound, FrameUniforms,
    GBuffer, CAMERA_SLOT,
};
use gibench_harness::{wgpu, Error, Result};

use crate::database::VisibilityDatabase;
use crate::lightmap_pass::{color_pass, target_pass, Leaves};
use crate::lowres::{accumulate, mask_depth, LowRes};
use crate::passes::{one_per_object, optimise, total_passes, Element, LightSet};
use crate::visibility::LightState;

/// How the passes reach the device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Submission {
    /// One draw per render pass holding every planned pass.
    Merged,
    /// One draw per pass, as the thesis submits them.
    Passes,
}

impl Submission {
    /// Parameter values, in [`Submission`]'s order.
    pub const NAMES: [&'static str; 2] = ["merged", "passes"];

    /// The submission named `name` (one of [`Self::NAMES`]).
    pub fn parse(name: &str) -> Result<Submission> {
        match name {
            "merged" => Ok(Submission::Merged),
            "passes" => Ok(Submission::Passes),
            other => Err(Error::param(
                "submission",
                format!("expected merged or passes (got {other})"),
            )),
        }
    }
}

/// Lights one draw handles at most.
pub const MAX_LIGHTS_PER_DRAW: u32 = 16;
/// The record entry bit that asks for a shadow-map lookup.
const LOOKUP: u32 = 0x8000_0000;

/// Barczak's optimisation levels (Figure 5-3) as far as the light draws are concerned (the
/// low-resolution pass comes on top of Full and VD).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// Light maps minus the occluded partial lights.
    Full,
    /// Unblocked lights without lookups, partial lights with them, no light maps.
    VisibilityDetermination,
    /// Every light with a lookup.
    Naive,
}
/// The raster entries' stride (a dynamic offset's alignment).
const RECORD_STRIDE: u64 = 256;
/// Bytes of one pass's light record.
const LIGHTS_STRIDE: u64 = std::mem::size_of::<DrawLights>() as u64;

/// Where and how a set of draws rasterises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Raster {
    /// Full resolution, every pixel of a leaf.
    Full = 0,
    /// The low-resolution pass's image (accumulated positively, subtracted by its composite).
    Low = 1,
    /// Full resolution, edge pixels only (the low-resolution pass's depth mask).
    Edges = 2,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct RasterData {
    counts: [u32; 4],
    ndc: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct DrawLights {
    count: [u32; 4],
    lights: [u32; 16],
}

/// See the module docs.
pub struct LightDraws {
    k: u32,
    submission: Submission,
    leaves: Arc<Leaves>,
    /// Per emitted triangle: its leaf triangle's first vertex and its pass's record.
    emitted: wgpu::Buffer,
    records: wgpu::Buffer,
    /// Draws the buffers hold at most.
    max_draws: u32,
    store_group: wgpu::BindGroup,
    gbuffer_group: wgpu::BindGroup,
    /// Per [`Raster`]: subtracting and adding pipelines.
    pipelines: [[wgpu::RenderPipeline; 2]; 3],
    /// The two raster entries (full resolution, low resolution), a record apart.
    _raster: wgpu::Buffer,
    /// The last plan's level.
    level: Level,
    /// The CPU copies of the emitted-triangle and record uploads, reused frame to frame.
    scratch_emitted: Vec<[u32; 2]>,
    scratch_records: Vec<DrawLights>,
    /// This frame's passes: each one's emitted vertices (three per emitted triangle).
    draws: Vec<Range<u32>>,
    /// Elements of the last plan (for the results: passes made).
    elements: usize,
    /// The draws the last plan's elements would have needed unmerged.
    unmerged: usize,
}

impl LightDraws {
    /// The pass over `leaves` for `lights` lights in `store` and `atlas`, `k` lights per pass,
    /// submitted as `submission` says.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        uniforms: &FrameUniforms,
        gbuffer: &GBuffer,
        leaves: Arc<Leaves>,
        lights: u32,
        k: u32,
        submission: Submission,
        store: &VplStore,
        atlas: &ShadowAtlas,
        lowres: Option<&LowRes>,
    ) -> Result<LightDraws> {
        if !(1..=MAX_LIGHTS_PER_DRAW).contains(&k) {
            return Err(Error::param(
                "lights-per-draw",
                format!("expected 1..={MAX_LIGHTS_PER_DRAW} (got {k})"),
            ));
        }
        let (emitted, records, max_draws) = draw_buffers(gpu, &leaves, lights, k)?;
        let raster = raster_buffer(gpu, lowres);
        let buffers = [store.buffer(), &records, &raster, &emitted, leaves.buffer()];
        let Bound {
            layout: store_layout,
            group: store_group,
        } = store_bind_group(&gpu.device, buffers);
        let pipelines = pipelines(&gpu.device, uniforms, gbuffer, &store_layout, atlas);
        gpu.check_errors()?;
        Ok(LightDraws {
            k,
            submission,
            leaves,
            emitted,
            records,
            max_draws,
            store_group,
            gbuffer_group: gbuffer.read_group.clone(),
            pipelines,
            _raster: raster,
            level: Level::Full,
            scratch_emitted: Vec::new(),
            scratch_records: Vec::new(),
            draws: Vec::new(),
            elements: 0,
            unmerged: 0,
        })
    }

    /// Plans this frame's draws for `level` from `db` (merging elements when `optimise`) and
    /// uploads them. Returns the draws planned.
    pub fn plan(
        &mut self,
        gpu: &GpuContext,
        db: &VisibilityDatabase,
        level: Level,
        optimise_passes: bool,
    ) -> Result<u32> {
        let lights = db.lights.len() as u32;
        let per_leaf = |want: &dyn Fn(LightState) -> bool| -> Vec<LightSet> {
            self.leaves
                .tiles
                .iter()
                .map(|&(r, n)| {
                    LightSet::from_indices(
                        (0..lights).filter(|&l| want(db.state(r, n, l as usize))),
                    )
                })
                .collect()
        };
        // (elements, whether their lights need lookups)
        let groups: Vec<(Vec<Element>, bool)> = match level {
            Level::Full => vec![(
                one_per_object(&per_leaf(&|s| s == LightState::Partial)),
                true,
            )],
            Level::VisibilityDetermination => vec![
                (
                    one_per_object(&per_leaf(&|s| s == LightState::Unblocked)),
                    false,
                ),
                (
                    one_per_object(&per_leaf(&|s| s == LightState::Partial)),
                    true,
                ),
            ],
            Level::Naive => vec![(one_per_object(&per_leaf(&|_| true)), true)],
        };
        // Scratch kept between frames.
        let mut emitted = std::mem::take(&mut self.scratch_emitted);
        let mut records = std::mem::take(&mut self.scratch_records);
        emitted.clear();
        records.clear();
        self.draws.clear();
        self.elements = 0;
        self.unmerged = 0;
        for (elements, lookup) in groups {
            self.unmerged += total_passes(&elements, self.k as usize);
            let elements = if optimise_passes {
                optimise(elements, self.k as usize)
            } else {
                elements
            };
            self.elements += elements.len();
            for e in &elements {
                let flag = if lookup { LOOKUP } else { 0 };
                let lights: Vec<u32> = e.lights.iter().map(|l| l | flag).collect();
                for chunk in lights.chunks(self.k as usize) {
                    let mut rec = DrawLights {
                        count: [chunk.len() as u32, 0, 0, 0],
                        lights: [0; 16],
                    };
                    rec.lights[..chunk.len()].copy_from_slice(chunk);
                    let record = self.draws.len() as u32;
                    let start = 3 * emitted.len() as u32;
                    for &tile in &e.objects {
                        let vertices = self.leaves.ranges[tile as usize].clone();
                        emitted.extend(vertices.step_by(3).map(|v| [v, record]));
                    }
                    if record >= self.max_draws || emitted.len() as u64 * 8 > self.emitted.size() {
                        return Err(Error::Invalid(format!(
                            "barczak's light draws: this frame's plan needs more than the {} passes and {} triangles the device's bindings hold (the pass optimiser drew leaves in more passes than without it); use fewer samples (vpls) or level vd",
                            self.max_draws,
                            self.emitted.size() / 8
                        )));
                    }
                    records.push(rec);
                    self.draws.push(start..3 * emitted.len() as u32);
                }
            }
        }
        if !emitted.is_empty() {
            gpu.queue
                .write_buffer(&self.emitted, 0, bytemuck::cast_slice(&emitted));
            gpu.queue
                .write_buffer(&self.records, 0, bytemuck::cast_slice(&records));
        }
        self.scratch_emitted = emitted;
        self.scratch_records = records;
        self.level = level;
        Ok(self.draws.len() as u32)
    }

    /// Submits the passes as `submission` says from now on.
    pub fn set_submission(&mut self, submission: Submission) {
        self.submission = submission;
    }

    /// The patch leaves' vertices (what a draw over every leaf reads).
    pub fn leaf_vertices(&self) -> u32 {
        self.leaves.vertex_count()
    }

    /// Elements of the last plan.
    pub fn elements(&self) -> usize {
        self.elements
    }

    /// The draws (passes) of the last plan, and those its elements would have needed before
    /// the render-pass optimiser merged them (the same when it did not run): its saving.
    pub fn passes(&self) -> (usize, usize) {
        (self.draws.len(), self.unmerged)
    }

    /// Records the planned draws into `target` at full resolution: kept for [`Level::Full`]
    /// (the light-map pass drew it), cleared first otherwise. Returns the draws made.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        uniforms: &FrameUniforms,
        atlas: &ShadowAtlas,
        target: &wgpu::TextureView,
    ) -> u32 {
        let mut pass = color_pass(
            encoder,
            "barczak light draws",
            target,
            self.level != Level::Full,
        );
        self.record(&mut pass, Raster::Full, uniforms, atlas)
    }

    /// Records the planned draws into `lowres`'s low-resolution image (cleared first), which
    /// then holds the sum [`Self::encode_edges`] composites. Returns the draws made.
    pub fn encode_low(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        uniforms: &FrameUniforms,
        atlas: &ShadowAtlas,
        lowres: &LowRes,
    ) -> u32 {
        let mut pass = color_pass(
            encoder,
            "barczak light draws (low resolution)",
            lowres.low_view(),
            true,
        );
        self.record(&mut pass, Raster::Low, uniforms, atlas)
    }

    /// Composites `lowres`'s interpolated image into `target` off the edges (subtracted for
    /// [`Level::Full`], after the light maps; added into a cleared target otherwise) and records
    /// the planned draws again at full resolution on the edges (after
    /// [`LowRes::encode_mask`]). Returns the draws made.
    pub fn encode_edges(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        uniforms: &FrameUniforms,
        atlas: &ShadowAtlas,
        target: &wgpu::TextureView,
        lowres: &LowRes,
    ) -> u32 {
        let subtract = self.level == Level::Full;
        let mut pass = target_pass(
            encoder,
            "barczak light draws (edges)",
            target,
            !subtract,
            Some(lowres.mask_view()),
        );
        lowres.composite(&mut pass, subtract);
        self.record(&mut pass, Raster::Edges, uniforms, atlas)
    }

    fn record(
        &self,
        pass: &mut wgpu::RenderPass,
        raster: Raster,
        uniforms: &FrameUniforms,
        atlas: &ShadowAtlas,
    ) -> u32 {
        let subtract = self.level == Level::Full;
        pass.set_pipeline(&self.pipelines[raster as usize][if subtract { 0 } else { 1 }]);
        pass.set_bind_group(
            0,
            uniforms.views.group(),
            &[uniforms.views.offset(CAMERA_SLOT)],
        );
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.set_bind_group(3, atlas.group(), &[]);
        let raster_offset = if raster == Raster::Low {
            RECORD_STRIDE as u32
        } else {
            0
        };
        pass.set_bind_group(2, &self.store_group, &[raster_offset]);
        match (self.submission, self.draws.last()) {
            (_, None) => {}
            (Submission::Merged, Some(last)) => pass.draw(0..last.end, 0..1),
            (Submission::Passes, _) => {
                for range in &self.draws {
                    pass.draw(range.clone(), 0..1);
                }
            }
        }
        self.draws.len() as u32
    }
}

/// The emitted triangles and the per-pass light records for `lights` lights over `leaves`, `k`
/// per pass, sized once by [`draw_capacity`]; and the passes they hold. Refused when a plan
/// without merging might not fit the device's storage binding, or the leaves' vertices do not.
fn draw_buffers(
    gpu: &GpuContext,
    leaves: &Leaves,
    lights: u32,
    k: u32,
) -> Result<(wgpu::Buffer, wgpu::Buffer, u32)> {
    let device = &gpu.device;
    let tiles = leaves.tiles.len() as u64;
    let limits = gpu.device.limits();
    let limit = limits
        .max_buffer_size
        .min(limits.max_storage_buffer_binding_size);
    let capacity = draw_capacity(tiles, leaves.vertex_count() as u64, lights, k, limit);
    let Some((max_draws, max_emitted)) = capacity else {
        return Err(Error::Invalid(format!(
            "barczak's light draws would need more than this device binds ({} MB) for {} leaves ({} of their vertices) and {lights} light samples; use fewer samples (vpls) or a scene with fewer patches (max-charts)",
            limit >> 20,
            tiles,
            leaves.vertex_count(),
        )));
    };
    // The leaves' vertices are bound too (pulled by the vertex shader).
    if leaves.buffer().size() > limit {
        return Err(Error::Invalid(format!(
            "barczak's {} leaf vertices take {} MB, more than this device binds ({} MB); use a scene with fewer patches (max-charts)",
            leaves.vertex_count(),
            leaves.buffer().size() >> 20,
            limit >> 20
        )));
    }
    let storage = |label, size| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    };
    let emitted = storage("barczak emitted triangles", max_emitted * 8);
    let records = storage("barczak pass lights", max_draws * LIGHTS_STRIDE);
    Ok((emitted, records, max_draws as u32))
}

/// The passes and the emitted triangles the draws are sized for over `tiles` leaves of
/// `vertices` vertices (triangle lists), `lights` lights, `k` per pass, within `limit` bytes a
/// binding; `None` when even a plan without merging might not fit.
///
/// Passes: the most any level plans without merging, every leaf with every light, split in two
/// groups (VD: one more pass per leaf at most); merging only ever removes passes. Emitted
/// triangles: each leaf's triangles once per pass of it, so without merging at most those
/// passes per leaf; a merged plan can draw a leaf in more passes (up to one per light: every
/// (leaf, light) pair is in one pass), so the buffer holds up to that many where the device
/// binds them, and a plan beyond what it holds is refused at plan time, naming the sizes.
fn draw_capacity(tiles: u64, vertices: u64, lights: u32, k: u32, limit: u64) -> Option<(u64, u64)> {
    let passes_per_leaf = lights.div_ceil(k) as u64 + 1;
    let max_draws = (tiles * passes_per_leaf).max(1);
    let triangles = vertices / 3;
    let unmerged = (triangles * passes_per_leaf.min(lights as u64)).max(1);
    let most = (triangles * lights as u64).max(1);
    let max_emitted = most.min(limit / 8);
    (max_draws * LIGHTS_STRIDE <= limit && unmerged <= max_emitted)
        .then_some((max_draws, max_emitted))
}

/// The two raster entries, a record apart: full resolution, then the low-resolution pass's
/// (factor and projection shift; full resolution again without one).
fn raster_buffer(gpu: &GpuContext, lowres: Option<&LowRes>) -> wgpu::Buffer {
    let raster = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("barczak light draws raster"),
        size: 2 * RECORD_STRIDE,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let full = RasterData {
        counts: [1, 0, 0, 0],
        ndc: [0.0; 4],
    };
    let low = lowres.map_or(full, |l| {
        let [x, y] = l.ndc_offset();
        RasterData {
            counts: [l.factor, l.factor / 2, 0, 0],
            ndc: [x, y, 0.0, 0.0],
        }
    });
    gpu.queue
        .write_buffer(&raster, 0, bytemuck::bytes_of(&full));
    gpu.queue
        .write_buffer(&raster, RECORD_STRIDE, bytemuck::bytes_of(&low));
    raster
}

/// Group 2 of the light draws: 0 the store's lights, 1 the passes' light records, 2 the raster
/// entry (at a dynamic offset), 3 the emitted vertices, 4 the leaves' vertices.
fn store_bind_group(
    device: &wgpu::Device,
    [lights, records, raster, emitted, leaves]: [&wgpu::Buffer; 5],
) -> Bound {
    let raster_size = std::mem::size_of::<RasterData>() as u64;
    let raster_slot = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer: raster,
        offset: 0,
        size: wgpu::BufferSize::new(raster_size),
    });
    // Each binding visible to the stage that reads it: three storage buffers a stage, within
    // the downlevel limit of four.
    use wgpu::ShaderStages as S;
    let read_in = |stage: S| move |b, _| read_storage_entry(b, stage);
    Bindings::new("barczak lights", S::VERTEX_FRAGMENT)
        .with(read_in(S::FRAGMENT), lights.as_entire_binding())
        .with(read_in(S::FRAGMENT), records.as_entire_binding())
        .with(|b, v| dynamic_storage_entry(b, v, raster_size), raster_slot)
        .with(read_in(S::VERTEX), emitted.as_entire_binding())
        .with(read_in(S::VERTEX), leaves.as_entire_binding())
        .build(device)
}

/// The light draws' pipelines per [`Raster`] (full resolution, low resolution, edges), each
/// subtracting and adding.
fn pipelines(
    device: &wgpu::Device,
    uniforms: &FrameUniforms,
    gbuffer: &GBuffer,
    store_layout: &wgpu::BindGroupLayout,
    atlas: &ShadowAtlas,
) -> [[wgpu::RenderPipeline; 2]; 3] {
    let source = format!(
        "{}\n{}\n{}",
        VplStore::wgsl(2, 0, false),
        ShadowAtlas::wgsl(3),
        include_str!("shaders/light_draws.wgsl")
    );
    let module = shader_module(device, "barczak light draws", &source);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("barczak light draws"),
        bind_group_layouts: &[
            Some(&uniforms.view_layout),
            Some(&gbuffer.read_layout),
            Some(store_layout),
            Some(atlas.layout()),
        ],
        immediate_size: 0,
    });
    let pipeline = |entry: &str, operation, depth| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("barczak light draws"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_leaf"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: depth,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: &[Some(accumulate(operation))],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    use wgpu::BlendOperation::{Add, ReverseSubtract};
    let edges = || Some(mask_depth(false, wgpu::CompareFunction::Greater));
    [
        [
            pipeline("fs_subtract", ReverseSubtract, None),
            pipeline("fs_add", Add, None),
        ],
        // The low image holds what the composite then subtracts or adds.
        [
            pipeline("fs_subtract", Add, None),
            pipeline("fs_add", Add, None),
        ],
        [
            pipeline("fs_subtract", ReverseSubtract, edges()),
            pipeline("fs_add", Add, edges()),
        ],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sibenik's charts (29,927 leaves, 373,068 of their vertices at the defaults) and the
    /// conference room's with 64 lights fit the 128 MB a device binds by default (wgpu's
    /// default `max_storage_buffer_binding_size`). Catches an emitted record per vertex (8
    /// bytes a vertex: 191 MB on Sibenik, refused) where one per triangle suffices, and a
    /// capacity that insists on the worst merged plan (236 MB on the conference room).
    #[test]
    fn the_large_scenes_at_64_lights_fit_a_default_storage_binding() {
        let limit = wgpu::Limits::default().max_storage_buffer_binding_size;
        assert!(draw_capacity(29_927, 373_068, 64, 7, limit).is_some());
        // The conference room's 136,185 leaves (1,452,696 vertices): the worst merged plan
        // would not fit, a plan without merging does.
        let (draws, emitted) = draw_capacity(136_185, 1_452_696, 64, 7, limit).unwrap();
        assert!(emitted * 8 <= limit && draws * LIGHTS_STRIDE <= limit);
        assert!(emitted >= 1_452_696 / 3 * 11, "{emitted}");
    }
}
