//! `laine`'s parameters: their specs (name, range, default, doc) and the typed struct read
//! from them.

use gibench_harness::kit::ir::gather::GatherParams;
use gibench_harness::kit::technique::{ParamKind, ParamSpec, Params};
use gibench_harness::{Error, Result};

pub(crate) const OWN_PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "VPLs lighting each frame, at most (Laine's maxLights: 256); fewer while sampling points miss the scene",
    },
    ParamSpec {
        name: "recalc-min",
        kind: ParamKind::Int { min: 0, max: 4096 },
        default: "4",
        doc: "VPLs deleted each frame at least (free slots kept), the least-useful first",
    },
    ParamSpec {
        name: "recalc-max",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "8",
        doc: "new sampling points (and shadow maps) per frame at most",
    },
];

/// `laine`'s parameters, read once.
#[derive(Clone, Copy, Debug)]
pub struct LaineParams {
    pub max_lights: u32,
    pub recalc_min: u32,
    pub recalc_max: u32,
    pub gather: GatherParams,
}

impl LaineParams {
    /// Reads and cross-checks the parameters: `recalc-min` above `recalc-max` would delete
    /// more VPLs each frame than it may create, and `recalc-min` at or above `vpls` would
    /// delete every VPL; both drain the VPL count, so both are errors.
    pub fn from_params(params: &Params) -> Result<LaineParams> {
        let p = LaineParams {
            max_lights: params.int("vpls") as u32,
            recalc_min: params.int("recalc-min") as u32,
            recalc_max: params.int("recalc-max") as u32,
            gather: GatherParams::from_params(params)?,
        };
        if p.recalc_min > p.recalc_max {
            return Err(Error::param(
                "laine.recalc-min",
                format!(
                    "{} is above recalc-max ({}): more VPLs would be deleted each frame than created",
                    p.recalc_min, p.recalc_max
                ),
            ));
        }
        if p.recalc_min >= p.max_lights {
            return Err(Error::param(
                "laine.recalc-min",
                format!(
                    "{} must be below vpls ({}): every VPL would be deleted each frame",
                    p.recalc_min, p.max_lights
                ),
            ));
        }
        Ok(p)
    }
}
