//! Keller's instant radiosity (Keller 1997), two ways:
//!
//! * **`keller-full`** — every frame, trace `vpls` quasi-random (Halton) light paths from the
//!   current primary light, place a VPL at each path vertex (Keller's fractional absorption by
//!   the scene's average reflectance for bounces beyond the first), render all of their shadow
//!   maps, and gather. This is also the comparison method of Laine et al. 2007's Table 1.
//! * **`keller-incremental`** — Keller's interactive variant as the Kautz course slides state
//!   it: keep the last N light paths (and their shadow maps), each frame replace the oldest
//!   `budget` of them by new ones traced from the current light (continuing the Halton sequence)
//!   and accumulate. When the light moves the illumination lags behind, by design; the lag is
//!   measured per frame against the reference (`gibench run --quality --quality-all`).
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

use gibench_harness::ir::gather::{GatherParams, VplGather, GATHER_PARAMS};
use gibench_harness::ir::raster::AtlasClear;
use gibench_harness::passes::DrawSet;
use gibench_harness::quality::IndirectComponent;
use gibench_harness::technique::{
    Conformance, FrameContext, ParamKind, ParamSpec, Params, PrepareContext, Prepared, Technique,
    TechniqueInfo,
};
use gibench_harness::vpl::{self, Vpl, VplSettings};
use gibench_harness::{wgpu, Error, Result};

/// Stage: tracing light paths and placing VPLs on the CPU.
pub const STAGE_VPL_GENERATION: &str = "vpl-generation";

const BOUNCES: ParamSpec = ParamSpec {
    name: "bounces",
    kind: ParamKind::Int { min: 1, max: 8 },
    default: "1",
    doc: "path vertices per light path (1 = single bounce as in Laine; more use Keller's fractional absorption)",
};

const FULL_OWN: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "light paths traced per frame (= first-bounce VPLs; Laine's comparison: 256)",
    },
    BOUNCES,
];

const INCREMENTAL_OWN: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "light paths kept (N); the first frame traces all of them",
    },
    ParamSpec {
        name: "budget",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "4",
        doc: "oldest paths replaced by new ones each frame",
    },
    BOUNCES,
];

/// Conformance on the Cornell boxes against the one-bounce reference (64 paths, 4x4 tiles):
/// measured relative L1 0.35–0.76 and mean ratio 0.91–1.03 over the spot, area, omni and sun
/// boxes (the omni and sun boxes are the hard ones: few VPLs inside, hot spots near the light).
const CONFORMANCE: Conformance = Conformance {
    max_relative_l1: 0.85,
    mean_ratio: (0.85, 1.08),
};

/// `keller-full` registry entry.
pub const FULL: TechniqueInfo = TechniqueInfo {
    name: "keller-full",
    description: "Keller instant radiosity: all VPLs and their shadow maps recomputed every frame",
    params: &[FULL_OWN, GATHER_PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: IndirectComponent::OneBounce,
    conformance: CONFORMANCE,
    prepare,
    create: create_full,
};

/// `keller-incremental` registry entry.
pub const INCREMENTAL: TechniqueInfo = TechniqueInfo {
    name: "keller-incremental",
    description: "Keller instant radiosity: keep the last N paths, replace the oldest `budget` per frame, accumulate",
    params: &[INCREMENTAL_OWN, GATHER_PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: IndirectComponent::OneBounce,
    conformance: CONFORMANCE,
    prepare,
    create: create_incremental,
};

/// The parameters of both Keller techniques, read once.
#[derive(Clone, Copy, Debug)]
pub struct KellerParams {
    /// N: light paths per frame (full) or kept (incremental).
    pub paths: u32,
    pub bounces: u32,
    /// Paths replaced per frame (incremental; at most `paths`).
    pub budget: u32,
    pub gather: GatherParams,
}

impl KellerParams {
    pub fn from_params(params: &Params) -> Result<KellerParams> {
        let paths = params.int("vpls") as u32;
        let budget = if params.has("budget") {
            params.int("budget") as u32
        } else {
            paths
        };
        Ok(KellerParams {
            paths,
            bounces: params.int("bounces") as u32,
            budget: budget.min(paths),
            gather: GatherParams::from_params(params)?,
        })
    }
}

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
    settings: VplSettings,
}

fn create_full(
    params: &Params,
    ctx: &PrepareContext,
    prepared: &Prepared,
) -> Result<Box<dyn Technique>> {
    let p = KellerParams::from_params(params)?;
    let gather = VplGather::new(&p.gather, ctx, p.paths * p.bounces, DrawSet::StaticCasters)?;
    Ok(Box::new(KellerFull {
        gather,
        settings: VplSettings {
            paths: p.paths,
            bounces: p.bounces,
            first_path: 0,
            normalisation_paths: p.paths,
            average_reflectance: Some(prepared_rho(prepared)?),
        },
    }))
}

impl Technique for KellerFull {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let (scene, bvh, light) = (ctx.scene, ctx.bvh, ctx.frame.light);
        let settings = self.settings;
        let vpls: Vec<(u32, Vpl)> = ctx.profiler.cpu_stage(STAGE_VPL_GENERATION, || {
            vpl::generate(scene, bvh, &light, &settings)
                .into_iter()
                .enumerate()
                .map(|(i, v)| (i as u32, v))
                .collect()
        });
        // Every map is re-rendered: clear the whole atlas.
        self.gather.render_maps(ctx, &vpls, AtlasClear::Whole)?;
        self.gather.gather(ctx, &vpls)
    }

    fn output(&self) -> &wgpu::TextureView {
        self.gather.output()
    }
}

/// `keller-incremental`: a ring of N path slots; each holds the VPLs of one light path.
pub struct KellerIncremental {
    gather: VplGather,
    paths: u32,
    budget: u32,
    bounces: u32,
    /// VPLs of each path slot (empty when the path left the scene).
    ring: Vec<Vec<Vpl>>,
    /// Next path slot to replace (the oldest).
    oldest: u32,
    /// Halton index of the next path.
    next_path: u64,
    average_reflectance: f32,
}

fn create_incremental(
    params: &Params,
    ctx: &PrepareContext,
    prepared: &Prepared,
) -> Result<Box<dyn Technique>> {
    let p = KellerParams::from_params(params)?;
    let gather = VplGather::new(&p.gather, ctx, p.paths * p.bounces, DrawSet::StaticCasters)?;
    Ok(Box::new(KellerIncremental {
        gather,
        paths: p.paths,
        budget: p.budget,
        bounces: p.bounces,
        ring: Vec::new(),
        oldest: 0,
        next_path: 0,
        average_reflectance: prepared_rho(prepared)?,
    }))
}

impl Technique for KellerIncremental {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let (scene, bvh, light) = (ctx.scene, ctx.bvh, ctx.frame.light);
        let first = self.ring.is_empty();
        let count = if first { self.paths } else { self.budget };
        let (paths, bounces, rho) = (self.paths, self.bounces, self.average_reflectance);
        let (ring, oldest, next_path) = (&mut self.ring, &mut self.oldest, &mut self.next_path);
        let new_vpls: Vec<(u32, Vpl)> = ctx.profiler.cpu_stage(STAGE_VPL_GENERATION, || {
            if ring.is_empty() {
                ring.resize(paths as usize, Vec::new());
            }
            // One batch of `count` new paths (Keller's fractional absorption applies within the
            // batch), normalised as one of N paths each.
            let settings = VplSettings {
                paths: count,
                bounces,
                first_path: *next_path,
                normalisation_paths: paths,
                average_reflectance: Some(rho),
            };
            let batch = vpl::generate(scene, bvh, &light, &settings);
            let mut new_vpls = Vec::new();
            for k in 0..count as u64 {
                let p = *oldest;
                *oldest = (*oldest + 1) % paths;
                let path_vpls: Vec<Vpl> = batch
                    .iter()
                    .filter(|v| v.path == *next_path + k)
                    .copied()
                    .collect();
                for (b, v) in path_vpls.iter().enumerate() {
                    new_vpls.push((p * bounces + b as u32, *v));
                }
                ring[p as usize] = path_vpls;
            }
            *next_path += count as u64;
            new_vpls
        });
        let vpls: Vec<(u32, Vpl)> = self
            .ring
            .iter()
            .enumerate()
            .flat_map(|(p, path)| {
                path.iter()
                    .enumerate()
                    .map(move |(b, v)| (p as u32 * bounces + b as u32, *v))
            })
            .collect();
        // The first frame renders every map; later frames only the replaced paths' maps.
        let clear = if first {
            AtlasClear::Whole
        } else {
            AtlasClear::RenderedSlots
        };
        self.gather.render_maps(ctx, &new_vpls, clear)?;
        self.gather.gather(ctx, &vpls)
    }

    fn output(&self) -> &wgpu::TextureView {
        self.gather.output()
    }
}
