//! The parameters of `barczak`: their declarations (names, ranges, defaults, documentation)
//! and [`BarczakParams`], the typed values read from them once for a resolution.

use gibench_harness::kit::technique::{ParamKind, ParamSpec, Params};
use gibench_harness::{Error, Result};

use crate::light_draws::Submission;
use crate::renderer::{Optimisation, RendererSettings};
use crate::samples::SampleSettings;

/// The parameters' declarations.
pub(crate) const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "vpls",
        kind: ParamKind::Int { min: 1, max: 4096 },
        default: "64",
        doc: "light samples lighting each frame (the thesis: up to 300)",
    },
    ParamSpec {
        name: "set",
        kind: ParamKind::Choice(&["indirect", "direct"]),
        default: "indirect",
        doc: "indirect: samples at the hits of random walks from the light (§4.1; compare with the multi-bounce reference); direct: points on the area light (soft shadows; compare with --quality-reference direct)",
    },
    ParamSpec {
        name: "bounces",
        kind: ParamKind::Int { min: 1, max: 16 },
        default: "5",
        doc: "hits per random walk at most (the thesis' Figure 5-10: 5)",
    },
    ParamSpec {
        name: "level",
        kind: ParamKind::Choice(&Optimisation::NAMES),
        default: "full",
        doc: "Figure 5-3's optimisation level: full (light maps, visibility determination, low-resolution pass, pass optimiser), vd-lp, vd, naive (every light with a lookup everywhere)",
    },
    ParamSpec {
        name: "lights-per-draw",
        kind: ParamKind::Int { min: 1, max: 16 },
        default: "7",
        doc: "lights one pass handles (the thesis' X800: 7 per pass)",
    },
    ParamSpec {
        name: "submission",
        kind: ParamKind::Choice(&Submission::NAMES),
        default: "merged",
        doc: "merged: each render pass's light passes in one draw, every vertex naming its pass's lights (same fragments and lights); passes: one draw per pass, as the thesis submits them (its per-pass cost)",
    },
    ParamSpec {
        name: "lowres",
        kind: ParamKind::Int { min: 2, max: 16 },
        default: "2",
        doc: "the low-resolution pass's factor (levels full and vd-lp); the resolution must be a multiple of it",
    },
    ParamSpec {
        name: "edge-step",
        kind: ParamKind::Int { min: 1, max: 64 },
        default: "3",
        doc: "pixels stepped by the edge detection of the low-resolution pass (at least the factor)",
    },
    ParamSpec {
        name: "vpl-map-size",
        kind: ParamKind::Int { min: 8, max: 4096 },
        default: "128",
        doc: "octahedral shadow-map edge in texels",
    },
    ParamSpec {
        name: "updates",
        kind: ParamKind::Int { min: 0, max: 4096 },
        default: "32",
        doc: "shadow maps a moving object made out of date re-rendered per frame, brightest and oldest first (the thesis: 100-150 of 300)",
    },
    ParamSpec {
        name: "face-cull",
        kind: ParamKind::Choice(&["on", "off"]),
        default: "on",
        doc: "on: a shadow map is drawn only into the octahedral faces that hold an occluder (the thesis' §4.2.2 culling test); off: into all four",
    },
    ParamSpec {
        name: "light-map-res",
        kind: ParamKind::Int { min: 1, max: 64 },
        default: "8",
        doc: "light-map texels along a patch leaf's edge",
    },
    ParamSpec {
        name: "max-charts",
        kind: ParamKind::Int { min: 1, max: 1_000_000 },
        default: "200000",
        doc: "planar charts a scene that records no patches may make (one patch each; preparation time and memory grow with them: Sibenik makes 25,010, Maze 53,219, the conference room 115,302: about a minute and 2.4 GB on 2 cores)",
    },
    ParamSpec {
        name: "prt-directions",
        kind: ParamKind::Int { min: 16, max: 65536 },
        default: "256",
        doc: "ray directions of each mover vertex's PRT transfer integral (prepared once)",
    },
];

/// The parameters, read once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BarczakParams {
    pub renderer: RendererSettings,
}

impl BarczakParams {
    /// Reads `params` for a run at `resolution`; errors name the parameter.
    pub fn from_params(params: &Params, resolution: [u32; 2]) -> Result<BarczakParams> {
        let vpls = params.int("vpls") as u32;
        let samples = if params.choice("set") == "direct" {
            SampleSettings {
                direct: vpls,
                indirect: 0,
                bounces: params.int("bounces") as u32,
            }
        } else {
            SampleSettings {
                direct: 0,
                indirect: vpls,
                bounces: params.int("bounces") as u32,
            }
        };
        let level = Optimisation::parse(params.choice("level"))?;
        let lowres = params.int("lowres") as u32;
        let edge_step = params.int("edge-step") as u32;
        if level.low_res() {
            let [w, h] = resolution;
            if w % lowres != 0 || h % lowres != 0 {
                return Err(Error::param(
                    "lowres",
                    format!("the resolution {w}x{h} is not a multiple of the factor {lowres} (level {})", level.name()),
                ));
            }
            // The interpolation reads low-resolution samples up to a factor's width away and
            // the edge detection compares pixels `edge-step` apart: a step below the factor
            // misses edges the interpolation reads across.
            if edge_step < lowres {
                return Err(Error::param(
                    "edge-step",
                    format!("{edge_step} is below the low-resolution factor {lowres} (level {}): expected at least the factor", level.name()),
                ));
            }
        }
        Ok(BarczakParams {
            renderer: RendererSettings {
                samples,
                light_map_res: params.int("light-map-res") as u32,
                lights_per_draw: params.int("lights-per-draw") as u32,
                submission: Submission::parse(params.choice("submission"))?,
                level,
                lowres,
                edge_step,
                map_size: params.int("vpl-map-size") as u32,
                updates: params.int("updates") as u32,
                prt_directions: params.int("prt-directions") as usize,
                face_cull: params.choice("face-cull") == "on",
                max_charts: params.int("max-charts") as usize,
            },
        })
    }
}
