//! The parameters of `keller-full` and `keller-incremental`: their declarations (names, ranges,
//! defaults, documentation) and [`KellerParams`], the typed values read from them once.

use gibench_harness::kit::ir::gather::GatherParams;
use gibench_harness::kit::technique::{ParamKind, ParamSpec, Params};
use gibench_harness::Result;

/// Both techniques' path length.
const BOUNCES: ParamSpec = ParamSpec {
    name: "bounces",
    kind: ParamKind::Int { min: 1, max: 8 },
    default: "1",
    doc: "path vertices per light path (1 = single bounce as in Laine; more use Keller's fractional absorption)",
};

/// `keller-full`'s own parameters (the kit's gather parameters follow them).
pub(crate) const FULL_OWN: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "VPLs lighting each frame: light paths are traced until there are this many (Laine's comparison: 256)",
    },
    BOUNCES,
];

/// `keller-incremental`'s own parameters (the kit's gather parameters follow them).
pub(crate) const INCREMENTAL_OWN: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "VPLs lighting each frame: the ring keeps the N light paths that give this many at the first frame",
    },
    ParamSpec {
        name: "budget",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "4",
        doc: "oldest paths replaced by new ones each frame",
    },
    BOUNCES,
];

/// The parameters of both Keller techniques, read once.
#[derive(Clone, Copy, Debug)]
pub struct KellerParams {
    /// VPLs lighting each frame.
    pub vpls: u32,
    pub bounces: u32,
    /// Paths replaced per frame (incremental).
    pub budget: u32,
    pub gather: GatherParams,
}

impl KellerParams {
    pub fn from_params(params: &Params) -> Result<KellerParams> {
        let vpls = params.int("vpls") as u32;
        Ok(KellerParams {
            vpls,
            bounces: params.int("bounces") as u32,
            budget: if params.has("budget") {
                params.int("budget") as u32
            } else {
                vpls
            },
            gather: GatherParams::from_params(params)?,
        })
    }
}
