//! The parameters of `gaitatzes`: their declarations (names, ranges, defaults, documentation)
//! and [`GaitatzesParams`], the typed values read from them once.

use gibench_harness::kit::technique::{ParamKind, ParamSpec, Params};
use gibench_harness::{Error, Result};

use crate::volume::{Mode, Transport};

/// The parameters' declarations.
pub(crate) const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "grid",
        kind: ParamKind::Int { min: 8, max: 128 },
        default: "32",
        doc: "cells per axis of the voxel grid (the paper: 32; 64 an option)",
    },
    ParamSpec {
        name: "iterations",
        kind: ParamKind::Int { min: 0, max: 1024 },
        default: "12",
        doc: "propagation iterations per frame (the paper: 11-12 outdoors, 64 for two bounces in the room); light advances at most one cell per iteration",
    },
    ParamSpec {
        name: "mode",
        kind: ParamKind::Choice(&["occluded", "lpv"]),
        default: "occluded",
        doc: "occluded: the paper's propagation through void cells with reflections at occupied ones (multiple bounces); lpv: Kaplanyan's light propagation volumes (reflective-shadow-map VPLs injected, his face weights, no occlusion, one bounce; transport and albedo do not apply)",
    },
    ParamSpec {
        name: "transport",
        kind: ParamKind::Choice(&Transport::NAMES),
        default: "cosine",
        doc: "what a void cell passes on through a face: cosine (the paper's reading, as in light propagation volumes: a clamped-cosine lobe along the face's axis; diffuses, most light between two walls returns to its source), carry (ours: the flux with the sender's own angular distribution; light keeps its direction and all of it reaches the facing wall, in beams too narrow) or pyramid (ours: the flux with the distribution of the sender's light within the face's pyramid; less returns than with cosine and it still spreads)",
    },
    ParamSpec {
        name: "albedo",
        kind: ParamKind::Choice(&["constant", "stored"]),
        default: "constant",
        doc: "albedo of secondary bounces: the paper's constant 0.5, or the voxel's stored albedo",
    },
];

/// The parameters, read once.
#[derive(Clone, Copy, Debug)]
pub struct GaitatzesParams {
    pub grid: u32,
    pub iterations: u32,
    pub mode: Mode,
    pub stored_albedo: bool,
    pub transport: Transport,
}

impl GaitatzesParams {
    pub fn from_params(params: &Params) -> Result<GaitatzesParams> {
        Ok(GaitatzesParams {
            grid: params.int("grid") as u32,
            iterations: params.int("iterations") as u32,
            mode: match params.choice("mode") {
                "lpv" => Mode::Lpv,
                "occluded" => Mode::Occluded,
                other => return Err(Error::param("mode", format!("unknown mode '{other}'"))),
            },
            stored_albedo: params.choice("albedo") == "stored",
            transport: Transport::parse(params.choice("transport"))?,
        })
    }
}
