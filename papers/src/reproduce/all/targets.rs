//! The targets of `gibench reproduce`, listed once: the paper modules' typed reproductions and
//! the sweeps and runs that are plain gibench commands (each with its arguments at quick and at
//! paper sizes), and the look-up of one by name.

use gibench_harness::{Error, Result};

use crate::reproduce::{barczak2006, gaitatzes2010, ism2008, laine2007, PaperModule};

/// How a target is produced.
pub enum Kind {
    /// A typed reproduction of a paper module (it reads `--quick` and `--frames` itself).
    Paper(&'static PaperModule),
    /// A gibench command: its arguments (without `--out`) at quick and at paper sizes.
    Command {
        quick: &'static str,
        paper: &'static str,
    },
}

/// One reproduction target.
pub struct Target {
    pub name: &'static str,
    /// Its folder under the results root.
    pub dir: &'static str,
    /// What it regenerates.
    pub what: &'static str,
    pub kind: Kind,
}

/// Said of targets whose sizes do not change with `--quick`: the CPU reference and the runs
/// compared with it, whose cost grows with the pixels, keep 256×192 at paper sizes too.
const SAME_SIZES: &str = "(the same sizes with and without --quick)";

/// Every target, in the order `all` runs them.
pub const TARGETS: &[Target] = &[
    Target {
        name: "reference",
        dir: "reference",
        what: "the CPU reference of the Cornell box, frame 0, and its two-seed error estimate",
        kind: Kind::Command {
            quick: "reference --scene cornell --frame 0 --error-estimate --no-cache",
            paper: "reference --scene cornell --frame 0 --error-estimate --no-cache",
        },
    },
    Target {
        name: "keller-tiles",
        dir: "keller/tiles",
        what: "keller-full per-stage times against the tile count (256 VPLs)",
        kind: Kind::Command {
            quick: "sweep --technique keller-full --sweep tiles=1x1,2x2,4x4,8x8 --param vpls=256 --frames 20 --warmup 3",
            paper: "sweep --technique keller-full --sweep tiles=1x1,2x2,4x4,8x8 --param vpls=256 --param vpl-map-size=256 --resolution 1024x768 --shadow-size 1024 --frames 200 --warmup 20",
        },
    },
    Target {
        name: "keller-vpls",
        dir: "keller/vpls",
        what: "keller-full per-stage times against the VPL count",
        kind: Kind::Command {
            quick: "sweep --technique keller-full --sweep vpls=64,128,256,512,1024 --frames 20 --warmup 3",
            paper: "sweep --technique keller-full --sweep vpls=64,128,256,512,1024 --param vpl-map-size=256 --resolution 1024x768 --shadow-size 1024 --frames 200 --warmup 20",
        },
    },
    Target {
        name: "keller-lag",
        dir: "keller/lag",
        what: "per-frame error of keller-full and keller-incremental: the incremental variant's lag",
        kind: Kind::Command {
            quick: "run --technique keller-full,keller-incremental --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
            paper: "run --technique keller-full,keller-incremental --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
        },
    },
    Target {
        name: "clamp-cornell-laine",
        dir: "clamp/cornell-laine",
        what: "the VPL irradiance clamp: energy removed and error on Cornell (laine)",
        kind: Kind::Command {
            quick: "sweep --scene cornell --technique laine --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene cornell --technique laine --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "clamp-maze-laine",
        dir: "clamp/maze-laine",
        what: "the VPL irradiance clamp: energy removed and error on Maze (laine)",
        kind: Kind::Command {
            quick: "sweep --scene maze --technique laine --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene maze --technique laine --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "clamp-sibenik-laine",
        dir: "clamp/sibenik-laine",
        what: "the VPL irradiance clamp: energy removed and error on Sibenik (laine)",
        kind: Kind::Command {
            quick: "sweep --scene sibenik --technique laine --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene sibenik --technique laine --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "clamp-cornell-keller-full",
        dir: "clamp/cornell-keller-full",
        what: "the VPL irradiance clamp: energy removed and error on Cornell (keller-full)",
        kind: Kind::Command {
            quick: "sweep --scene cornell --technique keller-full --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene cornell --technique keller-full --sweep clamp=0,1,3,10,30,100 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "laine-tables",
        dir: "laine",
        what: "",
        kind: Kind::Paper(&laine2007::MODULE),
    },
    Target {
        name: "laine-management",
        dir: "laine",
        what: "",
        kind: Kind::Paper(&laine2007::MODULE),
    },
    Target {
        name: "laine-dispersion",
        dir: "laine",
        what: "",
        kind: Kind::Paper(&laine2007::MODULE),
    },
    Target {
        name: "laine-tiles",
        dir: "laine/tiles",
        what: "laine per-stage times against the tile count (256 VPLs)",
        kind: Kind::Command {
            quick: "sweep --technique laine --sweep tiles=1x1,2x2,4x4,8x8 --param vpls=256 --frames 20 --warmup 3",
            paper: "sweep --technique laine --sweep tiles=1x1,2x2,4x4,8x8 --param vpls=256 --param vpl-map-size=256 --resolution 1024x768 --shadow-size 1024 --frames 200 --warmup 20",
        },
    },
    Target {
        name: "laine-vpls",
        dir: "laine/vpls",
        what: "laine per-stage times against the VPL count",
        kind: Kind::Command {
            quick: "sweep --technique laine --sweep vpls=64,128,256,512,1024 --frames 20 --warmup 3",
            paper: "sweep --technique laine --sweep vpls=64,128,256,512,1024 --param vpl-map-size=256 --resolution 1024x768 --shadow-size 1024 --frames 200 --warmup 20",
        },
    },
    Target {
        name: "laine-budget",
        dir: "laine/budget",
        what: "laine per-stage times against the per-frame recalculation budget (recalcMax)",
        kind: Kind::Command {
            quick: "sweep --technique laine --sweep recalc-max=4,8,16,32 --param vpls=256 --frames 20 --warmup 3",
            paper: "sweep --technique laine --sweep recalc-max=4,8,16,32 --param vpls=256 --param vpl-map-size=256 --resolution 1024x768 --shadow-size 1024 --frames 200 --warmup 20",
        },
    },
    Target {
        name: "laine-quality",
        dir: "laine/quality",
        what: "per-frame error of laine and keller-full at 256 VPLs",
        kind: Kind::Command {
            quick: "run --technique laine,keller-full --param vpls=256 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
            paper: "run --technique laine,keller-full --param vpls=256 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
        },
    },
    Target {
        name: "laine-sibenik-vpls",
        dir: "laine/sibenik-vpls",
        what: "laine on Sibenik against the VPL count: tile balance, flicker, error",
        kind: Kind::Command {
            quick: "sweep --scene sibenik --technique laine --sweep vpls=64,128,256,512 --param vpl-map-size=64 --quality --quality-pairs 4 --frames 12 --warmup 3 --timing stages",
            paper: "sweep --scene sibenik --technique laine --sweep vpls=64,128,256,512 --param vpl-map-size=64 --quality --quality-pairs 4 --frames 12 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "laine-sibenik-1024",
        dir: "laine/sibenik-1024",
        what: "laine and keller-full on Sibenik at 1024 VPLs (the paper's stutter case)",
        kind: Kind::Command {
            quick: "run --scene sibenik --technique laine,keller-full --param vpls=1024 --param vpl-map-size=64 --frames 3 --warmup 3 --no-images",
            paper: "run --scene sibenik --technique laine,keller-full --param vpls=1024 --param vpl-map-size=256 --resolution 1024x768 --shadow-size 1024 --frames 200 --warmup 20 --no-images",
        },
    },
    Target {
        name: "ism-points",
        dir: "ism/points",
        what: "ism against the points splatted per VPL (the slides' first tunable): time and error",
        kind: Kind::Command {
            quick: "sweep --technique ism --sweep points-per-vpl=1024,2048,4096,8192,16384 --param vpls=256 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene sponza --technique ism --sweep points-per-vpl=1024,2048,4096,8192,16384 --param vpls=1024 --param vpl-map-size=256 --param point-pool=1048576 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "ism-map-size",
        dir: "ism/map-size",
        what: "ism against the imperfect map size (the slides' second tunable): time and error",
        kind: Kind::Command {
            quick: "sweep --technique ism --sweep vpl-map-size=64,128,256 --param vpls=256 --param points-per-vpl=8192 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene sponza --technique ism --sweep vpl-map-size=64,128,256 --param vpls=1024 --param points-per-vpl=8192 --param point-pool=1048576 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "ism-vpls",
        dir: "ism/vpls",
        what: "ism against the VPL count: time and error",
        kind: Kind::Command {
            quick: "sweep --technique ism --sweep vpls=256,512,1024 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene sponza --technique ism --sweep vpls=256,512,1024 --param vpl-map-size=256 --param points-per-vpl=8192 --param point-pool=1048576 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "ism-tiles",
        dir: "ism/tiles",
        what: "ism against the tile count at 1024 VPLs (16 of 1024 per pixel at 8x8)",
        kind: Kind::Command {
            quick: "sweep --technique ism --sweep tiles=4x4,8x8,16x16 --param vpls=1024 --quality --frames 8 --warmup 3 --timing stages",
            paper: "sweep --scene sponza --technique ism --sweep tiles=4x4,8x8,16x16 --param vpls=1024 --param vpl-map-size=256 --param points-per-vpl=8192 --param point-pool=1048576 --quality --frames 8 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "ism-quality",
        dir: "ism/quality",
        what: "per-frame error and flicker of ism, ism-classic (the same VPLs, classic maps) and keller-full at equal VPL counts in the Cornell box with an animated mover, the light and the mover moving",
        kind: Kind::Command {
            quick: "run --scene cornell-bunny --technique ism,ism-classic,keller-full --param vpls=256 --param ism.points-per-vpl=8192 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
            paper: "run --scene cornell-bunny --technique ism,ism-classic,keller-full --param vpls=256 --param ism.points-per-vpl=8192 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
        },
    },
    Target {
        name: "ism-sampling",
        dir: "ism/sampling",
        what: "ism's per-frame error and flicker for the two VPL warps (the flattened luminance CDF and a row, then a column) in the Cornell box with the light and the bunny moving",
        kind: Kind::Command {
            quick: "sweep --scene cornell-bunny --technique ism --sweep vpl-warp=flat,row-column --param vpls=256 --param ism.points-per-vpl=8192 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
            paper: "sweep --scene cornell-bunny --technique ism --sweep vpl-warp=flat,row-column --param vpls=256 --param ism.points-per-vpl=8192 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
        },
    },
    Target {
        name: "ism-sampling-still",
        dir: "ism/sampling-still",
        what: "the same with the light held still (cornell-bunny-still-light): the flicker the bunny and the camera alone cause",
        kind: Kind::Command {
            quick: "sweep --scene cornell-bunny-still-light --technique ism --sweep vpl-warp=flat,row-column --param vpls=256 --param ism.points-per-vpl=8192 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
            paper: "sweep --scene cornell-bunny-still-light --technique ism --sweep vpl-warp=flat,row-column --param vpls=256 --param ism.points-per-vpl=8192 --quality --quality-all --frames 60 --warmup 0 --timing stages --spp 64",
        },
    },
    Target {
        name: "ism-pull-push-sun",
        dir: "ism/pull-push-sun",
        what: "ism's pull-push, the plain average against the depth-aware one (Marroquim et al. 2007), in the sun box where light leaks through the imperfect maps' holes: error and bias against the one-bounce reference",
        kind: Kind::Command {
            quick: "sweep --scene cornell-sun --technique ism --sweep pull-push=average,depth-aware --quality --frames 3 --warmup 3 --timing stages",
            paper: "sweep --scene cornell-sun --technique ism --sweep pull-push=average,depth-aware --quality --frames 3 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "ism-pull-push-spot",
        dir: "ism/pull-push-spot",
        what: "the same in the spot-lit Cornell box, where the depth-aware pull-push darkens",
        kind: Kind::Command {
            quick: "sweep --scene cornell --technique ism --sweep pull-push=average,depth-aware --quality --frames 3 --warmup 3 --timing stages",
            paper: "sweep --scene cornell --technique ism --sweep pull-push=average,depth-aware --quality --frames 3 --warmup 3 --timing stages",
        },
    },
    Target {
        name: "ism-breakdown",
        dir: "ism/breakdown",
        what: "",
        kind: Kind::Paper(&ism2008::MODULE),
    },
    Target {
        name: "gaitatzes-table1",
        dir: "gaitatzes/table1",
        what: "",
        kind: Kind::Paper(&gaitatzes2010::MODULE),
    },
    Target {
        name: "gaitatzes-quality",
        dir: "gaitatzes/quality",
        what: "",
        kind: Kind::Paper(&gaitatzes2010::MODULE),
    },
    Target {
        name: "gaitatzes-cornell",
        dir: "gaitatzes/cornell",
        what: "",
        kind: Kind::Paper(&gaitatzes2010::MODULE),
    },
    Target {
        name: "barczak2006",
        dir: "barczak2006",
        what: "",
        kind: Kind::Paper(&barczak2006::MODULE),
    },
    Target {
        name: "gaitatzes-grid",
        dir: "gaitatzes/grid",
        what: "gaitatzes against the grid size on the room (64 iterations)",
        kind: Kind::Command {
            quick: "sweep --scene gaitatzes-room --technique gaitatzes --sweep grid=16,24,32,48,64 --param iterations=64 --quality --quality-reference multi-bounce --frames 4 --warmup 3 --timing stages",
            paper: "sweep --scene gaitatzes-room --technique gaitatzes --sweep grid=16,24,32,48,64 --param iterations=64 --quality --quality-reference multi-bounce --resolution 512x512 --frames 100 --warmup 10 --timing stages",
        },
    },
    Target {
        name: "gaitatzes-iterations",
        dir: "gaitatzes/iterations",
        what: "gaitatzes against the propagation iterations on the room (32³)",
        kind: Kind::Command {
            quick: "sweep --scene gaitatzes-room --technique gaitatzes --sweep iterations=4,8,16,32,64,96 --quality --quality-reference multi-bounce --frames 4 --warmup 3 --timing stages",
            paper: "sweep --scene gaitatzes-room --technique gaitatzes --sweep iterations=4,8,16,32,64,96 --quality --quality-reference multi-bounce --resolution 512x512 --frames 100 --warmup 10 --timing stages",
        },
    },
    Target {
        name: "gaitatzes-transport",
        dir: "gaitatzes/transport",
        what: "gaitatzes' three transports (cosine: the paper's; carry, pyramid: ours) on the room (32³, 64 iterations)",
        kind: Kind::Command {
            quick: "sweep --scene gaitatzes-room --technique gaitatzes --sweep transport=cosine,carry,pyramid --param iterations=64 --quality --quality-reference multi-bounce --frames 4 --warmup 3 --timing stages",
            paper: "sweep --scene gaitatzes-room --technique gaitatzes --sweep transport=cosine,carry,pyramid --param iterations=64 --quality --quality-reference multi-bounce --resolution 512x512 --frames 100 --warmup 10 --timing stages",
        },
    },
    Target {
        name: "gaitatzes-sibenik",
        dir: "gaitatzes/sibenik",
        what: "gaitatzes' three transports on Sibenik against the multi-bounce reference (32³, the default 12 iterations)",
        kind: Kind::Command {
            quick: "sweep --scene sibenik --technique gaitatzes --sweep transport=cosine,carry,pyramid --quality --quality-reference multi-bounce --frames 4 --warmup 3 --timing stages",
            paper: "sweep --scene sibenik --technique gaitatzes --sweep transport=cosine,carry,pyramid --quality --quality-reference multi-bounce --resolution 512x512 --frames 100 --warmup 10 --timing stages",
        },
    },
    Target {
        name: "equal-time",
        dir: "equal-time",
        what: "every technique at equal time on the Cornell box and Sibenik: each quality knob (VPLs, iterations) set by a short timed search to the largest value whose frame fits the budget, then the error at those settings against both components",
        kind: Kind::Command {
            quick: "run --scene cornell,sibenik --equal-time 150ms --quality --quality-pairs 1 --frames 10 --warmup 3 --timing frame",
            paper: "run --scene cornell,sibenik --equal-time 33ms --quality --resolution 1024x768 --frames 100 --warmup 10 --timing frame",
        },
    },
];

/// The order `all --budget` runs the targets in: the papers' headline tables first (Laine's
/// Tables 1 and 2, the ISM slides' breakdown, Gaitatzes' Table 1, Barczak's figures, Keller's
/// sweeps), then the rest of the papers' targets, the parameter sweeps, the per-frame error
/// runs, the clamp sweeps and last the CPU reference (the same at both sizes). Every target of
/// [`TARGETS`] once (a unit test checks).
pub const PRIORITY: &[&str] = &[
    "laine-tables",
    "ism-breakdown",
    "gaitatzes-table1",
    "barczak2006",
    "keller-tiles",
    "keller-vpls",
    "laine-management",
    "laine-dispersion",
    "gaitatzes-quality",
    "gaitatzes-cornell",
    "laine-tiles",
    "laine-vpls",
    "laine-budget",
    "ism-points",
    "ism-map-size",
    "ism-vpls",
    "ism-tiles",
    "ism-pull-push-sun",
    "ism-pull-push-spot",
    "gaitatzes-grid",
    "gaitatzes-iterations",
    "gaitatzes-transport",
    "gaitatzes-sibenik",
    "equal-time",
    "laine-sibenik-1024",
    "laine-sibenik-vpls",
    "keller-lag",
    "laine-quality",
    "ism-quality",
    "ism-sampling",
    "ism-sampling-still",
    "clamp-cornell-laine",
    "clamp-cornell-keller-full",
    "clamp-maze-laine",
    "clamp-sibenik-laine",
    "reference",
];

/// `name`'s place in [`PRIORITY`].
pub fn priority(name: &str) -> usize {
    PRIORITY
        .iter()
        .position(|p| *p == name)
        .unwrap_or(PRIORITY.len())
}

impl Target {
    /// What it regenerates, one line.
    pub fn description(&self) -> String {
        match self.kind {
            Kind::Paper(m) => (m.describe)(self.name).to_string(),
            Kind::Command { quick, paper } if quick == paper => {
                format!("{} {SAME_SIZES}", self.what)
            }
            Kind::Command { .. } => self.what.to_string(),
        }
    }
}

/// The target called `name`.
pub fn find(name: &str) -> Result<&'static Target> {
    TARGETS
        .iter()
        .chain(EXTRA.iter())
        .find(|t| t.name == name)
        .ok_or_else(|| {
            let names: Vec<&str> = TARGETS.iter().chain(EXTRA.iter()).map(|t| t.name).collect();
            Error::param(
                "target",
                format!(
                    "unknown target '{name}'; expected all or one of: {}",
                    names.join(", ")
                ),
            )
        })
}

/// Targets that `all` does not run because another target makes the same files
/// (`laine-tables` writes both tables from one set of runs).
const EXTRA: &[Target] = &[
    Target {
        name: "laine-table1",
        dir: "laine",
        what: "",
        kind: Kind::Paper(&laine2007::MODULE),
    },
    Target {
        name: "laine-table2",
        dir: "laine",
        what: "",
        kind: Kind::Paper(&laine2007::MODULE),
    },
];

#[cfg(test)]
mod tests {
    /// Catches: a target added to TARGETS but not to the budget's priority order (it would
    /// always run last, silently), or one listed twice or misspelt.
    #[test]
    fn the_priority_order_lists_every_target_once() {
        let mut p: Vec<&str> = super::PRIORITY.to_vec();
        let mut t: Vec<&str> = super::TARGETS.iter().map(|t| t.name).collect();
        p.sort();
        t.sort();
        assert_eq!(p, t);
    }
}
