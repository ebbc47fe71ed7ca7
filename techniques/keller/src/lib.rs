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

use gibench_harness::passes::{
    FilterSettings, Interleave, VplLighting, VplMapKind, VplShadowSettings,
};
use gibench_harness::technique::{
    FrameContext, ParamKind, ParamSpec, Params, PrepareContext, Technique, TechniqueInfo,
};
use gibench_harness::vpl::{self, Vpl, VplSettings};
use gibench_harness::{wgpu, Result};

/// Parameters shared by every VPL technique's gathering.
pub const GATHER_PARAMS: [ParamSpec; 6] = [
    ParamSpec {
        name: "tiles",
        kind: ParamKind::Tiles,
        default: "4x4",
        doc: "interleaved-sampling tiles NxM (Laine: 4x4); 1x1 = no interleaving",
    },
    ParamSpec {
        name: "shadow-map",
        kind: ParamKind::Choice(&["paraboloid", "cube"]),
        default: "paraboloid",
        doc: "VPL shadow-map parameterisation",
    },
    ParamSpec {
        name: "shadow-size",
        kind: ParamKind::Int { min: 8, max: 4096 },
        default: "128",
        doc: "VPL shadow-map edge in texels (Laine: 256)",
    },
    ParamSpec {
        name: "depth-bits",
        kind: ParamKind::Choice(&["16", "32"]),
        default: "16",
        doc: "VPL shadow-map depth format: 16 (Laine) or 32",
    },
    ParamSpec {
        name: "clamp",
        kind: ParamKind::Float { min: 0.0, max: 1.0 },
        default: "0.02",
        doc: "minimum VPL-receiver distance in 1/r^2, as a fraction of the scene's bounding-box diagonal",
    },
    ParamSpec {
        name: "bounces",
        kind: ParamKind::Int { min: 1, max: 8 },
        default: "1",
        doc: "path vertices per light path (1 = single bounce as in Laine; more use Keller's fractional absorption)",
    },
];

const FULL_PARAMS: [ParamSpec; 7] = {
    let mut p = [ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "light paths traced per frame (= first-bounce VPLs; Laine's comparison: 256)",
    }; 7];
    let mut i = 0;
    while i < 6 {
        p[i + 1] = GATHER_PARAMS[i];
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
    let mut i = 0;
    while i < 6 {
        p[i + 2] = GATHER_PARAMS[i];
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

/// The gathering half every VPL technique shares: output texture, interleaving, VPL maps.
pub struct VplGather {
    /// Kept alive for the view and the filter's storage binding.
    _output: wgpu::Texture,
    view: wgpu::TextureView,
    pub interleave: Interleave,
    pub lighting: VplLighting,
}

impl VplGather {
    /// Builds the gather for at most `capacity` VPLs from the gather parameters in `params`.
    pub fn new(params: &Params, ctx: &PrepareContext, capacity: u32) -> Result<VplGather> {
        let device = &ctx.gpu.device;
        let [w, h] = ctx.resolution;
        let output = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("indirect irradiance"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: gibench_harness::passes::HDR_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let settings = &ctx.scene.descriptor.settings;
        let interleave = Interleave::new(
            ctx.gpu,
            ctx.gbuffer,
            params.tiles("tiles"),
            FilterSettings {
                alpha: settings.filter_distance,
                beta: settings.filter_normal,
            },
            &output,
        )?;
        let depth_bits = if params.choice("depth-bits") == "32" {
            32
        } else {
            16
        };
        let lighting = VplLighting::new(
            ctx.gpu,
            ctx.gpu_scene,
            ctx.uniforms,
            &interleave,
            VplShadowSettings {
                kind: VplMapKind::parse(params.choice("shadow-map"))?,
                size: params.int("shadow-size") as u32,
                depth_bits,
                capacity,
                clamp_distance: params.float("clamp") as f32 * ctx.gpu_scene.diagonal(),
                bias: settings.shadow_bias,
            },
        )?;
        let view = output.create_view(&Default::default());
        Ok(VplGather {
            _output: output,
            view,
            interleave,
            lighting,
        })
    }

    /// Records split, accumulate, combine and filter as four stages over `vpls` (slot, VPL),
    /// whose list order is the tile assignment order.
    pub fn gather(&self, ctx: &mut FrameContext, vpls: &[(u32, Vpl)]) -> Result<()> {
        self.lighting.write_vpls(&ctx.gpu.queue, vpls);
        let gpu = ctx.gpu;
        ctx.profiler
            .gpu_stage(gpu, "split", |enc| self.interleave.encode_split(enc))?;
        ctx.profiler.gpu_stage(gpu, "accumulate", |enc| {
            self.lighting.encode_accumulate(enc, &self.interleave)
        })?;
        ctx.profiler
            .gpu_stage(gpu, "combine", |enc| self.interleave.encode_combine(enc))?;
        ctx.profiler
            .gpu_stage(gpu, "filter", |enc| self.interleave.encode_filter(enc))?;
        ctx.profiler.count("vpls", vpls.len() as f64);
        Ok(())
    }

    /// Records the shadow maps of `slots` as the `vpl-shadow-maps` stage.
    pub fn render_maps(
        &self,
        ctx: &mut FrameContext,
        slots: &[u32],
        clear_all: bool,
    ) -> Result<()> {
        let gpu = ctx.gpu;
        let (scene, uniforms) = (ctx.gpu_scene, ctx.uniforms);
        let n = ctx.profiler.gpu_stage(gpu, "vpl-shadow-maps", |enc| {
            self.lighting
                .encode_shadow_maps(enc, scene, uniforms, slots, clear_all)
        })?;
        ctx.profiler.count("shadow-maps", n as f64);
        Ok(())
    }

    pub fn output(&self) -> &wgpu::TextureView {
        &self.view
    }
}

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
