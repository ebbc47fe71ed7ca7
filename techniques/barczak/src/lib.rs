//! `barczak`: Barczak 2006, "Interactive Illumination Using Large Sets of Point
//! Lights" (M.S. thesis, University of Maryland) — light-mapped, visibility-culled instant
//! radiosity with moving objects.
//!
//! The parts, each tested on its own (the CPU ones against brute force, the GPU ones against the
//! CPU):
//!
//! * [`visibility`] — §4.3.1: occlusion pyramids from patches (and complex objects' bounding
//!   spheres) to each light, polygon and sphere blockers, lights classified unblocked / partial /
//!   fully blocked, hierarchical patch subdivision with early termination.
//! * [`blocker_index`] — a hierarchy of the blockers' boxes, so that a pyramid is tested only
//!   against blockers that may reach into it (the same database, affordable on tens of
//!   thousands of chart patches).
//! * [`database`] — §4.5.1–4.5.2: the visibility database of every receiver node and light,
//!   updated by Table 4-1 when an object moves, with the light-map changes and the shadow
//!   maps a motion affects.
//! * [`lightmap`] — §4.3.2, §4.5.2: a light map per leaf sub-patch holding its lit lights'
//!   irradiance without visibility, updated by single lights when a motion blocks or frees
//!   them; with the partial lights' subtraction it equals summing every light with visibility.
//! * [`lightmap_pass`] — §4.3.2 on the GPU: the light maps drawn for every patch leaf the camera
//!   sees (one draw), bilinear inside each leaf.
//! * [`light_draws`] — §4.3.2's second pass drawn as §4.3.4–4.3.5 do: per optimised element,
//!   draws of up to K lights (shared octahedral atlas lookups), subtracting the occluded partial
//!   lights after the light maps (Full), or adding lights with lookups only where partial (VD)
//!   or everywhere (Naive); the draws are counted.
//! * [`passes`] — §4.3.5: the greedy render-pass optimiser of Figure 4-10 over elements (sets of
//!   objects with the lights they share), a pass drawing up to K lights.
//! * [`schedule`] — §4.5.3: shadow maps a motion made out of date re-rendered a fixed number
//!   per frame, by brightness × frames out of date.
//! * [`prt`] — §4.4: 5th-order SH transfer per vertex of a complex mesh (self-shadowed, by ray
//!   casts, prepared once), the lighting environment at its centre from the visible light
//!   samples, and irradiance as their dot product.
//! * [`setup`] — the above put together from a scene once: receivers and blockers from the
//!   scene's patches and movers (`gibench_harness::scene::Patch`; the `barczak-*` rooms record
//!   them, other scenes get their planar charts, at most `max-charts`), light samples, the
//!   database and the light maps.
//! * [`prt_pass`] — §4.4 on the GPU: each mover drawn once, per vertex its transfer dotted with
//!   the lighting environment (taken into the mover's frame).
//! * [`renderer`] — the parts wired frame after frame: movers moved in the database, light maps
//!   and shadow maps updated (by priority), the subtraction planned and drawn, movers lit by PRT.
//! * [`samples`] — §4.1: the direct light samples on area emitters and the indirect ones from
//!   random walks, computed once from the static geometry.
//!
//! * [`lowres`] — §4.3.3: the lights drawn at low resolution, interpolated, and drawn again at
//!   full resolution where the kit's `EdgeMask` finds edges (written as depth, as the thesis).
//!
//! The shadow maps are the shared atlas's octahedral kind (§4.2.1,
//! `gibench_harness::kit::ir::atlas::MapKind::Octahedral`).
//!
//! **As a technique** ([`INFO`], `barczak`): the output is the irradiance of one light-sample
//! set — `set=indirect` (default: the random-walk samples, compared with the multi-bounce
//! reference) or `set=direct` (points on the area light: compare with `--quality-reference
//! direct`) — `vpls` samples either way (the shared meaning: the lights lighting the frame).
//! The samples are made once, from the light's pose at the first frame (the thesis' static
//! lights). Stages: `visibility` (CPU: movers in the database, light-map updates, schedule,
//! pass planning), `shadow-maps`, `light-maps`, `edges`, `low-res`, `lights`, `prt-lighting`
//! (CPU), `prt`; counters `vpls`, `maps-rendered`, `map-faces` (octahedral faces drawn into:
//! `face-cull=on` skips those without occluders), `light-draws`, `elements`, `passes` and
//! `passes-unmerged` (the light draws planned, and what the same elements would have needed
//! before Figure 4-10's render-pass optimiser merged them: its saving, at level `full`),
//! `light-map-changes`, and the database's size: `patches` (the scene's recorded patches or
//! generated charts) and `leaves` (their light-mapped sub-patches).

pub mod blocker_index;
pub mod database;
pub mod light_draws;
pub mod lightmap;
pub mod lightmap_pass;
pub mod lowres;
mod params;
pub mod passes;
pub mod prt;
pub mod prt_pass;
pub mod renderer;
pub mod samples;
pub mod schedule;
pub mod setup;
pub mod visibility;

pub use params::BarczakParams;

use gibench_harness::kit::technique::IndirectComponent;
use gibench_harness::kit::technique::{
    cornell_boxes, Conformance, Converged, FrameContext, Knob, KnownBias, Params, PrepareContext,
    Prepared, Technique, TechniqueInfo,
};
use gibench_harness::{wgpu, Error, Result};

use params::PARAMS;
use renderer::Renderer;

/// Stage (CPU): movers moved in the visibility database, light maps updated and uploaded,
/// shadow maps due chosen, light draws planned.
pub const STAGE_VISIBILITY: &str = "visibility";
/// Stage: the shadow maps due (octahedral, movers included).
pub const STAGE_SHADOW_MAPS: &str = "shadow-maps";
/// Stage: the light-map pass (Full).
pub const STAGE_LIGHT_MAPS: &str = "light-maps";
/// Stage: edge detection and its depth mask (low-resolution levels).
pub const STAGE_EDGES: &str = "edges";
/// Stage: the light draws at low resolution.
pub const STAGE_LOW_RES: &str = "low-res";
/// Stage: the light draws at full resolution (with the low-resolution pass: its interpolated
/// image off the edges and the draws on them).
pub const STAGE_LIGHTS: &str = "lights";
/// Stage (CPU): the movers' lighting environments (visible samples projected to SH).
pub const STAGE_PRT_LIGHTING: &str = "prt-lighting";
/// Stage: the movers drawn by PRT.
pub const STAGE_PRT: &str = "prt";
/// Every stage, declared, in frame order (the low-resolution ones only at levels `full` and
/// `vd-lp`, the light maps only at `full`).
pub const STAGES: &[gibench_harness::kit::technique::Stage] = &[
    gibench_harness::kit::technique::Stage::cpu(STAGE_VISIBILITY),
    gibench_harness::kit::technique::Stage::gpu(STAGE_SHADOW_MAPS),
    gibench_harness::kit::technique::Stage::gpu(STAGE_LIGHT_MAPS),
    gibench_harness::kit::technique::Stage::gpu(STAGE_EDGES),
    gibench_harness::kit::technique::Stage::gpu(STAGE_LOW_RES),
    gibench_harness::kit::technique::Stage::gpu(STAGE_LIGHTS),
    gibench_harness::kit::technique::Stage::cpu(STAGE_PRT_LIGHTING),
    gibench_harness::kit::technique::Stage::gpu(STAGE_PRT),
];

/// What barczak's light samples light with `params`: the area light's direct light
/// (`set=direct`, points on the light) or every bounce (`set=indirect`, random walks).
fn computed_component(params: &Params) -> IndirectComponent {
    if params.choice("set") == "direct" {
        IndirectComponent::Direct
    } else {
        IndirectComponent::MultiBounce
    }
}

/// Registry entry.
/// On the Cornell boxes and the papers' large scenes (their planar charts as patches, 64
/// indirect samples, 5 bounces, no clamp) against the 8-bounce reference (measured on lavapipe,
/// 96x72, after three frames): the omni box's L1 is unclamped samples close to its walls (hot
/// spots); Sibenik is 22 % dark and Maze 20 % bright at 64 samples, the conference room
/// (115,302 charts) 21 % dark.
const CONFORMANCE: [KnownBias; 8] = {
    let c = cornell_boxes([
        (0.844, 0.330),
        (0.948, 0.367),
        (1.045, 0.673),
        (1.059, 0.431),
    ]);
    [
        c[0],
        c[1],
        c[2],
        c[3],
        KnownBias::new("sibenik", 0.784, 0.323),
        KnownBias::new("sponza", 1.119, 0.321),
        KnownBias::new("maze", 1.205, 0.468),
        KnownBias::new("conference", 0.795, 0.365),
    ]
};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "barczak",
    paper: "Barczak 2006",
    summary: "light-mapped, visibility-culled instant radiosity",
    description: "Barczak 2006 light-mapped, visibility-culled instant radiosity with octahedral shadow maps, a low-resolution pass and PRT movers (level=full|vd-lp|vd|naive)",
    stages: &[STAGES],
    params: &[PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: computed_component,
    conformance: Conformance {
        defaults: &CONFORMANCE,
        converged: Converged {
            params: &["vpls=1024"],
            why: "1024 light samples (16x the defaults): the samples' noise and hot spots shrink; left: the light maps' resolution (8 texels a patch edge) and the random walks' five hits",
            boxes: &cornell_boxes([(0.952, 0.125), (0.985, 0.125), (0.962, 0.515), (0.973, 0.159)]),
        },
    },
    knob: Some(Knob::VPLS),
    prepare,
    create,
};

fn prepare(params: &Params, ctx: &PrepareContext) -> Result<Prepared> {
    let p = BarczakParams::from_params(params, ctx.resolution)?;
    Ok(Box::new(renderer::Prepared::new(
        ctx.gpu,
        ctx.scene,
        ctx.bvh,
        &ctx.first_frame,
        &p.renderer,
    )?))
}

fn create(
    params: &Params,
    ctx: &PrepareContext,
    prepared: &Prepared,
) -> Result<Box<dyn Technique>> {
    let p = BarczakParams::from_params(params, ctx.resolution)?;
    let prepared = prepared
        .downcast_ref::<renderer::Prepared>()
        .ok_or_else(|| Error::Invalid("barczak: prepared data of another technique".into()))?
        .clone();
    let renderer = Renderer::with(
        ctx.gpu,
        ctx.scene,
        ctx.uniforms,
        ctx.gbuffer,
        &ctx.first_frame,
        p.renderer,
        prepared,
    )?;
    // The database's size never changes after preparation: counted once, reported per frame.
    let patches_and_leaves = renderer.scene().patches_and_leaves();
    let costs = renderer.stage_costs(ctx.gpu_scene);
    Ok(Box::new(Barczak {
        renderer,
        patches_and_leaves,
        costs,
    }))
}

/// `barczak`.
pub struct Barczak {
    renderer: Renderer,
    /// The database's patch receivers and their leaves (the `patches` and `leaves` counters).
    patches_and_leaves: (usize, usize),
    /// The GPU stages' declared costs, computed once.
    costs: renderer::StageCosts,
}

impl Technique for Barczak {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let gpu = ctx.gpu;
        let (scene, uniforms, bvh, frame) = (ctx.gpu_scene, ctx.uniforms, ctx.bvh, ctx.frame);
        let r = &mut self.renderer;
        let costs = &self.costs;
        let mut counts = ctx
            .profiler
            .cpu_stage(STAGE_VISIBILITY, || r.update(gpu, frame))?;
        (counts.maps_rendered, counts.map_faces) =
            ctx.profiler.gpu_stage(gpu, STAGE_SHADOW_MAPS, |enc| {
                r.encode_shadow_maps(gpu, enc, scene, uniforms)
            })?;
        ctx.profiler.stage_cost(
            STAGE_SHADOW_MAPS,
            costs.shadow_map.scaled(counts.maps_rendered as f64),
        );
        ctx.profiler.gpu_stage(gpu, STAGE_LIGHT_MAPS, |enc| {
            r.encode_light_maps(enc, uniforms)
        })?;
        ctx.profiler.stage_cost(STAGE_LIGHT_MAPS, costs.light_maps);
        let low = r.lowres().is_some();
        if low {
            ctx.profiler
                .gpu_stage(gpu, STAGE_EDGES, |enc| r.encode_edges(enc))?;
            ctx.profiler.stage_cost(STAGE_EDGES, costs.edges);
            counts.light_draws += ctx
                .profiler
                .gpu_stage(gpu, STAGE_LOW_RES, |enc| r.encode_low(enc, uniforms))?;
            ctx.profiler.stage_cost(STAGE_LOW_RES, costs.low_res);
        }
        counts.light_draws += ctx
            .profiler
            .gpu_stage(gpu, STAGE_LIGHTS, |enc| r.encode_lights(enc, uniforms))?;
        ctx.profiler.stage_cost(STAGE_LIGHTS, costs.lights);
        ctx.profiler
            .cpu_stage(STAGE_PRT_LIGHTING, || r.prt_lighting(gpu, bvh));
        ctx.profiler
            .gpu_stage(gpu, STAGE_PRT, |enc| r.encode_prt(enc, scene, uniforms))?;
        ctx.profiler.stage_cost(STAGE_PRT, costs.prt);
        let samples = &r.scene().samples;
        let vpls = samples.direct.len() + samples.indirect.len();
        ctx.profiler.count("vpls", vpls as f64);
        ctx.profiler
            .count("maps-rendered", counts.maps_rendered as f64);
        ctx.profiler.count("map-faces", counts.map_faces as f64);
        ctx.profiler.count("light-draws", counts.light_draws as f64);
        ctx.profiler.count("elements", counts.elements as f64);
        ctx.profiler.count("passes", counts.passes as f64);
        ctx.profiler
            .count("passes-unmerged", counts.passes_unmerged as f64);
        ctx.profiler
            .count("light-map-changes", counts.light_map_changes as f64);
        let (patches, leaves) = self.patches_and_leaves;
        ctx.profiler.count("patches", patches as f64);
        ctx.profiler.count("leaves", leaves as f64);
        Ok(())
    }

    fn output(&self) -> &wgpu::TextureView {
        self.renderer.output_view()
    }
}
