//! `gibench reproduce all`: every paper table, figure and sweep in one command.
//!
//! The targets are listed once, in [`TARGETS`]: the paper modules' typed reproductions and the
//! sweeps and runs that are plain gibench commands (each with its arguments at quick and at
//! paper sizes). `all` checks every selected target before any runs (scenes load, parameters
//! parse, folders are writable), prints a time estimate, runs them one after another on one
//! adapter under one progress bar, and publishes everything as one output set: each target's
//! folder under `--out` is replaced (files its target did not write are removed), so the folder
//! never mixes the files of two runs of a target. It then lists every table and figure it
//! wrote and records them in `reproduce-all.json` / `.md` (per target: the command, the work,
//! the estimate and the time taken) and `reproduce-all.html` (one page with every target's
//! figures and links to its tables and pages).
//!
//! **The estimate** scales the time each target took in the last `reproduce all` recorded in
//! the output folder (or in the committed `results/`) by the work it does now (frames ×
//! pixels; frames × VPLs for CPU-only targets); it says which adapter and mode those times were
//! measured on. A target never timed before has no estimate, and the printout says so.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use gibench_harness::gpu::GpuContext;
use gibench_harness::output::OutputSet;
use gibench_harness::report;
use gibench_harness::{Error, Result};

use super::{barczak2006, gaitatzes2010, ism2008, laine2007, out_dir, PaperModule, ReproduceArgs};
use crate::{Bars, Job};

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
];

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

/// A target checked and ready to run into `out`.
struct Planned {
    target: &'static Target,
    out: PathBuf,
    /// The equivalent command line (for the listing and the manifest).
    command: String,
    work: Work,
    /// `reproduce`'s arguments with `out` set (paper targets).
    args: ReproduceArgs,
    job: Option<Job>,
}

/// Frames rendered or stepped, and the work units estimates scale with.
#[derive(Clone, Copy, Default)]
struct Work {
    frames: u64,
    units: u64,
}

impl Planned {
    fn new(target: &'static Target, args: &ReproduceArgs, out: PathBuf) -> Result<Planned> {
        let mode = if args.quick { " --quick" } else { "" };
        let mut targs = args.clone();
        targs.out = Some(out.clone());
        match target.kind {
            Kind::Paper(m) => {
                (m.check)(target.name, &targs)?;
                let (frames, units) = (m.work)(target.name, &targs);
                let mut command = format!(
                    "gibench reproduce {}{mode} --out {}",
                    target.name,
                    out.display()
                );
                if let Some(f) = args.frames {
                    command.push_str(&format!(" --frames {f}"));
                }
                if !args.scenes.is_empty() {
                    command.push_str(&format!(" --scenes {}", args.scenes.join(",")));
                }
                if args.html {
                    command.push_str(" --html");
                }
                Ok(Planned {
                    target,
                    out,
                    command,
                    work: Work { frames, units },
                    args: targs,
                    job: None,
                })
            }
            Kind::Command { quick, paper } => {
                if !args.scenes.is_empty() {
                    return Err(Error::param(
                        "scenes",
                        format!(
                            "applies to the paper targets only; '{}' runs the scene its command names",
                            target.name
                        ),
                    ));
                }
                let mut argv: Vec<String> = (if args.quick { quick } else { paper })
                    .split_whitespace()
                    .map(String::from)
                    .collect();
                if let Some(f) = args.frames {
                    if argv[0] != "reference" {
                        set_option(&mut argv, "--frames", &f.to_string());
                    }
                }
                if let Some(a) = &args.assets {
                    set_option(&mut argv, "--assets", &a.display().to_string());
                }
                if args.html && argv[0] != "reference" {
                    argv.push("--html".into());
                }
                set_option(&mut argv, "--out", &out.display().to_string());
                let job = Job::plan(&argv).map_err(|e| {
                    Error::Invalid(format!(
                        "target '{}' (gibench {}): {e}",
                        target.name,
                        argv.join(" ")
                    ))
                })?;
                let (frames, units) = job.work();
                Ok(Planned {
                    target,
                    out,
                    command: format!("gibench {}", argv.join(" ")),
                    work: Work { frames, units },
                    args: targs,
                    job: Some(job),
                })
            }
        }
    }

    fn needs_gpu(&self) -> bool {
        match (&self.job, &self.target.kind) {
            (Some(job), _) => job.needs_gpu(),
            (None, Kind::Paper(m)) => (m.needs_gpu)(self.target.name),
            (None, Kind::Command { .. }) => true,
        }
    }

    /// Runs the target; returns a line saying what it wrote.
    fn run(&self, gpu: Option<&GpuContext>, bars: &Bars) -> Result<String> {
        match (&self.job, &self.target.kind) {
            (Some(job), _) => job.execute(gpu, bars),
            (None, Kind::Command { .. }) => Err(Error::Invalid(format!(
                "target '{}' was not planned",
                self.target.name
            ))),
            (None, Kind::Paper(m)) => {
                let (tables, runs) = (m.reproduce)(self.target.name, &self.args, gpu, bars)?;
                let mut written = Vec::new();
                for (table, stem) in &tables {
                    bars.table(table);
                    written.extend(report::write_tables(table, &self.out, stem)?);
                }
                let mut done = format!(
                    "wrote {}",
                    written
                        .iter()
                        .map(|p| p.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
                if self.args.html {
                    let page = self.out.join(format!("{}.html", self.target.name));
                    let figures = (m.figures)(&self.out, self.target.name);
                    crate::write_page(
                        &page,
                        self.target.description(),
                        tables.into_iter().map(|(t, _)| t).collect(),
                        figures,
                        crate::with_folder(&(m.runs_folder)(&self.args), runs),
                    )?;
                    done.push_str(&crate::page_line(&page));
                }
                Ok(done)
            }
        }
    }
}

/// Sets `--name value` in a command's arguments (replacing a value it has).
fn set_option(argv: &mut Vec<String>, name: &str, value: &str) {
    match argv.iter().position(|a| a == name) {
        Some(i) if i + 1 < argv.len() => argv[i + 1] = value.to_string(),
        _ => argv.extend([name.to_string(), value.to_string()]),
    }
}

/// `gibench reproduce TARGET` (one target) or `gibench reproduce all`.
pub fn reproduce(args: &ReproduceArgs) -> Result<()> {
    if args.target != "all" {
        if !args.only.is_empty() {
            return Err(Error::param(
                "only",
                "applies to `gibench reproduce all` only",
            ));
        }
        let target = find(&args.target)?;
        let out = out_dir(args, target.dir);
        let planned = Planned::new(target, args, out.clone())?;
        if args.list {
            println!(
                "{}  {}\n  {}",
                target.name,
                planned.target.description(),
                planned.command
            );
            return Ok(());
        }
        crate::writable_dir("out", &out)?;
        let set = OutputSet::begin("out", &out)?;
        let gpu = if planned.needs_gpu() && planned.job.is_some() {
            Some(super::open_gpu(args)?)
        } else {
            None
        };
        let done = planned.run(gpu.as_ref(), &Bars::Own(args.quiet))?;
        set.publish()?;
        eprintln!("{done}");
        return Ok(());
    }
    if !args.scenes.is_empty() {
        return Err(Error::param(
            "scenes",
            "applies to single Laine targets; `all` runs every target on its own scenes",
        ));
    }
    let root = args.out.clone().unwrap_or_else(|| PathBuf::from("results"));
    let selected: Vec<&'static Target> = if args.only.is_empty() {
        TARGETS.iter().collect()
    } else {
        let mut picked = Vec::new();
        for name in &args.only {
            let t = TARGETS
                .iter()
                .find(|t| t.name == name.trim())
                .ok_or_else(|| {
                    Error::param(
                        "only",
                        format!(
                            "'{name}' is not a target of `all`; expected some of: {}",
                            TARGETS
                                .iter()
                                .map(|t| t.name)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    )
                })?;
            if picked.iter().any(|p: &&Target| p.name == t.name) {
                return Err(Error::param("only", format!("'{name}' is listed twice")));
            }
            picked.push(t);
        }
        // In the order of TARGETS, whatever the order given.
        TARGETS
            .iter()
            .filter(|t| picked.iter().any(|p| p.name == t.name))
            .collect()
    };
    // Every target is checked before any runs.
    eprintln!("gibench reproduce all: checking {} targets", selected.len());
    let planned: Vec<Planned> = selected
        .iter()
        .map(|t| Planned::new(t, args, root.join(t.dir)))
        .collect::<Result<_>>()?;
    let mode = if args.quick { "quick" } else { "paper" };
    let gpu = if planned.iter().any(Planned::needs_gpu) {
        Some(super::open_gpu(args)?)
    } else {
        None
    };
    let adapter = gpu
        .as_ref()
        .map(|g| format!("{} ({})", g.info.adapter, g.info.backend))
        .unwrap_or_else(|| "CPU only".into());
    let previous = Manifest::previous(&root);
    let measured: Vec<Option<(f64, String)>> = planned
        .iter()
        .map(|p| {
            previous
                .as_ref()
                .and_then(|m| m.estimate(p.target.name, p.work.units))
        })
        .collect();
    let estimates: Vec<Option<f64>> = measured.iter().map(|m| m.as_ref().map(|e| e.0)).collect();
    // The adapters the estimates were measured on (a CPU-only target's on any).
    let mut sources: Vec<&str> = measured
        .iter()
        .zip(&planned)
        .filter(|(_, p)| p.needs_gpu())
        .filter_map(|(m, _)| m.as_ref().map(|e| e.1.as_str()))
        .collect();
    sources.sort();
    sources.dedup();
    print_plan(
        &planned,
        &estimates,
        previous.as_ref(),
        &sources,
        mode,
        &adapter,
        &root,
    );
    if args.list {
        return Ok(());
    }
    crate::writable_dir("out", &root)?;
    let set = OutputSet::begin("out", &root)?;
    for p in &planned {
        if matches!(p.target.kind, Kind::Command { .. }) {
            set.replace(Path::new(p.target.dir))?;
        }
        if let Kind::Paper(m) = p.target.kind {
            for sub in (m.owned_folders)(p.target.name) {
                set.replace(&Path::new(p.target.dir).join(sub))?;
            }
        }
    }
    // The bar advances in estimated milliseconds (work units where there is no estimate).
    let spans: Vec<u64> = if estimates.iter().all(Option::is_some) {
        estimates
            .iter()
            .map(|e| (e.unwrap_or(0.0) * 1e3).max(1.0) as u64)
            .collect()
    } else {
        planned.iter().map(|p| p.work.units.max(1)).collect()
    };
    let overall = Overall::new(args.quiet, spans.iter().sum());
    let started = Instant::now();
    let mut records = Vec::new();
    let mut before = set.staged().len();
    for (i, p) in planned.iter().enumerate() {
        overall.start(
            &format!("{}/{} {}", i + 1, planned.len(), p.target.name),
            spans[i],
            p.work.frames,
        );
        let t = Instant::now();
        let done = p.run(gpu.as_ref(), &Bars::Shared(&overall))?;
        let seconds = t.elapsed().as_secs_f64();
        let staged = set.staged();
        let files: Vec<PathBuf> = staged[before..].to_vec();
        before = staged.len();
        overall.note(&format!(
            "{} done in {}: {done}",
            p.target.name,
            duration(seconds)
        ));
        records.push(Record {
            name: p.target.name.to_string(),
            dir: p.target.dir.to_string(),
            what: p.target.description(),
            command: p.command.clone(),
            frames: p.work.frames,
            units: p.work.units,
            estimate_s: estimates[i],
            seconds: Some(seconds),
            files: files
                .iter()
                .map(|f| f.to_string_lossy().into_owned())
                .collect(),
            carried_from: None,
            adapter: if p.needs_gpu() {
                adapter.clone()
            } else {
                "CPU only".into()
            },
        });
    }
    overall.finish();
    let seconds = started.elapsed().as_secs_f64();
    let estimate: Option<f64> = estimates.iter().copied().sum();
    let manifest = Manifest::new(
        mode,
        &adapter,
        gpu.as_ref(),
        seconds,
        estimate,
        records,
        // Entries are carried over only from this folder's own manifest: one found elsewhere
        // (the committed results/) only gives estimates; its files are not here.
        previous
            .as_ref()
            .filter(|p| p.source == root.join(format!("{MANIFEST}.json"))),
    );
    let manifest = manifest.dated_by_their_files(&root);
    manifest.write(&root)?;
    manifest.write_index(&root)?;
    set.publish()?;
    println!("{}", manifest.listing(&root));
    Ok(())
}

/// The `git_commit` the first of `files` (relative to `root`) that is a JSON object naming one
/// records: the commit that made a target's files.
fn recorded_commit(root: &Path, files: &[String]) -> Option<String> {
    files.iter().filter(|f| f.ends_with(".json")).find_map(|f| {
        let bytes = gibench_harness::error::read_bounded(&root.join(f), 64 << 20).ok()?;
        let v: serde_json::Value = serde_json::from_slice(&bytes).ok()?;
        let commit = v.get("git_commit")?.as_str()?;
        (!commit.is_empty()).then(|| commit.to_string())
    })
}

/// "12m03s" (one word, for scripts reading `--list`).
fn duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{seconds:.1}s")
    }
}

#[allow(clippy::too_many_arguments)]
fn print_plan(
    planned: &[Planned],
    estimates: &[Option<f64>],
    previous: Option<&Manifest>,
    sources: &[&str],
    mode: &str,
    adapter: &str,
    root: &Path,
) {
    eprintln!(
        "gibench reproduce all ({mode} sizes) on {adapter}: {} targets into {}",
        planned.len(),
        root.display()
    );
    for (p, e) in planned.iter().zip(estimates) {
        eprintln!(
            "  {:<26} {:>9}  {:<22} {}",
            p.target.name,
            e.map(duration).unwrap_or_else(|| "?".into()),
            p.target.dir,
            p.command
        );
    }
    let known: f64 = estimates.iter().flatten().sum::<f64>().max(0.0);
    let unknown = estimates.iter().filter(|e| e.is_none()).count();
    match previous {
        Some(_) if unknown == estimates.len() => eprintln!(
            "estimate: none — the run recorded in {} timed none of these targets",
            Manifest::places(root)
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" or ")
        ),
        Some(m) => eprintln!(
            "estimate: {}{} — the times of the {} run recorded in {} (on {}), scaled by the work each target does now{}",
            duration(known),
            if unknown > 0 { format!(" + {unknown} targets never timed") } else { String::new() },
            m.mode,
            m.source.display(),
            if sources.is_empty() { "the CPU".to_string() } else { sources.join("; ") },
            if sources.iter().any(|s| *s != adapter) { "; a different adapter, so only a rough guide" } else { "" }
        ),
        None => eprintln!(
            "estimate: none — no earlier `reproduce all` is recorded in {} (the bar shows the work done instead)",
            Manifest::places(root)
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" or ")
        ),
    }
}

/// `reproduce all`'s progress bar: one span per target, advanced by its frames.
pub struct Overall {
    bar: indicatif::ProgressBar,
    state: Mutex<Span>,
}

#[derive(Default)]
struct Span {
    start: u64,
    len: u64,
    frames: u64,
    done: u64,
    label: String,
}

impl Overall {
    fn new(quiet: bool, total: u64) -> Overall {
        let bar = if quiet {
            indicatif::ProgressBar::hidden()
        } else {
            indicatif::ProgressBar::new(total.max(1))
        };
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:<44} [{bar:30}] {percent:>3}% {elapsed_precise} (ETA {eta_precise})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Overall {
            bar,
            state: Mutex::new(Span::default()),
        }
    }

    /// The next target: `len` of the bar, `frames` frames.
    fn start(&self, label: &str, len: u64, frames: u64) {
        if let Ok(mut s) = self.state.lock() {
            let start = s.start + s.len;
            *s = Span {
                start,
                len,
                frames,
                done: 0,
                label: label.to_string(),
            };
            self.bar.set_position(start);
        }
        self.bar.set_message(label.to_string());
    }

    /// A technique's pass starts.
    pub fn technique(&self, name: &str) {
        if let Ok(s) = self.state.lock() {
            self.bar.set_message(format!("{} · {name}", s.label));
        }
    }

    /// A frame was rendered.
    pub fn frame(&self) {
        if let Ok(mut s) = self.state.lock() {
            s.done += 1;
            if s.frames > 0 {
                let part = s.len as f64 * (s.done.min(s.frames) as f64 / s.frames as f64);
                self.bar.set_position(s.start + part as u64);
            }
        }
    }

    /// A line above the bar.
    pub fn note(&self, line: &str) {
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// One target's entry in `reproduce-all.json`.
#[derive(serde::Serialize, serde::Deserialize, Clone)]
struct Record {
    name: String,
    dir: String,
    what: String,
    command: String,
    frames: u64,
    units: u64,
    estimate_s: Option<f64>,
    seconds: Option<f64>,
    /// Relative to the results root.
    files: Vec<String>,
    /// Not run this time: the entry (and its files) are from this earlier commit's run.
    carried_from: Option<String>,
    /// The adapter the target ran on ("CPU only" for targets that need none).
    #[serde(default)]
    adapter: String,
}

/// `reproduce-all.json`: what the last `reproduce all` into a folder ran and wrote.
#[derive(serde::Serialize, serde::Deserialize)]
struct Manifest {
    mode: String,
    adapter: String,
    driver: String,
    git_commit: String,
    cpu_threads: usize,
    seconds: f64,
    estimate_s: Option<f64>,
    targets: Vec<Record>,
    #[serde(skip)]
    source: PathBuf,
}

const MANIFEST: &str = "reproduce-all";

impl Manifest {
    /// Where an earlier manifest is looked for: `root`, then `results/`.
    fn places(root: &Path) -> Vec<PathBuf> {
        let mut places = vec![root.join(format!("{MANIFEST}.json"))];
        let committed = Path::new("results").join(format!("{MANIFEST}.json"));
        if places[0] != committed {
            places.push(committed);
        }
        places
    }

    /// The manifest in `root`, else in `results/`.
    fn previous(root: &Path) -> Option<Manifest> {
        Self::places(root).into_iter().find_map(|p| {
            let text = gibench_harness::error::read_bounded(&p, 16 << 20).ok()?;
            let mut m: Manifest = serde_json::from_slice(&text).ok()?;
            m.source = p;
            Some(m)
        })
    }

    /// Seconds for `target` doing `units` of work, from its recorded rate, and the adapter
    /// that rate was measured on.
    fn estimate(&self, target: &str, units: u64) -> Option<(f64, String)> {
        let r = self.targets.iter().find(|r| r.name == target)?;
        let s = r.seconds?;
        let adapter = if r.adapter.is_empty() {
            self.adapter.clone()
        } else {
            r.adapter.clone()
        };
        (r.units > 0).then(|| (s * units as f64 / r.units as f64, adapter))
    }

    fn new(
        mode: &str,
        adapter: &str,
        gpu: Option<&GpuContext>,
        seconds: f64,
        estimate_s: Option<f64>,
        mut targets: Vec<Record>,
        previous: Option<&Manifest>,
    ) -> Manifest {
        // Targets not run this time keep their earlier entry (their files are untouched).
        if let Some(prev) = previous.filter(|p| p.mode == mode) {
            for r in &prev.targets {
                if !targets.iter().any(|t| t.name == r.name) {
                    let mut r = r.clone();
                    r.carried_from
                        .get_or_insert_with(|| prev.git_commit.clone());
                    if r.adapter.is_empty() {
                        r.adapter = prev.adapter.clone();
                    }
                    targets.push(r);
                }
            }
            let order = |name: &str| TARGETS.iter().position(|t| t.name == name);
            targets.sort_by_key(|r| order(&r.name));
        }
        Manifest {
            mode: mode.to_string(),
            adapter: adapter.to_string(),
            driver: gpu.map(|g| g.info.driver.clone()).unwrap_or_default(),
            git_commit: gibench_harness::runner::git_commit(),
            cpu_threads: std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            seconds,
            estimate_s,
            targets,
            source: PathBuf::new(),
        }
    }

    /// The entries carried from an earlier run dated by the commit their files record, where
    /// they record one: a target regenerated on its own since that run was made by another
    /// commit than the one the earlier manifest names.
    fn dated_by_their_files(mut self, root: &Path) -> Manifest {
        for r in &mut self.targets {
            if r.carried_from.is_some() {
                if let Some(commit) = recorded_commit(root, &r.files) {
                    r.carried_from = Some(commit);
                }
            }
        }
        self
    }

    /// Tables (`.md`, with `.csv` and `.tex` beside) and figures (`.svg`, `--html`'s pages, the
    /// reference's `.png` images) of a record.
    fn outputs(r: &Record) -> (Vec<&str>, Vec<&str>, usize) {
        let figure = |f: &str| {
            f.ends_with(".svg")
                || f.ends_with(".html")
                || (r.name == "reference" && f.ends_with(".png"))
        };
        let tables: Vec<&str> = r
            .files
            .iter()
            .filter(|f| f.ends_with(".md"))
            .map(String::as_str)
            .collect();
        let figures: Vec<&str> = r
            .files
            .iter()
            .filter(|f| figure(f))
            .map(String::as_str)
            .collect();
        (tables, figures, r.files.len())
    }

    fn write(&self, root: &Path) -> Result<()> {
        let json = serde_json::to_vec_pretty(self).map_err(|e| Error::Invalid(e.to_string()))?;
        gibench_harness::error::write_atomic(&root.join(format!("{MANIFEST}.json")), &json)?;
        let mut md = format!(
            "# gibench reproduce all ({} sizes)\n\nLast run: on {}{}, git {}, {} CPU threads: {} ({}). \
             Targets it did not run keep the entry of the run that made their files (\"from git …\").\n\n\
             | target | what | command | ran on | time (estimate) | tables | figures | files |\n|---|---|---|---|---|---|---|---|\n",
            self.mode,
            self.adapter,
            if self.driver.is_empty() {
                String::new()
            } else {
                format!(" (driver {})", self.driver)
            },
            self.git_commit,
            self.cpu_threads,
            duration(self.seconds),
            self.estimate_s
                .map(|e| format!("estimated {}", duration(e)))
                .unwrap_or_else(|| "no estimate".into()),
        );
        for r in &self.targets {
            let (tables, figures, files) = Self::outputs(r);
            let time = match (r.seconds, &r.carried_from) {
                (_, Some(c)) => format!("from git {c}"),
                (Some(s), None) => format!(
                    "{} ({})",
                    duration(s),
                    r.estimate_s.map(duration).unwrap_or_else(|| "?".into())
                ),
                (None, None) => "?".into(),
            };
            md.push_str(&format!(
                "| {} | {} | `{}` | {} | {time} | {} | {} | {files} |\n",
                r.name,
                r.what,
                r.command,
                r.adapter,
                tables.join("<br>"),
                figures.join("<br>"),
            ));
        }
        gibench_harness::error::write_atomic(&root.join(format!("{MANIFEST}.md")), md.as_bytes())
    }

    /// `reproduce-all.html`: every target with its pages, tables and figures.
    fn write_index(&self, root: &Path) -> Result<()> {
        let entries: Vec<gibench_harness::html::IndexEntry> = self
            .targets
            .iter()
            .map(|r| gibench_harness::html::IndexEntry {
                name: r.name.clone(),
                what: r.what.clone(),
                time: match (r.seconds, &r.carried_from) {
                    (_, Some(c)) => format!("from the run of git {c}"),
                    (Some(s), None) => duration(s),
                    (None, None) => "?".into(),
                },
                files: r.files.clone(),
            })
            .collect();
        gibench_harness::html::write_index(
            &root.join(format!("{MANIFEST}.html")),
            &format!(
                "gibench reproduce all ({} sizes) on {}",
                self.mode, self.adapter
            ),
            &crate::command_line(),
            &entries,
        )
    }

    /// Every table and figure, per target, for the terminal.
    fn listing(&self, root: &Path) -> String {
        let mut out = format!(
            "gibench reproduce all ({} sizes) took {} ({}); wrote into {}:",
            self.mode,
            duration(self.seconds),
            self.estimate_s
                .map(|e| format!("estimated {}", duration(e)))
                .unwrap_or_else(|| "no estimate".into()),
            root.display()
        );
        for r in self.targets.iter().filter(|r| r.carried_from.is_none()) {
            let (tables, figures, files) = Self::outputs(r);
            out.push_str(&format!("\n  {} ({files} files)", r.name));
            for t in tables {
                out.push_str(&format!("\n    table  {t} (.csv, .tex beside)"));
            }
            for f in figures {
                let kind = if f.ends_with(".html") {
                    "page  "
                } else {
                    "figure"
                };
                out.push_str(&format!("\n    {kind} {f}"));
            }
        }
        out.push_str(&format!(
            "\n  and {MANIFEST}.json / {MANIFEST}.md: every target's command, time and files"
        ));
        out.push_str(&format!(
            "\n  and {MANIFEST}.html: every target's pages, tables and figures on one page"
        ));
        out
    }
}
