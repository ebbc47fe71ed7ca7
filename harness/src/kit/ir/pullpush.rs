//! **Pull-push**: fills the holes of every imperfect shadow map at once, in texture space
//! (Ritschel et al. 2008), and writes the maps into the atlas. Two modes ([`PullPushMode`]):
//! the plain average (the pull-push of Grossman and Dally 1998, `ism`'s default) and
//! depth-aware (after Marroquim et al. 2007, `pull-push=depth-aware`).
//!
//! Reads: [`PointSplat`]'s imperfect depth buffer (level 0).
//! Writes (owns): a pyramid of `levels` coarser levels of every map, (mean reversed depth,
//! weight) per texel; the float ([`AtlasFormat::Float32`]) [`ShadowAtlas`] — every slot's
//! paraboloid block.
//!
//! **Depth-aware** (Marroquim, Kraus, Cavalcanti 2007, "Efficient point-based rendering using
//! image reconstruction"). Pull: of each 2×2 block's valid children, those within the level's
//! depth interval of the front-most one are kept (the front-most surface's); the texel of
//! level k + 1 stores their mean depth with weight min(1, Σ kept weights) (0 when none is
//! valid). Push, from level `levels` − 1 down to 1, and the last push into the atlas at level
//! 0: a texel that is empty, or occluded (behind its parent by more than the interval: a
//! farther surface seen through a hole in a nearer one) where the parent's points cover it,
//! takes its parent's depth; any other texel keeps its own. A plain average would invent an
//! occluder between the two surfaces at a hole or a silhouette, and keep the farther surface
//! where it shows through a hole — where light leaks.
//!
//! The interval at level 0 is the larger of the points' diameter 2r (r from the points'
//! density, [`PullPushSettings::interval`]) and a slanted surface's depth change across one
//! texel (up to 75° from the view ray, at the front-most surface's distance), in depth units;
//! both double per level (a texel of level k spans 2^k texels). Three changes from the paper,
//! each measured (docs/deviations.md): the slant term (our points are splatted as single
//! texels, not discs, so a slanted surface changes depth between neighbouring texels by more
//! than a point's diameter, and the diameter alone splits it in two); the mean of the kept
//! children rather than the front-most depth (which fills a slanted surface's holes nearer the
//! light than the surface, so it shadows itself); and the occluded fill only where a texel of
//! its level is no wider, at the parent's distance, than a point's diameter (a coarser parent
//! would spread an occluder past its silhouette).
//!
//! **Average.** Pull: each texel of level k + 1 is the mean of the valid depths among its 2×2
//! children, with weight min(1, Σ child weights). Push: a texel of weight w < 1 becomes
//! w · itself + (1 − w) · its parent; at level 0 a texel a point landed on keeps its depth
//! exactly and a hole takes its parent's depth.
//!
//! In both a hole stays empty (0) where no point landed within 2^`levels` texels — so large
//! empty regions (no geometry behind a VPL's horizon) are not closed up — and no read crosses a
//! map's tile border (each map is its own slot). `levels` 0 copies the splats unfilled (the
//! paper's "depth map without pull-push", with its leaks).
//!
//! Deviation: the push takes the parent texel (nearest), not a bilinear mix of four parents
//! (public implementations weigh them 9/3/3/1).

use bytemuck::{Pod, Zeroable};

use super::atlas::{AtlasFormat, ShadowAtlas};
use super::splat::{texel_buffer_size, PointSplat};
use crate::gpu::GpuContext;
use crate::kit::passes::{compute_pipeline, params_buffer, Bindings};
use crate::measure::roofline::StageCost;
use crate::{Error, Result};

/// GPU layout of `PullPushParams` in `pullpush.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsData {
    counts: [u32; 4],
    offsets: [u32; 4],
    fill: [f32; 4],
}

/// How the pull-push fills holes (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PullPushMode {
    /// Marroquim et al. 2007: front-most depth interval in the pull, only empty or occluded
    /// texels filled in the push.
    DepthAware,
    /// Grossman and Dally 1998: every valid child averaged, partial texels blended.
    Average,
}

impl PullPushMode {
    /// The parameter values, in the order of the variants.
    pub const NAMES: &'static [&'static str] = &["depth-aware", "average"];

    /// The mode named `name` (one of [`PullPushMode::NAMES`]).
    pub fn from_name(name: &str) -> Result<PullPushMode> {
        match name {
            "depth-aware" => Ok(PullPushMode::DepthAware),
            "average" => Ok(PullPushMode::Average),
            other => Err(Error::param(
                "pull-push",
                format!("expected one of {:?}, got '{other}'", Self::NAMES),
            )),
        }
    }

    fn code(self) -> u32 {
        match self {
            PullPushMode::DepthAware => 0,
            PullPushMode::Average => 1,
        }
    }
}

/// What the pull-push does: its levels, its mode and (depth-aware) the depth interval.
#[derive(Clone, Copy, Debug)]
pub struct PullPushSettings {
    /// Levels pulled (at most log2 of the map size).
    pub levels: u32,
    pub mode: PullPushMode,
    /// The depth interval at level 0, in the atlas's depth units (reversed, 1 − distance /
    /// far): two surfaces closer than this are one. Unused by [`PullPushMode::Average`].
    pub interval: f32,
}

impl PullPushSettings {
    /// The interval of points sampled uniformly by area, `points` of them over `area`, in
    /// `atlas`'s depth units: their diameter 2r, with r the radius of the disc each point
    /// stands for (π r² = area / points), over the atlas's far distance.
    pub fn interval(area: f64, points: u32, atlas: &ShadowAtlas) -> f32 {
        let r = (area / (std::f64::consts::PI * points.max(1) as f64)).sqrt();
        (2.0 * r / atlas.far as f64) as f32
    }
}

/// One dispatch: its pipeline, bind group and the edge of a map at its level.
struct Pass {
    pipeline: usize,
    group: wgpu::BindGroup,
    _params: wgpu::Buffer,
    /// The edge of the level it writes: one invocation per texel of every map (8x8 groups,
    /// the map's slot in z).
    edge: u32,
}

/// The pull-push passes (see the module docs).
pub struct PullPush {
    /// The passes' declared minimum cost per frame, from the maps' sizes and the levels.
    pub cost: StageCost,
    /// pull, push, store.
    pipelines: [wgpu::ComputePipeline; 3],
    passes: Vec<Pass>,
    _pyramid: wgpu::Buffer,
    slots: u32,
    levels: u32,
}

const NO_SOURCE: u32 = u32::MAX;

/// The steepest slant (75°: tan ≈ 3.73) at which a surface still counts as one across a texel
/// in the depth-aware mode: a texel of a paraboloid map of `size`² spans at most 4 / `size`
/// radians (at the centre), over which a surface at distance D tilted θ from the view ray
/// changes distance by about D · (4 / size) · tan θ.
pub const SLANT_TAN: f32 = 3.73;

impl PullPush {
    /// The passes over `splat`'s depth buffer into `atlas` (a float atlas of the same slots
    /// and map size), as `settings` say.
    pub fn new(
        gpu: &GpuContext,
        splat: &PointSplat,
        atlas: &ShadowAtlas,
        settings: PullPushSettings,
    ) -> Result<PullPush> {
        if settings.mode == PullPushMode::DepthAware
            && !(settings.interval.is_finite() && settings.interval >= 0.0)
        {
            return Err(Error::Invalid(format!(
                "the pull-push's depth interval must be finite and at least 0 (got {})",
                settings.interval
            )));
        }
        let device = &gpu.device;
        let (slots, size) = splat.layout();
        if atlas.settings.format != AtlasFormat::Float32 || atlas.settings.size != size {
            return Err(Error::Invalid(
                "pull-push writes a float atlas of the splat's map size".into(),
            ));
        }
        let levels = settings.levels.min(size.trailing_zeros());
        // Offsets of levels 1..=levels in the pyramid (items).
        let mut offsets = vec![0u32; levels as usize + 2];
        let mut items = 0u64;
        for k in 1..=levels {
            offsets[k as usize] = items as u32;
            let s = (size >> k) as u64;
            items += slots as u64 * s * s;
        }
        let bytes = texel_buffer_size(
            gpu,
            items.max(1) * 2,
            "the pull-push pyramid",
            "vpl-map-size",
        )?;
        let pyramid = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pull-push pyramid"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let atlas_view = atlas.texture().create_view(&Default::default());
        let (depth, store) = (splat.depth(), Some(&atlas_view));
        // The two layouts, from the passes' declaration (a layout reads only the bindings'
        // kinds, so any buffer stands in for the per-pass parameters made below).
        let layout = declare(&pyramid, depth, &pyramid, None).layout(device);
        let store_layout = declare(&pyramid, depth, &pyramid, store).layout(device);
        let common = include_str!("shaders/pullpush.wgsl");
        let pipeline = |layout: &wgpu::BindGroupLayout, source: String, entry: &str| {
            compute_pipeline(device, entry, &source, &[layout], entry)
        };
        let pipelines = [
            pipeline(&layout, common.to_string(), "pull"),
            pipeline(&layout, common.to_string(), "push"),
            pipeline(
                &store_layout,
                include_str!("shaders/pullpush_store.wgsl").to_string(),
                "store",
            ),
        ];
        let columns = atlas.columns();
        let pass = |kind: usize, level: u32, source: u32| -> Pass {
            let s = size >> level;
            // The interval of the level compared: the children's (level − 1) in the pull, the
            // texels' own in the push and the store.
            let compared = if kind == 0 { level - 1 } else { level };
            let scale = (1u32 << compared) as f32;
            let texel = 4.0 / size as f32;
            let params = params_buffer(
                gpu,
                "pull-push params",
                &ParamsData {
                    counts: [level, s, slots, columns],
                    offsets: [offsets[level as usize], source, settings.mode.code(), 0],
                    fill: [
                        settings.interval * scale,
                        SLANT_TAN * texel * scale,
                        texel * scale,
                        settings.interval,
                    ],
                },
            );
            let layout = if kind == 2 { &store_layout } else { &layout };
            let atlas = if kind == 2 { store } else { None };
            let group = declare(&params, depth, &pyramid, atlas).group(device, layout);
            Pass {
                pipeline: kind,
                group,
                _params: params,
                edge: s,
            }
        };
        let mut passes = Vec::new();
        for k in 1..=levels {
            passes.push(pass(0, k, if k > 1 { offsets[k as usize - 1] } else { 0 }));
        }
        for k in (1..levels).rev() {
            passes.push(pass(1, k, offsets[k as usize + 1]));
        }
        passes.push(pass(2, 0, if levels > 0 { offsets[1] } else { NO_SOURCE }));
        gpu.check_errors()?;
        // The declared minimum cost ([`crate::measure::roofline`]): level 0 of every map read
        // once (the splat's `u32`, 4 bytes a texel) and the atlas written once (R32Float, 4);
        // the coarser levels, a third as many texels, are not counted (a pass pulling and
        // pushing one map's tile at a time can keep them on chip). Operations: per texel of
        // each pulled level its four children's weighted depths and weights summed (12), the
        // mean and the clamped weight (2); per texel pushed (each level below the top, level 0
        // included) the blend with its parent (4). With no levels the copy does none.
        let texels = |k: u32| slots as u64 * (size >> k) as u64 * (size >> k) as u64;
        let (pulled, pushed) = if levels == 0 {
            (0, 0)
        } else {
            (
                (1..=levels).map(texels).sum::<u64>(),
                (0..levels).map(texels).sum::<u64>(),
            )
        };
        let cost = StageCost::per_element(texels(0), 4, 4, 0)
            .plus(StageCost::per_element(pulled, 0, 0, 14))
            .plus(StageCost::per_element(pushed, 0, 0, 4));
        Ok(PullPush {
            cost,
            pipelines,
            passes,
            _pyramid: pyramid,
            slots,
            levels,
        })
    }

    /// Levels pulled (the requested number, at most log2 of the map size).
    pub fn levels(&self) -> u32 {
        self.levels
    }

    /// Records pull, push and the store into the atlas, one dispatch per level for all maps.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("pull-push"),
            timestamp_writes: None,
        });
        for p in &self.passes {
            pass.set_pipeline(&self.pipelines[p.pipeline]);
            pass.set_bind_group(0, &p.group, &[]);
            let groups = p.edge.div_ceil(8);
            pass.dispatch_workgroups(groups, groups, self.slots);
        }
    }
}

/// A pass's group: its parameters, the splat's depths read, the pyramid written, and for the
/// last pass (the store) the atlas written.
fn declare<'a>(
    params: &'a wgpu::Buffer,
    depth: &'a wgpu::Buffer,
    pyramid: &'a wgpu::Buffer,
    atlas: Option<&'a wgpu::TextureView>,
) -> Bindings<'a> {
    let group = Bindings::new("pull-push", wgpu::ShaderStages::COMPUTE)
        .params(params)
        .read(depth)
        .write(pyramid);
    match atlas {
        Some(view) => group.storage_texture(view, wgpu::TextureFormat::R32Float),
        None => group,
    }
}
