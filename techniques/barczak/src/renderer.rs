//! The parts wired for one frame after another (Barczak 2006 §4.3–4.5), at the optimisation
//! levels Full, VD and Naive (the low-resolution pass, for VD+LP and Full's own, is to come).
//!
//! Reads: the scene (patches, movers), the harness's G-buffer, uniforms and static BVH, each
//! frame's mover poses.
//! Writes: `output` (Rgba16Float irradiance of the light samples): on patches, per [`Level`],
//! light maps minus the occluded partial lights, or the lights drawn with or without lookups;
//! PRT on movers.
//!
//! Per frame: every mover that moved is moved in the visibility database (Table 4-1), the light
//! maps gain or lose single lights, and the shadow maps the motion touched go out of date; the
//! schedule re-renders `updates` of them by priority (all on the first frame); the light draws
//! are planned (optimised when `optimise`) and drawn; each mover's lighting environment is gathered
//! from the samples its centre sees (ray casts against the static BVH) and drawn by PRT.

use std::sync::Arc;

use gibench_harness::anim::FrameState;
use gibench_harness::bvh::SceneBvh;
use gibench_harness::gpu::GpuContext;
use gibench_harness::ir::atlas::{AtlasFormat, AtlasSettings, MapKind, ShadowAtlas};
use gibench_harness::ir::raster::{AtlasClear, AtlasRasteriser};
use gibench_harness::ir::store::VplStore;
use gibench_harness::passes::{
    render_target, DrawSet, FrameUniforms, GBuffer, GpuScene, HDR_FORMAT,
};
use gibench_harness::scene::Scene;
use gibench_harness::vpl::Vpl;
use gibench_harness::{wgpu, Result};
use glam::{Mat3, Mat4};

use crate::light_draws::{Level, LightDraws};
use crate::lightmap_pass::{Leaves, LightMapPass};
use crate::prt::{self, COEFFS};
use crate::prt_pass::PrtPass;
use crate::samples::SampleSettings;
use crate::schedule::ShadowMapSchedule;
use crate::setup::{prepare, BarczakScene};

/// The renderer's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RendererSettings {
    pub samples: SampleSettings,
    /// Light-map texels along a leaf's edge.
    pub light_map_res: u32,
    /// Lights per subtraction draw (K).
    pub lights_per_draw: u32,
    /// Merge elements by Figure 4-10's optimiser (at [`Level::Full`] only: the thesis' other
    /// levels draw each leaf on its own).
    pub optimise: bool,
    /// What the light draws do (light maps only with [`Level::Full`]).
    pub level: Level,
    /// Octahedral map edge, texels.
    pub map_size: u32,
    /// Shadow maps re-rendered per frame at most (after the first).
    pub updates: u32,
    /// Directions of the PRT transfer integral.
    pub prt_directions: usize,
}

/// What a frame did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameCounts {
    pub maps_rendered: u32,
    /// Draws of lights over leaves (the thesis' passes).
    pub light_draws: u32,
    pub elements: u32,
    pub light_map_changes: u32,
}

/// See the module docs.
pub struct Renderer {
    bz: BarczakScene,
    /// The light samples by slot, and as a plain list (for the PRT lighting).
    lights: Vec<(u32, Vpl)>,
    samples: Vec<Vpl>,
    /// This frame's maps to render (kept between frames: no allocation per frame).
    render: Vec<(u32, Vpl)>,
    atlas: ShadowAtlas,
    raster: AtlasRasteriser,
    light_map: LightMapPass,
    draws: LightDraws,
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
        let bz = prepare(
            scene,
            bvh,
            frame,
            &frame.light,
            settings.samples,
            settings.light_map_res,
        )?;
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
        let leaves = Arc::new(Leaves::new(gpu, &bz.db));
        let light_map = LightMapPass::new(gpu, uniforms, gbuffer, leaves.clone(), &bz.light_maps)?;
        let draws = LightDraws::new(
            gpu,
            uniforms,
            gbuffer,
            leaves,
            n,
            settings.lights_per_draw,
            &store,
            &atlas,
        )?;
        let transfers: Vec<Vec<[f32; COEFFS]>> = scene
            .movers
            .iter()
            .map(|m| {
                let lift = 1e-4 * scene.extent.diagonal;
                prt::transfer(
                    &m.mesh,
                    &SceneBvh::new(&m.mesh),
                    settings.prt_directions,
                    lift,
                )
            })
            .collect();
        let prt = PrtPass::new(gpu, uniforms, gbuffer, &transfers)?;
        let schedule = ShadowMapSchedule::new(bz.flux.iter().copied());
        let output = render_target(&gpu.device, "barczak irradiance", gbuffer.size, HDR_FORMAT);
        let output_view = output.create_view(&Default::default());
        Ok(Renderer {
            poses: frame.movers.clone(),
            samples: lights.iter().map(|(_, v)| *v).collect(),
            render: Vec::with_capacity(lights.len()),
            bz,
            lights,
            atlas,
            raster,
            light_map,
            draws,
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

    /// Updates for `frame` and records its passes (the harness has written its uniforms and
    /// recorded the G-buffer before).
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
        let mut counts = FrameCounts::default();
        let mut changed = false;
        for (k, pose) in frame.movers.iter().enumerate() {
            if pose.abs_diff_eq(self.poses[k], 0.0) {
                continue;
            }
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
        if !self.render.is_empty() {
            counts.maps_rendered = self.raster.render(
                gpu,
                encoder,
                &self.atlas,
                scene,
                uniforms,
                &self.render,
                AtlasClear::RenderedSlots,
            );
        }
        let optimise = self.settings.optimise && self.settings.level == Level::Full;
        counts.light_draws = self
            .draws
            .plan(gpu, &self.bz.db, self.settings.level, optimise)?;
        counts.elements = self.draws.elements() as u32;
        if self.settings.level == Level::Full {
            self.light_map.encode(encoder, uniforms, &self.output_view);
        }
        self.draws
            .encode(encoder, uniforms, &self.atlas, &self.output_view);
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
        self.prt.encode(encoder, scene, uniforms, &self.output_view);
        Ok(counts)
    }
}
