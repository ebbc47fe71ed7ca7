//! **Gather**: the kit wired for the common case — a CPU-managed VPL list, a rasterised depth
//! atlas of the static shadow casters, interleaved accumulation and the geometry-aware filter —
//! built from one set of named parameters ([`GATHER_PARAMS`], parsed once into
//! [`GatherParams`]) and recorded as the same profiler stages by every technique that uses it
//! (`keller-full`, `keller-incremental`, `laine`).
//!
//! Reads: the technique's VPLs (slot, [`Vpl`]), the G-buffer, the scene.
//! Writes: the technique's indirect-irradiance output (Rgba16Float, the G-buffer's size).
//! Stages: [`STAGE_VPL_SHADOW_MAPS`], [`STAGE_SPLIT`], [`STAGE_ACCUMULATE`],
//! [`STAGE_COMBINE`], [`STAGE_FILTER`]; counters `shadow-maps` and `vpls`.

use super::accumulate::{Accumulation, IrradianceClamp};
use super::atlas::{AtlasFormat, AtlasSettings, MapKind, ShadowAtlas};
use super::interleave::{FilterSettings, Interleave};
use super::raster::{AtlasClear, AtlasRasteriser, StoreViews};
use super::store::VplStore;
use crate::cpu::vpl::Vpl;
use crate::kit::passes::DrawSet;
use crate::kit::technique::{FrameContext, ParamKind, ParamSpec, Params, PrepareContext, Stage};
use crate::measure::roofline::StageCost;
use crate::Result;

/// Stage: rendering VPL maps (view upload included).
pub const STAGE_VPL_SHADOW_MAPS: &str = "vpl-shadow-maps";
/// Stage: splitting the G-buffer into tiles.
pub const STAGE_SPLIT: &str = "split";
/// Stage: accumulating VPL irradiance per tile.
pub const STAGE_ACCUMULATE: &str = "accumulate";
/// Stage: combining the tiles back.
pub const STAGE_COMBINE: &str = "combine";
/// Stage: the geometry-aware filter.
pub const STAGE_FILTER: &str = "filter";
/// The VPL shadow maps' stage, declared (techniques that draw the kit's maps).
pub const SHADOW_MAP_STAGES: &[Stage] = &[Stage::gpu(STAGE_VPL_SHADOW_MAPS)];
/// The gathering's stages, declared, in order (every VPL technique).
pub const GATHER_STAGES: &[Stage] = &[
    Stage::gpu(STAGE_SPLIT),
    Stage::gpu(STAGE_ACCUMULATE),
    Stage::gpu(STAGE_COMBINE),
    Stage::gpu(STAGE_FILTER),
];
/// The gathering stages Laine et al. 2007's Table 2 sums as "Σ common", in order.
pub const COMMON_STAGES: [&str; 4] = [STAGE_SPLIT, STAGE_ACCUMULATE, STAGE_COMBINE, STAGE_FILTER];

/// Parameters of every VPL technique's gathering.
pub const GATHER_PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "tiles",
        kind: ParamKind::Tiles,
        default: "4x4",
        doc: "interleaved-sampling tiles NxM (Laine: 4x4); 1x1 = no interleaving",
    },
    ParamSpec {
        name: "vpl-map",
        kind: ParamKind::Choice(MapKind::NAMES),
        default: "paraboloid",
        doc: "VPL shadow-map parameterisation: paraboloid, cube (6x the memory) or octahedral (Barczak 2006: the hemisphere on four octahedron faces in one square, the memory of a paraboloid map, rasterised exactly)",
    },
    ParamSpec {
        name: "vpl-map-size",
        kind: ParamKind::Int { min: 8, max: 4096 },
        default: "128",
        doc: "VPL shadow-map edge in texels (Laine: 256); not the run option --shadow-size, the primary light's map",
    },
    ParamSpec {
        name: "depth-bits",
        kind: ParamKind::Choice(&["16", "32"]),
        default: "16",
        doc: "VPL shadow-map depth format: 16 (Laine) or 32",
    },
    ParamSpec {
        name: "clamp",
        kind: ParamKind::Float { min: 0.0, max: 1e9 },
        default: "10",
        doc: "k: the largest irradiance one VPL may give a receiver is k x the mean irradiance of all the frame's VPLs (their summed flux over the scene's surface area, recorded as scene_surface_area); 0 = no clamp",
    },
];

/// [`GATHER_PARAMS`], parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherParams {
    pub tiles: (u32, u32),
    pub map: MapKind,
    pub map_size: u32,
    pub format: AtlasFormat,
    /// The irradiance clamp's factor k ([`super::accumulate`]; 0: no clamp).
    pub clamp: f32,
}

impl GatherParams {
    /// Reads the gather parameters (declared with [`GATHER_PARAMS`]) from `params`.
    pub fn from_params(params: &Params) -> Result<GatherParams> {
        Ok(GatherParams {
            tiles: params.tiles("tiles"),
            map: MapKind::parse(params.choice("vpl-map"))?,
            map_size: params.int("vpl-map-size") as u32,
            format: AtlasFormat::from_depth_bits(params.choice("depth-bits").parse().unwrap_or(0))?,
            clamp: params.float("clamp") as f32,
        })
    }
}

/// The common-case gather (see the module docs).
pub struct VplGather {
    /// Kept alive for the view and the filter's storage binding.
    _output: wgpu::Texture,
    view: wgpu::TextureView,
    pub interleave: Interleave,
    pub store: VplStore,
    pub atlas: ShadowAtlas,
    /// `None` when another pass writes the atlas (imperfect shadow maps).
    pub raster: Option<AtlasRasteriser>,
    pub accumulation: Accumulation,
    /// The stages' declared costs, computed once from the sizes.
    costs: GatherCosts,
}

impl VplGather {
    /// Builds the gather for at most `capacity` VPLs with `settings`, rasterising `draw_set`
    /// into the atlas (`None`: another pass writes it; [`VplGather::render_maps`] is then an
    /// error).
    pub fn new(
        settings: &GatherParams,
        ctx: &PrepareContext,
        capacity: u32,
        draw_set: Option<DrawSet>,
    ) -> Result<VplGather> {
        let gpu = ctx.gpu;
        let output = crate::kit::passes::indirect_target(&gpu.device, ctx.resolution, true);
        let scene_settings = &ctx.scene.descriptor.settings;
        let interleave = Interleave::new(
            gpu,
            ctx.gbuffer,
            settings.tiles,
            FilterSettings {
                alpha: scene_settings.filter_distance,
                beta: scene_settings.filter_normal,
            },
            &output,
        )?;
        let store = VplStore::new(gpu, capacity)?;
        let atlas = ShadowAtlas::new(
            gpu,
            &ctx.scene.extent,
            AtlasSettings {
                kind: settings.map,
                format: settings.format,
                size: settings.map_size,
                capacity,
                bias: scene_settings.shadow_bias,
            },
        )?;
        let raster = draw_set
            .map(|set| AtlasRasteriser::new(gpu, &atlas, ctx.uniforms, set))
            .transpose()?;
        let accumulation = Accumulation::new(
            gpu,
            &interleave,
            &store,
            &atlas,
            IrradianceClamp {
                factor: settings.clamp,
                surface_area: ctx.scene.extent.surface_area,
            },
        )?;
        let view = output.create_view(&Default::default());
        let costs = GatherCosts::new(
            &interleave,
            raster.as_ref().map(|r| r.map_cost(ctx.gpu_scene, &atlas)),
        );
        Ok(VplGather {
            costs,
            _output: output,
            view,
            interleave,
            store,
            atlas,
            raster,
            accumulation,
        })
    }

    /// Records the maps of `vpls` (slot, VPL) as the `vpl-shadow-maps` stage (views uploaded
    /// inside it) and counts them as `shadow-maps`.
    pub fn render_maps(
        &self,
        ctx: &mut FrameContext,
        vpls: &[(u32, Vpl)],
        clear: AtlasClear,
    ) -> Result<()> {
        let (gpu, scene, uniforms) = (ctx.gpu, ctx.gpu_scene, ctx.uniforms);
        let raster = self.rasteriser()?;
        let n = ctx.profiler.gpu_stage(gpu, STAGE_VPL_SHADOW_MAPS, |enc| {
            raster.render(gpu, enc, &self.atlas, scene, uniforms, vpls, clear)
        })?;
        self.maps_rendered(ctx, n);
        Ok(())
    }

    /// The rasteriser, or an error when another pass writes the atlas.
    fn rasteriser(&self) -> Result<&AtlasRasteriser> {
        self.raster.as_ref().ok_or_else(|| {
            crate::Error::Invalid("this gather's atlas is written by another pass".into())
        })
    }

    /// Records the maps of the store's slots `0..count`, written by a GPU pass earlier in the
    /// frame, as the `vpl-shadow-maps` stage (their views written from the store inside it) and
    /// counts them as `shadow-maps`.
    pub fn render_store_maps(
        &self,
        ctx: &mut FrameContext,
        views: &StoreViews,
        count: u32,
    ) -> Result<()> {
        let (gpu, scene, uniforms) = (ctx.gpu, ctx.gpu_scene, ctx.uniforms);
        let raster = self.rasteriser()?;
        let n = ctx.profiler.gpu_stage(gpu, STAGE_VPL_SHADOW_MAPS, |enc| {
            raster.render_store(enc, &self.atlas, scene, uniforms, views, count)
        })?;
        self.maps_rendered(ctx, n);
        Ok(())
    }

    /// Counts the `n` maps the `vpl-shadow-maps` stage rendered as `shadow-maps` and declares
    /// their cost.
    fn maps_rendered(&self, ctx: &mut FrameContext, n: u32) {
        if let Some(map) = self.costs.map {
            ctx.profiler
                .stage_cost(STAGE_VPL_SHADOW_MAPS, map.scaled(n as f64));
        }
        ctx.profiler.count("shadow-maps", n as f64);
    }

    /// Uploads `vpls` (slot, VPL) into the store and records the gathering stages. Counts
    /// `vpls`, and the fewest and most VPLs any interleaving tile gets (`tile-vpls-min`,
    /// `tile-vpls-max`: slot k lights tile k mod T).
    pub fn gather(&self, ctx: &mut FrameContext, vpls: &[(u32, Vpl)]) -> Result<()> {
        self.store.write(&ctx.gpu.queue, vpls);
        ctx.profiler.count("vpls", vpls.len() as f64);
        let tiles = (self.interleave.tiles[0] * self.interleave.tiles[1]) as usize;
        let mut per_tile = vec![0u32; tiles];
        for (slot, _) in vpls {
            per_tile[*slot as usize % tiles] += 1;
        }
        let (lo, hi) = per_tile
            .iter()
            .fold((u32::MAX, 0), |(lo, hi), &n| (lo.min(n), hi.max(n)));
        ctx.profiler.count("tile-vpls-min", lo as f64);
        ctx.profiler.count("tile-vpls-max", hi as f64);
        self.gather_stages(ctx, vpls.len() as u32)
    }

    /// Records split, accumulate, combine and filter over the store as it is (filled by the
    /// CPU or by a GPU pass earlier in the frame; its cost declared for a full store).
    pub fn gather_store(&self, ctx: &mut FrameContext) -> Result<()> {
        self.gather_stages(ctx, self.store.capacity())
    }

    /// The gathering stages over a store holding `vpls` VPLs, with their declared costs.
    fn gather_stages(&self, ctx: &mut FrameContext, vpls: u32) -> Result<()> {
        let gpu = ctx.gpu;
        let il = &self.interleave;
        let costs = &self.costs;
        ctx.profiler
            .gpu_stage(gpu, STAGE_SPLIT, |enc| il.encode_split(enc))?;
        ctx.profiler.stage_cost(STAGE_SPLIT, costs.split);
        ctx.profiler.gpu_stage(gpu, STAGE_ACCUMULATE, |enc| {
            self.accumulation.encode(enc, il, &self.atlas)
        })?;
        ctx.profiler.stage_cost(
            STAGE_ACCUMULATE,
            costs
                .accumulate
                .plus(costs.accumulate_per_vpl.scaled(vpls as f64)),
        );
        ctx.profiler
            .gpu_stage(gpu, STAGE_COMBINE, |enc| il.encode_combine(enc))?;
        ctx.profiler.stage_cost(STAGE_COMBINE, costs.combine);
        ctx.profiler
            .gpu_stage(gpu, STAGE_FILTER, |enc| il.encode_filter(enc))?;
        ctx.profiler.stage_cost(STAGE_FILTER, costs.filter);
        Ok(())
    }

    /// The indirect-irradiance output.
    pub fn output(&self) -> &wgpu::TextureView {
        &self.view
    }
}

/// The gathering stages' declared minimum costs ([`crate::measure::roofline`]), computed once
/// from the interleave's sizes and the map's; `accumulate` grows with the frame's VPL count.
struct GatherCosts {
    /// One VPL map (`None`: another pass writes the atlas).
    map: Option<StageCost>,
    split: StageCost,
    /// `accumulate` without its VPLs; each VPL adds `accumulate_per_vpl`.
    accumulate: StageCost,
    accumulate_per_vpl: StageCost,
    combine: StageCost,
    filter: StageCost,
}

impl GatherCosts {
    fn new(il: &Interleave, map: Option<StageCost>) -> GatherCosts {
        let pixels = il.full[0] as u64 * il.full[1] as u64;
        let texels = il.split_texels() as u64;
        let tiles = (il.tiles[0] * il.tiles[1]) as u64;
        // `split`: per pixel the G-buffer's depth (4 bytes) and normal (Rgba16Float, 8) read,
        // its split position and normal (two vec4<f32>, 32) written; the position rebuilt
        // from depth (a 4×4 matrix times a point, 32 operations).
        let split = StageCost::per_element(pixels, 12, 32, 32);
        // `accumulate`: per split texel its position and normal read (32 bytes) and its
        // irradiance written (16); every VPL read once (`GpuVpl`, 80 bytes). A texel is lit by
        // its tile's VPLs, vpls / tiles of them, so each VPL makes texels / tiles pairs, each
        // at least 40 operations: the vector to the VPL and its squared length (8), the
        // reciprocal distance (1), both cosines (10), the map coordinates of the lookup (10),
        // the product of the terms (5) and the flux's three channels scaled and added (6).
        // The shadow-map texels the lookups read are not counted: how many distinct ones
        // they touch depends on the geometry.
        let accumulate = StageCost::per_element(texels, 32, 16, 0);
        let accumulate_per_vpl = StageCost {
            bytes_read: std::mem::size_of::<super::store::GpuVpl>() as f64,
            bytes_written: 0.0,
            ops: texels as f64 / tiles as f64 * 40.0,
        };
        // `combine`: per pixel its split texel's irradiance read and written back in place
        // (a vec4<f32> each way, 16 bytes); no arithmetic.
        let combine = StageCost::per_element(pixels, 16, 16, 0);
        // `filter`: per pixel its split position and normal (32 bytes) and its combined
        // irradiance (16) read once — a tap reads a neighbour's, which the neighbour reads
        // anyway, so the minimum reads each once — and the output (Rgba16Float, 8) written.
        // Per tap of the n×m box other than the pixel itself, the geometry test: the position
        // difference (3), its squared length against α² (6), the normals' dot product against
        // β (6) — 15; per tap taken, its three channels and the count added (4); the mean's
        // three divisions (3).
        let filter = StageCost::per_element(pixels, 48, 8, (tiles - 1) * 15 + tiles * 4 + 3);
        GatherCosts {
            map,
            split,
            accumulate,
            accumulate_per_vpl,
            combine,
            filter,
        }
    }
}
