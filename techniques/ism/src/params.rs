//! The parameters of `ism` and `ism-classic`: their declarations (names, ranges, defaults,
//! documentation) and [`IsmParams`], the typed values read from them once and checked against
//! the device.

use gibench_harness::kit::ir::atlas::{AtlasFormat, MapKind};
use gibench_harness::kit::ir::gather::{GatherParams, GATHER_PARAMS};
use gibench_harness::kit::ir::pullpush::PullPushMode;
use gibench_harness::kit::ir::vpl_sample::VplWarp;
use gibench_harness::kit::technique::{ParamKind, ParamSpec, Params};
use gibench_harness::{Error, Result};

/// `ism`'s own parameters (the kit's gather parameters [`GATHER`] follow them).
pub(crate) const OWN_PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "VPLs lighting each frame, importance-sampled from the reflective shadow map (the slides: 1024)",
    },
    ParamSpec {
        name: "points-per-vpl",
        kind: ParamKind::Int { min: 1, max: 1 << 20 },
        default: "1024",
        doc: "points splatted into each VPL's imperfect map (the slides: 8k)",
    },
    ParamSpec {
        name: "point-pool",
        kind: ParamKind::Int { min: 1, max: 1 << 24 },
        default: "65536",
        doc: "points sampled on the surfaces once; each VPL takes its own run of them",
    },
    ParamSpec {
        name: "rsm-size",
        kind: ParamKind::Int { min: 8, max: 2048 },
        default: "64",
        doc: "edge of each face of the reflective shadow map, texels",
    },
    ParamSpec {
        name: "pull-push-levels",
        kind: ParamKind::Int { min: 0, max: 12 },
        default: "3",
        doc: "pyramid levels of the pull-push: holes up to 2^levels texels wide are filled (0: none)",
    },
    ParamSpec {
        name: "vpl-warp",
        kind: ParamKind::Choice(VplWarp::NAMES),
        default: "row-column",
        doc: "how each VPL's fixed point picks its texel of the reflective shadow map: 'flat', the luminance CDF over the flattened map; 'row-column', a row by luminance, then a texel of it",
    },
    ParamSpec {
        name: "pull-push",
        kind: ParamKind::Choice(PullPushMode::NAMES),
        default: "average",
        doc: "how the pull-push fills holes: 'average' (every valid depth averaged); 'depth-aware' (Marroquim et al. 2007: the front-most surface's depth interval in the pull, only empty or occluded texels filled in the push: closes the sun box's leak, darkens the other boxes; results/ism/README.md)",
    },
];

/// The kit's gather parameters that apply to imperfect maps: tiles, map size, clamp (the maps
/// are always paraboloid, in a float atlas).
pub(crate) const GATHER: &[ParamSpec] = &[GATHER_PARAMS[0], GATHER_PARAMS[2], GATHER_PARAMS[4]];

/// The parameters `ism-classic` shares with `ism` (no points, no pull-push).
pub(crate) const CLASSIC_PARAMS: &[ParamSpec] = &[OWN_PARAMS[0], OWN_PARAMS[3], OWN_PARAMS[5]];

/// The parameters, read once.
#[derive(Clone, Copy, Debug)]
pub struct IsmParams {
    pub vpls: u32,
    pub points_per_vpl: u32,
    pub pool: u32,
    pub rsm_size: u32,
    pub levels: u32,
    /// How the pull-push fills holes (`ism-classic`: unused, the average).
    pub fill: PullPushMode,
    pub warp: VplWarp,
    pub gather: GatherParams,
}

impl IsmParams {
    /// `ism`'s parameters.
    pub fn from_params(params: &Params) -> Result<IsmParams> {
        let p = IsmParams {
            vpls: params.int("vpls") as u32,
            points_per_vpl: params.int("points-per-vpl") as u32,
            pool: params.int("point-pool") as u32,
            rsm_size: params.int("rsm-size") as u32,
            levels: params.int("pull-push-levels") as u32,
            fill: PullPushMode::from_name(params.choice("pull-push"))?,
            warp: VplWarp::from_name(params.choice("vpl-warp"))?,
            gather: Self::gather(params, AtlasFormat::Float32),
        };
        if p.points_per_vpl > p.pool {
            return Err(Error::param(
                "points-per-vpl",
                format!(
                    "{} points per VPL from a pool of {} (point-pool): a VPL cannot take more points than the pool has",
                    p.points_per_vpl, p.pool
                ),
            ));
        }
        Ok(p)
    }

    /// Checks the sizes the parameters give against `gpu`'s limits, naming the parameter, before
    /// any work (the pool's sampling takes seconds at its largest): the point pool's storage
    /// buffer (16 bytes a point), the reflective shadow map's texel buffers (16 bytes a texel,
    /// six faces) and its 3 × 2 faces' texture.
    pub fn check_device(&self, gpu: &gibench_harness::gpu::GpuContext) -> Result<()> {
        let max = gpu.max_storage_buffer();
        let pool_bytes = self.pool as u64 * 16;
        if pool_bytes > max {
            return Err(Error::param(
                "point-pool",
                format!(
                    "{} points take {pool_bytes} bytes, more than this adapter's largest storage \
                     buffer ({max} bytes): at most {} points here",
                    self.pool,
                    max / 16
                ),
            ));
        }
        let size = self.rsm_size as u64;
        let rsm_bytes = 6 * size * size * 16;
        let max_texture = gpu.max_texture_2d() as u64;
        let largest = ((max / 96) as f64).sqrt() as u64;
        if rsm_bytes > max || 3 * size > max_texture {
            return Err(Error::param(
                "rsm-size",
                format!(
                    "a reflective shadow map of {size}² per face needs {rsm_bytes}-byte texel \
                     buffers and a {}×{} texture; this adapter allows {max} bytes and {max_texture} \
                     texels: at most {} here",
                    3 * size,
                    2 * size,
                    largest.min(max_texture / 3)
                ),
            ));
        }
        Ok(())
    }

    /// `ism-classic`'s parameters (no points, no pull-push: those fields are 0).
    pub fn classic_from_params(params: &Params) -> Result<IsmParams> {
        Ok(IsmParams {
            vpls: params.int("vpls") as u32,
            points_per_vpl: 0,
            pool: 0,
            rsm_size: params.int("rsm-size") as u32,
            levels: 0,
            fill: PullPushMode::Average,
            warp: VplWarp::from_name(params.choice("vpl-warp"))?,
            gather: Self::gather(params, AtlasFormat::Depth32),
        })
    }

    /// The gather over paraboloid maps in `format`.
    fn gather(params: &Params, format: AtlasFormat) -> GatherParams {
        GatherParams {
            tiles: params.tiles("tiles"),
            map: MapKind::Paraboloid,
            map_size: params.int("vpl-map-size") as u32,
            format,
            clamp: params.float("clamp") as f32,
        }
    }
}
