//! Keller's instant radiosity (Keller 1997), two ways:
//!
//! * **`keller-full`** — every frame, trace quasi-random (Halton) light paths from the current
//!   primary light until there are `vpls` VPLs (the fewest paths that give that many; each
//!   path carries Φ / paths), a VPL at each path vertex (Keller's fractional absorption by the
//!   scene's average reflectance for bounces beyond the first), render all of their shadow
//!   maps, and gather. This is also the comparison method of Laine et al. 2007's Table 1.
//! * **`keller-incremental`** — Keller's interactive variant as the Kautz course slides state
//!   it: keep the last N light paths (and their shadow maps), each frame replace the oldest
//!   `budget` of them by new ones traced from the current light (continuing the Halton sequence)
//!   and accumulate. N is the number of paths `keller-full` needs for `vpls` VPLs at the first
//!   frame, so both light a frame with about the same number of VPLs. The ring holds the same
//!   distribution as `keller-full`'s N paths ([`PathRing`]). When the light moves the
//!   illumination lags behind, by design; the lag is measured per frame against the reference
//!   (`gibench run --quality --quality-all`).
//!
//! `vpls` means the same for every VPL technique: the number of VPLs lighting the frame (the
//! `vpls` counter of the results records it per frame).
//!
//! Both gather with the harness's interleaved sampling (split, accumulate, combine, geometry-aware
//! filter; Laine §5) and paraboloid or cube VPL maps, so only VPL management differs.
//!
//! Deviations: Keller rendered each VPL's full image with hardware shadow volumes and an
//! accumulation buffer; here every VPL is gathered per pixel through shadow maps and interleaved
//! sampling (as Segovia et al. and Laine et al. do). Because the camera moves, the incremental
//! variant keeps VPLs and their shadow maps, not per-VPL images, and re-gathers every frame.
//!
//! Needs: compute shaders and storage buffers (GL ES 3.1 / Vulkan), no optional features.

mod params;
mod ring;

pub use params::KellerParams;
pub use ring::PathRing;

use gibench_harness::cpu::vpl::{self, Vpl};
use gibench_harness::kit::ir::gather::{VplGather, GATHER_PARAMS};
use gibench_harness::kit::ir::raster::AtlasClear;
use gibench_harness::kit::passes::DrawSet;
use gibench_harness::kit::technique::IndirectComponent;
use gibench_harness::kit::technique::{
    cornell_boxes, Conformance, Converged, FrameContext, Knob, Params, PrepareContext, Prepared,
    Technique, TechniqueInfo,
};
use gibench_harness::{wgpu, Error, Result};

use params::{FULL_OWN, INCREMENTAL_OWN};

/// Stage: tracing light paths and placing VPLs on the CPU.
pub const STAGE_VPL_GENERATION: &str = "vpl-generation";
/// Keller's own stage, declared.
const OWN_STAGES: &[gibench_harness::kit::technique::Stage] =
    &[gibench_harness::kit::technique::Stage::cpu(
        STAGE_VPL_GENERATION,
    )];

/// `keller-full`'s known bias on the Cornell boxes against the one-bounce reference (64 VPLs,
/// 4x4 tiles; measured on lavapipe, 96x72, after three frames): the mean within 5 % of the
/// reference's; the omni and sun boxes' larger L1 is their hot spots near the light and few
/// VPLs inside.
const CONFORMANCE_FULL: Conformance = Conformance {
    defaults: &cornell_boxes([
        (0.959, 0.304),
        (0.965, 0.349),
        (0.967, 0.720),
        (1.052, 0.566),
    ]),
    converged: Converged {
        params: &["vpls=1024"],
        why: "1024 VPLs (16x the defaults; 64 per pixel under the 4x4 tiles): the VPLs' noise and hot spots shrink; left: the clamp (k = 10) and the shadow maps' depth bias",
        boxes: &cornell_boxes([(0.974, 0.100), (0.985, 0.107), (0.991, 0.666), (1.006, 0.210)]),
    },
};

/// `keller-incremental`'s, measured the same way: the same VPL count, some of it kept from
/// earlier frames.
const CONFORMANCE_INCREMENTAL: Conformance = Conformance {
    defaults: &cornell_boxes([
        (0.973, 0.388),
        (0.994, 0.420),
        (0.973, 0.700),
        (0.956, 0.632),
    ]),
    converged: Converged {
        params: &["vpls=1024"],
        why: "1024 VPLs (16x the defaults; 64 per pixel under the 4x4 tiles): the VPLs' noise and hot spots shrink; left: the clamp (k = 10) and the shadow maps' depth bias; the ring still holds paths from earlier frames' light and bunny",
        boxes: &cornell_boxes([(0.957, 0.326), (0.981, 0.311), (0.983, 0.660), (0.962, 0.429)]),
    },
};

/// What Keller's VPLs light with `params`: one bounce from single-vertex paths, several with
/// `bounces` > 1 (Keller's fractional absorption).
fn computed_component(params: &Params) -> IndirectComponent {
    if params.has("bounces") && params.int("bounces") > 1 {
        IndirectComponent::MultiBounce
    } else {
        IndirectComponent::OneBounce
    }
}

/// `keller-full` registry entry.
pub const FULL: TechniqueInfo = TechniqueInfo {
    name: "keller-full",
    paper: "Keller 1997",
    summary: "instant radiosity, every VPL map every frame",
    description: "Keller instant radiosity: all VPLs and their shadow maps recomputed every frame",
    stages: &[
        OWN_STAGES,
        gibench_harness::kit::ir::gather::SHADOW_MAP_STAGES,
        gibench_harness::kit::ir::gather::GATHER_STAGES,
    ],
    params: &[FULL_OWN, GATHER_PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: computed_component,
    conformance: CONFORMANCE_FULL,
    knob: Some(Knob::VPLS),
    prepare,
    create: create_full,
};

/// `keller-incremental` registry entry.
pub const INCREMENTAL: TechniqueInfo = TechniqueInfo {
    name: "keller-incremental",
    paper: "Keller 1997",
    summary: "a ring of light paths, oldest replaced",
    description: "Keller instant radiosity: keep the last N paths, replace the oldest `budget` per frame, accumulate",
    stages: &[OWN_STAGES, gibench_harness::kit::ir::gather::SHADOW_MAP_STAGES, gibench_harness::kit::ir::gather::GATHER_STAGES],
    params: &[INCREMENTAL_OWN, GATHER_PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: computed_component,
    conformance: CONFORMANCE_INCREMENTAL,
    knob: Some(Knob::VPLS),
    prepare,
    create: create_incremental,
};

/// What both Keller techniques prepare once per scene: Keller's ρ̄ (the mean of the channels of
/// the scene's area-weighted average reflectance, one pass over the static mesh).
struct KellerPrepared {
    average_reflectance: f32,
}

fn prepare(_: &Params, ctx: &PrepareContext) -> Result<Prepared> {
    Ok(Box::new(KellerPrepared {
        average_reflectance: vpl::mean_reflectance(ctx.scene),
    }))
}

fn prepared_rho(prepared: &Prepared) -> Result<f32> {
    prepared
        .downcast_ref::<KellerPrepared>()
        .map(|p| p.average_reflectance)
        .ok_or_else(|| Error::Invalid("keller: built without its preparation".into()))
}

/// `keller-full`.
pub struct KellerFull {
    gather: VplGather,
    vpls: u32,
    bounces: u32,
    average_reflectance: f32,
}

fn create_full(
    params: &Params,
    ctx: &PrepareContext,
    prepared: &Prepared,
) -> Result<Box<dyn Technique>> {
    let p = KellerParams::from_params(params)?;
    // More bounces can overshoot the count by a path's worth of VPLs.
    let capacity = p.vpls + p.bounces;
    let gather = VplGather::new(&p.gather, ctx, capacity, Some(DrawSet::StaticCasters))?;
    Ok(Box::new(KellerFull {
        gather,
        vpls: p.vpls,
        bounces: p.bounces,
        average_reflectance: prepared_rho(prepared)?,
    }))
}

impl Technique for KellerFull {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let (scene, bvh, light) = (ctx.scene, ctx.bvh, ctx.frame.light);
        let (target, bounces, rho) = (self.vpls, self.bounces, self.average_reflectance);
        let (settings, vpls) = ctx.profiler.cpu_stage(STAGE_VPL_GENERATION, || {
            let (settings, vpls) = vpl::generate_at_least(scene, bvh, &light, target, bounces, rho);
            let vpls: Vec<(u32, Vpl)> = vpls
                .into_iter()
                .enumerate()
                .map(|(i, v)| (i as u32, v))
                .collect();
            (settings, vpls)
        });
        ctx.profiler.count("light-paths", settings.paths as f64);
        // Every map is re-rendered: clear the whole atlas.
        self.gather.render_maps(ctx, &vpls, AtlasClear::Whole)?;
        self.gather.gather(ctx, &vpls)
    }

    fn output(&self) -> &wgpu::TextureView {
        self.gather.output()
    }
}

/// `keller-incremental`: the shared gathering over a [`PathRing`].
pub struct KellerIncremental {
    gather: VplGather,
    budget: u32,
    ring: PathRing,
    started: bool,
}

fn create_incremental(
    params: &Params,
    ctx: &PrepareContext,
    prepared: &Prepared,
) -> Result<Box<dyn Technique>> {
    let p = KellerParams::from_params(params)?;
    let rho = prepared_rho(prepared)?;
    // N: the paths keller-full needs for `vpls` VPLs under the first frame's light.
    let (settings, _) = vpl::generate_at_least(
        ctx.scene,
        ctx.bvh,
        &ctx.first_frame.light,
        p.vpls,
        p.bounces,
        rho,
    );
    let ring = PathRing::new(settings.paths, p.bounces, rho);
    let gather = VplGather::new(
        &p.gather,
        ctx,
        ring.paths() * p.bounces,
        Some(DrawSet::StaticCasters),
    )?;
    Ok(Box::new(KellerIncremental {
        gather,
        budget: p.budget,
        ring,
        started: false,
    }))
}

impl Technique for KellerIncremental {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let (scene, bvh, light) = (ctx.scene, ctx.bvh, ctx.frame.light);
        let first = !self.started;
        self.started = true;
        let count = if first {
            self.ring.paths()
        } else {
            self.budget
        };
        let ring = &mut self.ring;
        let new_vpls = ctx.profiler.cpu_stage(STAGE_VPL_GENERATION, || {
            ring.advance(scene, bvh, &light, count)
        });
        ctx.profiler.count("light-paths", self.ring.paths() as f64);
        // The first frame renders every map; later frames only the replaced paths' maps.
        let clear = if first {
            AtlasClear::Whole
        } else {
            AtlasClear::RenderedSlots
        };
        self.gather.render_maps(ctx, &new_vpls, clear)?;
        self.gather.gather(ctx, &self.ring.vpls())
    }

    fn output(&self) -> &wgpu::TextureView {
        self.gather.output()
    }
}
