//! The parts wired for one frame after another (Barczak 2006 §4.3–4.5), at the optimisation
//! four optimisation levels of Figure 5-3 ([`Optimisation`]).
//!
//! Reads: the scene (patches, movers), the harness's G-buffer, uniforms and static BVH, each
//! frame's mover poses.
//! Writes: `output` (Rgba16Float irradiance of the light samples): on patches, per [`Optimisation`],
//! light maps minus the occluded partial lights, or the lights drawn with or without lookups;
//! PRT on movers.
//!
//! Per frame: every mover that moved is moved in the visibility database (Table 4-1), the light
//! maps gain or lose single lights, and the shadow maps the motion touched go out of date; the
//! schedule re-renders `updates` of them by priority (all on the first frame), each only into
//! the octahedral faces that hold an occluder (§4.2.2, unless `face_cull` is off); the light draws
//! are planned (optimised at Full) and drawn — with the low-resolution pass at Full and VD+LP
//! (edges found, the lights drawn at low resolution, interpolated off the edges and drawn
//! again at full resolution on them); each mover's lighting environment is gathered
//! from the samples its centre sees (ray casts against the static BVH) and drawn by PRT.

use std::sync::Arc;

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::vpl::Vpl;
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::ir::atlas::{AtlasFormat, AtlasSettings, MapKind, ShadowAtlas};
use gibench_harness::kit::ir::edges::EdgeSettings;
use gibench_harness::kit::ir::face_cull::Occluders;
use gibench_harness::kit::ir::raster::{AtlasClear, AtlasRasteriser};
use gibench_harness::kit::ir::store::VplStore;
use gibench_harness::kit::passes::{
    render_target, DrawSet, FrameUniforms, GBuffer, GpuScene, Vertex, HDR_FORMAT,
};
use gibench_harness::measure::roofline::StageCost;
use gibench_harness::scene::anim::FrameState;
use gibench_harness::scene::Scene;
use gibench_harness::{wgpu, Error, Result};
use glam::{Mat3, Mat4};

use crate::light_draws::{Level, LightDraws, Submission};
use crate::lightmap_pass::{Leaves, LightMapPass};
use crate::lowres::LowRes;
use crate::prt::{self, COEFFS};
use crate::prt_pass::PrtPass;
use crate::samples::SampleSettings;
use crate::schedule::ShadowMapSchedule;
use crate::setup::{prepare, BarczakScene, LightMapSize};

/// The renderer's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RendererSettings {
    pub samples: SampleSettings,
    /// Light-map texels along a leaf's edge.
    pub light_map_res: u32,
    /// Lights per subtraction draw (K).
    pub lights_per_draw: u32,
    /// How the light passes reach the device.
    pub submission: Submission,
    /// Figure 5-3's optimisation level.
    pub level: Optimisation,
    /// The low-resolution pass's factor (at [`Optimisation::Full`] and
    /// [`Optimisation::VdLp`]).
    pub lowres: u32,
    /// Its edge detection's step, pixels.
    pub edge_step: u32,
    /// Octahedral map edge, texels.
    pub map_size: u32,
    /// Shadow maps re-rendered per frame at most (after the first).
    pub updates: u32,
    /// Directions of the PRT transfer integral.
    pub prt_directions: usize,
    /// Draw a shadow map only into the octahedral faces holding an occluder (§4.2.2).
    pub face_cull: bool,
    /// Charts a scene without recorded patches may make (`Scene::receiver_patches`).
    pub max_charts: usize,
}

/// What the renderer prepares on the CPU once per scene (§4.1, §4.3, §4.4): the scene's light
/// samples, visibility database and light maps, and each mover's PRT transfer.
#[derive(Clone, Debug)]
pub struct Prepared {
    pub bz: BarczakScene,
    /// Per mover, per vertex.
    pub transfers: Vec<Vec<[f32; COEFFS]>>,
}

impl Prepared {
    /// Prepares `scene` at `frame` (light and mover poses).
    pub fn new(
        gpu: &GpuContext,
        scene: &Scene,
        bvh: &SceneBvh,
        frame: &FrameState,
        settings: &RendererSettings,
    ) -> Result<Prepared> {
        let light_maps = LightMapSize {
            res: settings.light_map_res,
            max_bytes: gpu.max_storage_buffer(),
        };
        let bz = prepare(
            scene,
            bvh,
            frame,
            &frame.light,
            settings.samples,
            light_maps,
            settings.max_charts,
        )?;
        let lift = 1e-4 * scene.extent.diagonal;
        let transfers = scene
            .movers
            .iter()
            .map(|m| {
                prt::transfer(
                    &m.mesh,
                    &SceneBvh::new(&m.mesh),
                    settings.prt_directions,
                    lift,
                )
            })
            .collect();
        Ok(Prepared { bz, transfers })
    }
}

/// Figure 5-3's optimisation levels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Optimisation {
    /// Everything: visibility determination, light maps with the occluded partial lights
    /// subtracted, the low-resolution pass, the pass optimiser.
    Full,
    /// Visibility determination and the low-resolution pass.
    VdLp,
    /// Visibility determination only, at full resolution.
    Vd,
    /// Brute force: every light with a shadow-map lookup on every leaf, full resolution.
    Naive,
}

impl Optimisation {
    /// Every level, in Figure 5-3's order.
    pub const ALL: [Optimisation; 4] = [
        Optimisation::Full,
        Optimisation::VdLp,
        Optimisation::Vd,
        Optimisation::Naive,
    ];
    /// The parameter's words.
    pub const NAMES: [&'static str; 4] = ["full", "vd-lp", "vd", "naive"];

    /// The level named `name` (one of [`Self::NAMES`]).
    pub fn parse(name: &str) -> Result<Optimisation> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Self::ALL[i])
            .ok_or_else(|| {
                Error::param(
                    "level",
                    format!("expected one of {} (got '{name}')", Self::NAMES.join(", ")),
                )
            })
    }
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
    /// What its light draws do.
    pub fn draws(self) -> Level {
        match self {
            Optimisation::Full => Level::Full,
            Optimisation::VdLp | Optimisation::Vd => Level::VisibilityDetermination,
            Optimisation::Naive => Level::Naive,
        }
    }
    /// Whether it has the low-resolution pass.
    pub fn low_res(self) -> bool {
        matches!(self, Optimisation::Full | Optimisation::VdLp)
    }
}

/// What a frame did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameCounts {
    pub maps_rendered: u32,
    /// Octahedral faces drawn into (four per map without face culling).
    pub map_faces: u32,
    /// Draws of lights over leaves (the thesis' passes; the low-resolution pass draws twice).
    pub light_draws: u32,
    pub elements: u32,
    /// The light draws planned (the thesis' passes) and those the same elements would have
    /// needed before the render-pass optimiser merged them.
    pub passes: u32,
    pub passes_unmerged: u32,
    pub light_map_changes: u32,
}

/// The GPU stages' declared minimum costs ([`gibench_harness::measure::roofline`]), computed once
/// by [`Renderer::stage_costs`]. The light draws' arithmetic, per pixel and light, is not
/// counted: which pixels each draw's leaves cover is known on the GPU only, so `low-res` and
/// `lights` declare what they must read and write (a lower bound).
#[derive(Clone, Copy, Debug)]
pub struct StageCosts {
    /// One shadow map (times the maps a frame renders).
    pub shadow_map: StageCost,
    pub light_maps: StageCost,
    pub edges: StageCost,
    pub low_res: StageCost,
    pub lights: StageCost,
    pub prt: StageCost,
}

/// See the module docs.
pub struct Renderer {
    bz: BarczakScene,
    /// The light samples by slot, and as a plain list (for the PRT lighting).
    lights: Vec<(u32, Vpl)>,
    samples: Vec<Vpl>,
    /// This frame's maps to render (kept between frames: no allocation per frame).
    render: Vec<(u32, Vpl)>,
    /// The faces of each map of `render` to draw into (§4.2.2).
    faces: Vec<u8>,
    /// The occluders in world space: the static casters' triangles (once) and the movers'
    /// bounding spheres (posed every frame).
    occluders: Occluders,
    atlas: ShadowAtlas,
    raster: AtlasRasteriser,
    light_map: LightMapPass,
    draws: LightDraws,
    lowres: Option<LowRes>,
    prt: PrtPass,
    schedule: ShadowMapSchedule,
    poses: Vec<Mat4>,
    settings: RendererSettings,
    first: bool,
    _store: VplStore,
    output: wgpu::Texture,
    output_view: wgpu::TextureView,
}

impl Renderer {
    /// Prepares `scene` at `frame` (light and mover poses) and the GPU parts.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &GpuContext,
        scene: &Scene,
        bvh: &SceneBvh,
        uniforms: &FrameUniforms,
        gbuffer: &GBuffer,
        frame: &FrameState,
        settings: RendererSettings,
    ) -> Result<Renderer> {
        let prepared = Prepared::new(gpu, scene, bvh, frame, &settings)?;
        Renderer::with(gpu, scene, uniforms, gbuffer, frame, settings, prepared)
    }

    /// The GPU parts for a scene prepared by [`Prepared::new`] at `frame`.
    pub fn with(
        gpu: &GpuContext,
        scene: &Scene,
        uniforms: &FrameUniforms,
        gbuffer: &GBuffer,
        frame: &FrameState,
        settings: RendererSettings,
        prepared: Prepared,
    ) -> Result<Renderer> {
        let Prepared { bz, transfers } = prepared;
        let lights = bz.samples.slotted();
        let n = lights.len() as u32;
        let store = VplStore::new(gpu, n)?;
        store.write(&gpu.queue, &lights);
        let atlas = ShadowAtlas::new(
            gpu,
            &scene.extent,
            AtlasSettings {
                kind: MapKind::Octahedral,
                format: AtlasFormat::Depth16,
                size: settings.map_size,
                capacity: n,
                bias: 0.01,
            },
        )?;
        let raster = AtlasRasteriser::new(gpu, &atlas, uniforms, DrawSet::CastersAndMovers)?;
        let lowres = if settings.level.low_res() {
            Some(LowRes::new(
                gpu,
                gbuffer,
                settings.lowres,
                EdgeSettings {
                    step: settings.edge_step,
                    ..EdgeSettings::default()
                },
            )?)
        } else {
            None
        };
        let leaves = Arc::new(Leaves::new(gpu, &bz.db));
        let light_map = LightMapPass::new(gpu, uniforms, gbuffer, leaves.clone(), &bz.light_maps)?;
        let draws = LightDraws::new(
            gpu,
            uniforms,
            gbuffer,
            leaves,
            n,
            settings.lights_per_draw,
            settings.submission,
            &store,
            &atlas,
            lowres.as_ref(),
        )?;
        let prt = PrtPass::new(gpu, uniforms, gbuffer, &transfers)?;
        let schedule = ShadowMapSchedule::new(bz.flux.iter().copied());
        let output = render_target(&gpu.device, "barczak irradiance", gbuffer.size, HDR_FORMAT);
        let output_view = output.create_view(&Default::default());
        let casters = scene.shadow_caster_mesh();
        let occluders = Occluders::new(
            (0..casters.triangle_count())
                .map(|t| casters.triangle(t))
                .collect(),
        );
        Ok(Renderer {
            faces: Vec::with_capacity(lights.len()),
            occluders,
            poses: frame.movers.clone(),
            samples: lights.iter().map(|(_, v)| *v).collect(),
            render: Vec::with_capacity(lights.len()),
            bz,
            lights,
            atlas,
            raster,
            light_map,
            draws,
            lowres,
            prt,
            schedule,
            settings,
            first: true,
            _store: store,
            output,
            output_view,
        })
    }

    /// The irradiance texture.
    pub fn output(&self) -> &wgpu::Texture {
        &self.output
    }

    /// The irradiance view.
    pub fn output_view(&self) -> &wgpu::TextureView {
        &self.output_view
    }

    /// The prepared scene.
    pub fn scene(&self) -> &BarczakScene {
        &self.bz
    }

    /// The GPU stages' declared minimum costs for the scene drawn by `scene` (the harness's,
    /// the one the maps and the PRT draw read); call once, not per frame.
    pub fn stage_costs(&self, scene: &GpuScene) -> StageCosts {
        let size = self.output.size();
        let pixels = size.width as u64 * size.height as u64;
        // The patch leaves' vertices, read once by a pass that draws them: position and the
        // (leaf, s, t) or normal a pass needs (24 of their 36 bytes), moved to clip space once
        // (32 operations).
        let leaves = StageCost::per_element(self.draws.leaf_vertices() as u64, 24, 0, 32);
        // `shadow-maps`: the kit's map cost ([`AtlasRasteriser::map_cost`]), per map rendered.
        let shadow_map = self.raster.map_cost(scene, &self.atlas);
        // `light-maps` (Full): the leaves drawn once; per pixel the G-buffer's depth read (4
        // bytes) to find the leaf shown and the irradiance (Rgba16Float, 8) written; the
        // bilinear blend of four light-map texels (three lerps of three channels, 18) and its
        // coordinates (about 8). The light-map texels are not counted (how many a frame needs
        // depends on what the camera sees). Other levels draw nothing here: zero.
        let light_maps = if self.settings.level == Optimisation::Full {
            leaves.plus(StageCost::per_element(pixels, 4, 8, 26))
        } else {
            StageCost::default()
        };
        // `edges`: the kit's edge mask ([`EdgeMask::cost`](gibench_harness::kit::ir::edges::EdgeMask)).
        // Writing it again as depth for the draws' depth test is this implementation's, not
        // the minimum's.
        let edges = self
            .lowres
            .as_ref()
            .map_or(StageCost::default(), |l| l.edges().cost);
        // `low-res`, `lights`: the leaves drawn once, every light of the store read once
        // (`GpuVpl`), per pixel drawn (the low resolution's, or the full one's) the G-buffer's
        // depth read (4) and the irradiance (Rgba16Float, 8) written once; with the low pass,
        // `lights` also reads the low image once (8 per low pixel). The (pixel, light) pairs'
        // arithmetic is not counted (see [`StageCosts`]).
        let vpl_bytes = std::mem::size_of::<gibench_harness::kit::ir::store::GpuVpl>() as u64;
        let store = StageCost::per_element(self.lights.len() as u64, vpl_bytes, 0, 0);
        let draws = leaves.plus(store);
        let (low_res, lights) = match &self.lowres {
            Some(l) => {
                let low = l.size[0] as u64 * l.size[1] as u64;
                (
                    draws.plus(StageCost::per_element(low, 4, 8, 0)),
                    draws
                        .plus(StageCost::per_element(pixels, 4, 8, 0))
                        .plus(StageCost::per_element(low, 8, 0, 0)),
                )
            }
            None => (
                StageCost::default(),
                draws.plus(StageCost::per_element(pixels, 4, 8, 0)),
            ),
        };
        // `prt`: per mover vertex its position (12 bytes) and 25 transfer coefficients (100)
        // read once, every index read once; per vertex 25 RGB products summed (75 FMAs, 150
        // operations), clamped (3) and moved to clip space (32). The pixels the movers cover
        // are not counted (known on the GPU only).
        let mut prt = StageCost::default();
        for m in scene.movers.iter() {
            let vertices = m.vertices.size() / std::mem::size_of::<Vertex>() as u64;
            prt = prt
                .plus(StageCost::per_element(vertices, 12 + 100, 0, 185))
                .plus(StageCost::per_element(m.indices.size(), 1, 0, 0));
        }
        StageCosts {
            shadow_map,
            light_maps,
            edges,
            low_res,
            lights,
            prt,
        }
    }

    /// The low-resolution pass, where the level has one.
    pub fn lowres(&self) -> Option<&LowRes> {
        self.lowres.as_ref()
    }

    /// Updates for `frame` and records all its passes into `encoder` (the harness has written
    /// its uniforms and recorded the G-buffer before): the steps below in order.
    #[allow(clippy::too_many_arguments)]
    pub fn frame(
        &mut self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        bvh: &SceneBvh,
        frame: &FrameState,
    ) -> Result<FrameCounts> {
        let mut counts = self.update(gpu, frame)?;
        (counts.maps_rendered, counts.map_faces) =
            self.encode_shadow_maps(gpu, encoder, scene, uniforms);
        self.encode_light_maps(encoder, uniforms);
        self.encode_edges(encoder);
        counts.light_draws =
            self.encode_low(encoder, uniforms) + self.encode_lights(encoder, uniforms);
        self.prt_lighting(gpu, bvh);
        self.encode_prt(encoder, scene, uniforms);
        Ok(counts)
    }

    /// CPU, before the passes: every mover that moved is moved in the visibility database, the
    /// light maps updated (and uploaded), the shadow maps due chosen and, when a mover moved (or
    /// on the first frame), the light draws planned again. The counts but `maps_rendered` and
    /// `light_draws`.
    pub fn update(&mut self, gpu: &GpuContext, frame: &FrameState) -> Result<FrameCounts> {
        let mut counts = FrameCounts::default();
        let mut changed = false;
        // The plan depends only on the database: redone when a mover moved (and first).
        let mut replan = self.first;
        for (k, pose) in frame.movers.iter().enumerate() {
            if pose.abs_diff_eq(self.poses[k], 0.0) {
                continue;
            }
            replan = true;
            let delta = *pose * self.poses[k].inverse();
            let object = self.bz.first_mover_object + k as u32;
            let update = self
                .bz
                .db
                .move_object(object, |p| delta.transform_point3(p));
            self.bz
                .light_maps
                .apply(&self.bz.db, &self.bz.flux, &update.light_map, object);
            self.schedule.mark(&update.shadow_maps);
            counts.light_map_changes += update.light_map.len() as u32;
            changed |= !update.light_map.is_empty();
            self.poses[k] = *pose;
        }
        if changed {
            self.light_map.upload(gpu, &self.bz.light_maps);
        }
        self.render.clear();
        if self.first {
            self.first = false;
            self.render.extend_from_slice(&self.lights);
        } else {
            let due = self.schedule.next_frame(self.settings.updates as usize);
            self.render
                .extend(due.into_iter().map(|l| self.lights[l as usize]));
        }
        // §4.2.2: the faces of each due map that hold an occluder (the movers at their poses).
        self.faces.clear();
        if self.settings.face_cull {
            let (bounds, poses) = (&self.bz.movers, &self.poses);
            (self.occluders).set_spheres(bounds.iter().zip(poses).map(|(b, m)| b.posed(*m)));
            let (occ, atlas) = (&self.occluders, &self.atlas);
            (self.faces).extend(self.render.iter().map(|(_, v)| occ.faces(atlas, v)));
        }
        if replan {
            let level = self.settings.level;
            self.draws
                .plan(gpu, &self.bz.db, level.draws(), level == Optimisation::Full)?;
        }
        counts.elements = self.draws.elements() as u32;
        let (passes, unmerged) = self.draws.passes();
        (counts.passes, counts.passes_unmerged) = (passes as u32, unmerged as u32);
        Ok(counts)
    }

    /// The shadow maps due this frame (with the movers in them), each only into the faces
    /// [`update`](Self::update) found occluders in. Returns the maps and the faces drawn.
    pub fn encode_shadow_maps(
        &mut self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
    ) -> (u32, u32) {
        if self.render.is_empty() {
            return (0, 0);
        }
        self.raster.render_faces(
            gpu,
            encoder,
            &self.atlas,
            scene,
            uniforms,
            &self.render,
            &self.faces,
            AtlasClear::RenderedSlots,
        )
    }

    /// The light maps into the output (Full only).
    pub fn encode_light_maps(&self, encoder: &mut wgpu::CommandEncoder, uniforms: &FrameUniforms) {
        if self.settings.level == Optimisation::Full {
            self.light_map.encode(encoder, uniforms, &self.output_view);
        }
    }

    /// The edge detection and its depth mask (levels with the low-resolution pass).
    pub fn encode_edges(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(lowres) = &self.lowres {
            lowres.encode_mask(encoder);
        }
    }

    /// The light draws at low resolution (levels with the low-resolution pass). Returns the
    /// draws.
    pub fn encode_low(&self, encoder: &mut wgpu::CommandEncoder, uniforms: &FrameUniforms) -> u32 {
        match &self.lowres {
            Some(lowres) => self
                .draws
                .encode_low(encoder, uniforms, &self.atlas, lowres),
            None => 0,
        }
    }

    /// The light draws at full resolution: everywhere, or, with the low-resolution pass, its
    /// interpolated image off the edges and the draws on them. Returns the draws.
    pub fn encode_lights(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        uniforms: &FrameUniforms,
    ) -> u32 {
        match &self.lowres {
            Some(lowres) => {
                self.draws
                    .encode_edges(encoder, uniforms, &self.atlas, &self.output_view, lowres)
            }
            None => self
                .draws
                .encode(encoder, uniforms, &self.atlas, &self.output_view),
        }
    }

    /// CPU: each mover's lighting environment from the samples its centre sees (ray casts
    /// against the static BVH), uploaded.
    pub fn prt_lighting(&mut self, gpu: &GpuContext, bvh: &SceneBvh) {
        for (k, bounds) in self.bz.movers.iter().enumerate() {
            let model = self.poses[k];
            let (centre, _) = bounds.posed(model);
            let r = Mat3::from_mat4(model);
            let to_object = Mat3::from_cols(
                r.x_axis.normalize(),
                r.y_axis.normalize(),
                r.z_axis.normalize(),
            )
            .transpose();
            let lift = self.atlas.lift;
            let lighting = prt::lighting(centre, to_object, &self.samples, |v| {
                !bvh.occluded(centre, v.position + v.normal * lift, lift)
            });
            self.prt.set_lighting(gpu, k, &lighting);
        }
    }

    /// The movers by PRT.
    pub fn encode_prt(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
    ) {
        self.prt.encode(encoder, scene, uniforms, &self.output_view);
    }
}
