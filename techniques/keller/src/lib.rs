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

use gibench_harness::gather::{VplGather, GATHER_PARAMS};
use gibench_harness::technique::{
    FrameContext, ParamKind, ParamSpec, Params, PrepareContext, Technique, TechniqueInfo,
};
use gibench_harness::vpl::{self, Vpl, VplSettings};
use gibench_harness::{wgpu, Result};

const BOUNCES: ParamSpec = ParamSpec {
        name: "bounces",
        kind: ParamKind::Int { min: 1, max: 8 },
        default: "1",
        doc: "path vertices per light path (1 = single bounce as in Laine; more use Keller's fractional absorption)",
    };

const FULL_PARAMS: [ParamSpec; 7] = {
    let mut p = [ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "light paths traced per frame (= first-bounce VPLs; Laine's comparison: 256)",
    }; 7];
    p[1] = BOUNCES;
    let mut i = 0;
    while i < 5 {
        p[i + 2] = GATHER_PARAMS[i];
        i += 1;
    }
    p
};

const INCREMENTAL_PARAMS: [ParamSpec; 8] = {
    let mut p = [ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "light paths kept (N); the first frame traces all of them",
    }; 8];
    p[1] = ParamSpec {
        name: "budget",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "4",
        doc: "oldest paths replaced by new ones each frame",
    };
    p[2] = BOUNCES;
    let mut i = 0;
    while i < 5 {
        p[i + 3] = GATHER_PARAMS[i];
        i += 1;
    }
    p
};

/// `keller-full` registry entry.
pub const FULL: TechniqueInfo = TechniqueInfo {
    name: "keller-full",
    description: "Keller instant radiosity: all VPLs and their shadow maps recomputed every frame",
    params: &FULL_PARAMS,
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    create: create_full,
};

/// `keller-incremental` registry entry.
pub const INCREMENTAL: TechniqueInfo = TechniqueInfo {
    name: "keller-incremental",
    description: "Keller instant radiosity: keep the last N paths, replace the oldest `budget` per frame, accumulate",
    params: &INCREMENTAL_PARAMS,
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    create: create_incremental,
};

/// `keller-full`.
pub struct KellerFull {
    gather: VplGather,
    settings: VplSettings,
}

/// Keller's ρ̄: the mean of the channels of the scene's area-weighted average reflectance.
fn average_reflectance(ctx: &PrepareContext) -> f32 {
    let r = ctx.scene.average_reflectance();
    (r.x + r.y + r.z) / 3.0
}

fn create_full(params: &Params, ctx: &PrepareContext) -> Result<Box<dyn Technique>> {
    let paths = params.int("vpls") as u32;
    let bounces = params.int("bounces") as u32;
    let gather = VplGather::new(params, ctx, paths * bounces)?;
    Ok(Box::new(KellerFull {
        gather,
        settings: VplSettings {
            paths,
            bounces,
            first_path: 0,
            normalisation_paths: paths,
            average_reflectance: Some(average_reflectance(ctx)),
        },
    }))
}

impl Technique for KellerFull {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let (scene, bvh, light) = (ctx.scene, ctx.bvh, ctx.frame.light);
        let settings = self.settings;
        let lighting = &self.gather.lighting;
        let queue = &ctx.gpu.queue;
        let vpls: Vec<(u32, Vpl)> = ctx.profiler.cpu_stage("vpl-generation", || {
            let vpls: Vec<(u32, Vpl)> = vpl::generate(scene, bvh, &light, &settings)
                .into_iter()
                .enumerate()
                .map(|(i, v)| (i as u32, v))
                .collect();
            for (slot, v) in &vpls {
                lighting.write_view(queue, *slot, v);
            }
            vpls
        });
        let slots: Vec<u32> = vpls.iter().map(|(s, _)| *s).collect();
        self.gather.render_maps(ctx, &slots, true)?;
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

fn create_incremental(params: &Params, ctx: &PrepareContext) -> Result<Box<dyn Technique>> {
    let paths = params.int("vpls") as u32;
    let bounces = params.int("bounces") as u32;
    let budget = (params.int("budget") as u32).min(paths);
    let gather = VplGather::new(params, ctx, paths * bounces)?;
    Ok(Box::new(KellerIncremental {
        gather,
        paths,
        budget,
        bounces,
        ring: Vec::new(),
        oldest: 0,
        next_path: 0,
        average_reflectance: average_reflectance(ctx),
    }))
}

impl Technique for KellerIncremental {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let (scene, bvh, light) = (ctx.scene, ctx.bvh, ctx.frame.light);
        let first = self.ring.is_empty();
        let count = if first { self.paths } else { self.budget };
        let (paths, bounces, rho) = (self.paths, self.bounces, self.average_reflectance);
        let lighting = &self.gather.lighting;
        let queue = &ctx.gpu.queue;
        let (ring, oldest, next_path) = (&mut self.ring, &mut self.oldest, &mut self.next_path);
        let slots: Vec<u32> = ctx.profiler.cpu_stage("vpl-generation", || {
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
            let mut slots = Vec::new();
            for k in 0..count as u64 {
                let p = *oldest;
                *oldest = (*oldest + 1) % paths;
                let path_vpls: Vec<Vpl> = batch
                    .iter()
                    .filter(|v| v.path == *next_path + k)
                    .copied()
                    .collect();
                for (b, v) in path_vpls.iter().enumerate() {
                    let slot = p * bounces + b as u32;
                    lighting.write_view(queue, slot, v);
                    slots.push(slot);
                }
                ring[p as usize] = path_vpls;
            }
            *next_path += count as u64;
            slots
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
        self.gather.render_maps(ctx, &slots, first)?;
        self.gather.gather(ctx, &vpls)
    }

    fn output(&self) -> &wgpu::TextureView {
        self.gather.output()
    }
}
