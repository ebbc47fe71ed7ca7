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
//! `gibench_harness::ir::atlas::MapKind::Octahedral`).
//!
//! **As a technique** ([`INFO`], `barczak`): the output is the irradiance of one light-sample
//! set — `set=indirect` (default: the random-walk samples, compared with the multi-bounce
//! reference) or `set=direct` (points on the area light: compare with `--quality-reference
//! direct`) — `vpls` samples either way (the shared meaning: the lights lighting the frame).
//! The samples are made once, from the light's pose at the first frame (the thesis' static
//! lights). Stages: `visibility` (CPU: movers in the database, light-map updates, schedule,
//! pass planning), `shadow-maps`, `light-maps`, `edges`, `low-res`, `lights`, `prt-lighting`
//! (CPU), `prt`; counters `vpls`, `maps-rendered`, `map-faces` (octahedral faces drawn into:
//! `face-cull=on` skips those without occluders), `light-draws`, `elements`,
//! `light-map-changes`, and the database's size: `patches` (the scene's recorded patches or
//! generated charts) and `leaves` (their light-mapped sub-patches).

pub mod blocker_index;
pub mod database;
pub mod light_draws;
pub mod lightmap;
pub mod lightmap_pass;
pub mod lowres;
pub mod passes;
pub mod prt;
pub mod prt_pass;
pub mod renderer;
pub mod samples;
pub mod schedule;
pub mod setup;
pub mod visibility;

use gibench_harness::quality::IndirectComponent;
use gibench_harness::technique::{
    Conformance, FrameContext, ParamKind, ParamSpec, Params, PrepareContext, Prepared, Technique,
    TechniqueInfo,
};
use gibench_harness::{wgpu, Error, Result};

use renderer::{Optimisation, Renderer, RendererSettings};
use samples::SampleSettings;

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
/// Every stage, in frame order.
pub const STAGES: [&str; 8] = [
    STAGE_VISIBILITY,
    STAGE_SHADOW_MAPS,
    STAGE_LIGHT_MAPS,
    STAGE_EDGES,
    STAGE_LOW_RES,
    STAGE_LIGHTS,
    STAGE_PRT_LIGHTING,
    STAGE_PRT,
];

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "light samples lighting each frame (the thesis: up to 300)",
    },
    ParamSpec {
        name: "set",
        kind: ParamKind::Choice(&["indirect", "direct"]),
        default: "indirect",
        doc: "indirect: samples at the hits of random walks from the light (§4.1; compare with the multi-bounce reference); direct: points on the area light (soft shadows; compare with --quality-reference direct)",
    },
    ParamSpec {
        name: "bounces",
        kind: ParamKind::Int { min: 1, max: 16 },
        default: "5",
        doc: "hits per random walk at most (the thesis' Figure 5-10: 5)",
    },
    ParamSpec {
        name: "level",
        kind: ParamKind::Choice(&Optimisation::NAMES),
        default: "full",
        doc: "Figure 5-3's optimisation level: full (light maps, visibility determination, low-resolution pass, pass optimiser), vd-lp, vd, naive (every light with a lookup everywhere)",
    },
    ParamSpec {
        name: "lights-per-draw",
        kind: ParamKind::Int { min: 1, max: 16 },
        default: "7",
        doc: "lights one draw handles (the thesis' X800: 7 per pass)",
    },
    ParamSpec {
        name: "lowres",
        kind: ParamKind::Int { min: 2, max: 16 },
        default: "2",
        doc: "the low-resolution pass's factor (levels full and vd-lp); the resolution must be a multiple of it",
    },
    ParamSpec {
        name: "edge-step",
        kind: ParamKind::Int { min: 1, max: 64 },
        default: "3",
        doc: "pixels stepped by the edge detection of the low-resolution pass (at least the factor)",
    },
    ParamSpec {
        name: "vpl-map-size",
        kind: ParamKind::Int { min: 8, max: 4096 },
        default: "128",
        doc: "octahedral shadow-map edge in texels",
    },
    ParamSpec {
        name: "updates",
        kind: ParamKind::Int { min: 0, max: 4096 },
        default: "32",
        doc: "shadow maps a moving object made out of date re-rendered per frame, brightest and oldest first (the thesis: 100-150 of 300)",
    },
    ParamSpec {
        name: "face-cull",
        kind: ParamKind::Choice(&["on", "off"]),
        default: "on",
        doc: "on: a shadow map is drawn only into the octahedral faces that hold an occluder (the thesis' §4.2.2 culling test); off: into all four",
    },
    ParamSpec {
        name: "light-map-res",
        kind: ParamKind::Int { min: 1, max: 64 },
        default: "8",
        doc: "light-map texels along a patch leaf's edge",
    },
    ParamSpec {
        name: "max-charts",
        kind: ParamKind::Int { min: 1, max: 1_000_000 },
        default: "60000",
        doc: "planar charts a scene that records no patches may make (one patch each; preparation time and memory grow with them: Sibenik makes 25,010, Maze 53,219, the conference room 115,302)",
    },
    ParamSpec {
        name: "prt-directions",
        kind: ParamKind::Int { min: 16, max: 65536 },
        default: "256",
        doc: "ray directions of each mover vertex's PRT transfer integral (prepared once)",
    },
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
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "barczak",
    description: "Barczak 2006 light-mapped, visibility-culled instant radiosity with octahedral shadow maps, a low-resolution pass and PRT movers (level=full|vd-lp|vd|naive)",
    params: &[PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: computed_component,
    // On the Cornell boxes (their planar charts as patches, 64 indirect samples, 5 bounces, no
    // clamp) against the 8-bounce reference, measured: relative L1 0.33 (spot), 0.37 (area),
    // 0.67 (omni: unclamped samples close to the walls make hot spots), 0.43 (sun); mean ratio
    // 0.84-1.06 (one patch per triangle gave the same within 0.01). Halving the samples' flux
    // puts the ratio near 0.5, outside the bounds.
    conformance: Conformance {
        max_relative_l1: 0.8,
        mean_ratio: (0.7, 1.3),
    },
    prepare,
    create,
};

/// The parameters, read once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BarczakParams {
    pub renderer: RendererSettings,
}

impl BarczakParams {
    /// Reads `params` for a run at `resolution`; errors name the parameter.
    pub fn from_params(params: &Params, resolution: [u32; 2]) -> Result<BarczakParams> {
        let vpls = params.int("vpls") as u32;
        let samples = if params.choice("set") == "direct" {
            SampleSettings {
                direct: vpls,
                indirect: 0,
                bounces: params.int("bounces") as u32,
            }
        } else {
            SampleSettings {
                direct: 0,
                indirect: vpls,
                bounces: params.int("bounces") as u32,
            }
        };
        let level = Optimisation::parse(params.choice("level"))?;
        let lowres = params.int("lowres") as u32;
        let edge_step = params.int("edge-step") as u32;
        if level.low_res() {
            let [w, h] = resolution;
            if w % lowres != 0 || h % lowres != 0 {
                return Err(Error::param(
                    "lowres",
                    format!("the resolution {w}x{h} is not a multiple of the factor {lowres} (level {})", level.name()),
                ));
            }
            // The interpolation reads low-resolution samples up to a factor's width away and
            // the edge detection compares pixels `edge-step` apart: a step below the factor
            // misses edges the interpolation reads across.
            if edge_step < lowres {
                return Err(Error::param(
                    "edge-step",
                    format!("{edge_step} is below the low-resolution factor {lowres} (level {}): expected at least the factor", level.name()),
                ));
            }
        }
        Ok(BarczakParams {
            renderer: RendererSettings {
                samples,
                light_map_res: params.int("light-map-res") as u32,
                lights_per_draw: params.int("lights-per-draw") as u32,
                level,
                lowres,
                edge_step,
                map_size: params.int("vpl-map-size") as u32,
                updates: params.int("updates") as u32,
                prt_directions: params.int("prt-directions") as usize,
                face_cull: params.choice("face-cull") == "on",
                max_charts: params.int("max-charts") as usize,
            },
        })
    }
}

fn prepare(params: &Params, ctx: &PrepareContext) -> Result<Prepared> {
    let p = BarczakParams::from_params(params, ctx.resolution)?;
    Ok(Box::new(renderer::Prepared::new(
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
    Ok(Box::new(Barczak {
        renderer,
        patches_and_leaves,
    }))
}

/// `barczak`.
pub struct Barczak {
    renderer: Renderer,
    /// The database's patch receivers and their leaves (the `patches` and `leaves` counters).
    patches_and_leaves: (usize, usize),
}

impl Technique for Barczak {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let gpu = ctx.gpu;
        let (scene, uniforms, bvh, frame) = (ctx.gpu_scene, ctx.uniforms, ctx.bvh, ctx.frame);
        let r = &mut self.renderer;
        let mut counts = ctx
            .profiler
            .cpu_stage(STAGE_VISIBILITY, || r.update(gpu, frame))?;
        (counts.maps_rendered, counts.map_faces) =
            ctx.profiler.gpu_stage(gpu, STAGE_SHADOW_MAPS, |enc| {
                r.encode_shadow_maps(gpu, enc, scene, uniforms)
            })?;
        ctx.profiler.gpu_stage(gpu, STAGE_LIGHT_MAPS, |enc| {
            r.encode_light_maps(enc, uniforms)
        })?;
        let low = r.lowres().is_some();
        if low {
            ctx.profiler
                .gpu_stage(gpu, STAGE_EDGES, |enc| r.encode_edges(enc))?;
            counts.light_draws += ctx
                .profiler
                .gpu_stage(gpu, STAGE_LOW_RES, |enc| r.encode_low(enc, uniforms))?;
        }
        counts.light_draws += ctx
            .profiler
            .gpu_stage(gpu, STAGE_LIGHTS, |enc| r.encode_lights(enc, uniforms))?;
        ctx.profiler
            .cpu_stage(STAGE_PRT_LIGHTING, || r.prt_lighting(gpu, bvh));
        ctx.profiler
            .gpu_stage(gpu, STAGE_PRT, |enc| r.encode_prt(enc, scene, uniforms))?;
        let samples = &r.scene().samples;
        let vpls = samples.direct.len() + samples.indirect.len();
        ctx.profiler.count("vpls", vpls as f64);
        ctx.profiler
            .count("maps-rendered", counts.maps_rendered as f64);
        ctx.profiler.count("map-faces", counts.map_faces as f64);
        ctx.profiler.count("light-draws", counts.light_draws as f64);
        ctx.profiler.count("elements", counts.elements as f64);
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
