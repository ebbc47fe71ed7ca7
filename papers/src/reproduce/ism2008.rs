//! Ritschel, Grosch, Kim, Seidel, Dachsbacher and Kautz 2008, "Imperfect Shadow Maps for
//! Efficient Computation of Indirect Illumination", as the Kautz course slides present it: the
//! performance breakdown of Sponza, regenerated through the typed run API with the published
//! figures (`results/papers/ism2008.json`, labelled with their source) beside ours.
//!
//! * `ism-breakdown`: on one scene and the same frames, `ism` (RSM, VPL sampling, point splat,
//!   pull-push, gathering, filter), `ism-classic` (the same RSM-sampled VPLs with classic
//!   triangle-rasterised maps) and `keller-full` (instant radiosity with classic maps) at the same
//!   VPL count, map size and tiles: per-stage times, frame times, and the two ratios the slides
//!   state — classic maps against imperfect ones ("10 to 15 times longer") and the frame rate
//!   against instant radiosity with classic maps ("around ten times faster"). Beside them, the
//!   slides' figures and, as a second anchor, a master's thesis's per-stage figures on a later
//!   GPU.
//!
//! Paper sizes (Sponza, 1024 VPLs, 256² maps, 8k points per VPL, 16 VPLs per pixel: 8x8 tiles)
//! are the defaults, for a GPU; `--quick` keeps Sponza, 8k points per VPL and 16 VPLs per pixel
//! but takes 256 VPLs (4x4 tiles) with 64² maps at 256x192, so that the classic maps finish on a
//! CPU adapter.

use gibench_harness::kit::ir::gather::{COMMON_STAGES, STAGE_FILTER, STAGE_VPL_SHADOW_MAPS};
use gibench_harness::kit::technique::TechniqueInfo;
use gibench_harness::measure::results::RunResult;
use gibench_harness::report::{self, Cell, Table};
use gibench_harness::run::session::{RunSpec, TechniqueRun};
use gibench_harness::{Error, Result};
use gibench_ism::{STAGE_POINT_SPLAT, STAGE_PULL_PUSH, STAGE_RSM, STAGE_VPL_SAMPLING};
use gibench_keller::STAGE_VPL_GENERATION;

use super::{device_note, load_scene, ms, sum_ms, PaperModule, ReproduceArgs, Reproduction};
use crate::progress::Bars;
use gibench_harness::gpu::GpuContext;

/// The module's entry for `reproduce all`.
pub const MODULE: PaperModule = PaperModule {
    describe,
    owned_folders: |_| &["runs"],
    check,
    work,
    needs_gpu: |_| true,
    reproduce,
    runs_folder,
    figures: |_, _| Vec::new(),
};

/// What each target regenerates.
pub fn describe(target: &str) -> &'static str {
    match target {
        "ism-breakdown" => {
            "Ritschel et al. 2008 (course slides): ISM per-stage breakdown on Sponza, ISM vs classic maps on the same VPLs, vs keller-full"
        }
        _ => "",
    }
}

/// The target's sizes.
struct Sizes {
    scene: String,
    resolution: [u32; 2],
    vpls: u32,
    tiles: &'static str,
    map_size: u32,
    points_per_vpl: u32,
    pool: u32,
    frames: u32,
    warmup: u32,
}

/// The paper's sizes, or `--quick`'s; `--frames` and `--scenes` (its first) override.
fn sizes(args: &ReproduceArgs) -> Sizes {
    let mut s = if args.quick {
        Sizes {
            scene: "sponza".into(),
            resolution: [256, 192],
            vpls: 256,
            tiles: "4x4",
            map_size: 64,
            points_per_vpl: 8192,
            pool: 1 << 18,
            frames: 4,
            warmup: 3,
        }
    } else {
        Sizes {
            scene: "sponza".into(),
            // The slides do not state the resolution.
            resolution: [1024, 768],
            vpls: 1024,
            tiles: "8x8",
            map_size: 256,
            points_per_vpl: 8192,
            pool: 1 << 20,
            frames: 100,
            warmup: 10,
        }
    };
    if let Some(f) = args.frames {
        s.frames = f;
    }
    if args.tiny() {
        s.resolution = [64, 48];
    }
    if let Some(scene) = args.scenes.first() {
        s.scene = scene.clone();
    }
    s
}

fn check_target(target: &str) -> Result<()> {
    if target != "ism-breakdown" {
        return Err(Error::param(
            "target",
            format!("not an imperfect-shadow-map target: '{target}'"),
        ));
    }
    Ok(())
}

/// Checks what can be checked before any work: the target, the scene, the parameters.
pub fn check(target: &str, args: &ReproduceArgs) -> Result<()> {
    check_target(target)?;
    let scene = load_scene(&sizes(args).scene, args)?;
    spec(args, &scene)?.validate()
}

/// (frames rendered, frames × pixels): three techniques, timed per stage and per frame.
pub fn work(_: &str, args: &ReproduceArgs) -> (u64, u64) {
    let s = sizes(args);
    let frames = 3 * 2 * (s.frames + s.warmup) as u64;
    (
        frames,
        frames * s.resolution[0] as u64 * s.resolution[1] as u64,
    )
}

/// The folder of the runs behind the table.
pub fn runs_folder(args: &ReproduceArgs) -> std::path::PathBuf {
    super::out_dir(args, "ism/breakdown").join("runs")
}

/// The three runs on `scene`, on equal terms: the same VPL count, map size, tiles, frames,
/// resolution; 32-bit depth for both kinds of classic maps (the imperfect maps are 32-bit
/// float).
fn spec<'s>(args: &ReproduceArgs, scene: &'s gibench_harness::scene::Scene) -> Result<RunSpec<'s>> {
    let s = sizes(args);
    let all = crate::registry::all();
    let (vpls, size) = (s.vpls.to_string(), s.map_size.to_string());
    let (points, pool) = (s.points_per_vpl.to_string(), s.pool.to_string());
    let shared = [
        ("vpls", vpls.as_str()),
        ("tiles", s.tiles),
        ("vpl-map-size", size.as_str()),
    ];
    let stem = |t: &str| {
        format!(
            "{}-{t}-{}x{}",
            scene.descriptor.name, s.resolution[0], s.resolution[1]
        )
    };
    let mut ism = shared.to_vec();
    ism.extend([
        ("points-per-vpl", points.as_str()),
        ("point-pool", pool.as_str()),
    ]);
    let mut keller = shared.to_vec();
    keller.extend([("vpl-map", "paraboloid"), ("depth-bits", "32")]);
    let runs = vec![
        TechniqueRun::new(TechniqueInfo::find(all, "ism")?, &ism, stem("ism"))?,
        TechniqueRun::new(
            TechniqueInfo::find(all, "ism-classic")?,
            &shared,
            stem("ism-classic"),
        )?,
        TechniqueRun::new(
            TechniqueInfo::find(all, "keller-full")?,
            &keller,
            stem("keller-full"),
        )?,
    ];
    Ok(RunSpec {
        scene,
        runs,
        config: super::paper_config(args, s.resolution, s.frames, s.warmup, false),
        quality: None,
        cache: crate::options::default_reference_cache(),
        out: runs_folder(args),
        images: false,
    })
}

/// Runs the three techniques and builds the breakdown table.
pub fn reproduce(
    target: &str,
    args: &ReproduceArgs,
    gpu: Option<&GpuContext>,
    bars: &Bars,
) -> Result<(Vec<Reproduction>, Vec<RunResult>)> {
    check_target(target)?;
    let scene = load_scene(&sizes(args).scene, args)?;
    let spec = spec(args, &scene)?;
    spec.validate()?;
    let mut opened = None;
    let gpu = super::gpu_or_open(gpu, args, &mut opened)?;
    let runs = crate::progress::execute_with_bar(bars, gpu, &spec)?;
    let table = breakdown(args, &scene, &runs)?;
    Ok((vec![(table, "ism-breakdown")], runs))
}

/// The published figures.
fn paper() -> Result<serde_json::Value> {
    super::paper(
        "ism2008",
        include_str!("../../../results/papers/ism2008.json"),
    )
}

/// The time a run spends making its VPLs' maps: `ism`'s splat and pull-push, the others'
/// rasterised maps.
fn maps_ms(r: &RunResult) -> Option<f64> {
    if r.technique == "ism" {
        sum_ms(r, &[STAGE_POINT_SPLAT, STAGE_PULL_PUSH])
    } else {
        ms(r, STAGE_VPL_SHADOW_MAPS)
    }
}

fn fps(r: &RunResult) -> Option<f64> {
    r.frame.as_ref().map(|f| f.fps)
}

/// Gathering: split, accumulate and combine (the filter is its own column).
const GATHERING: [&str; 3] = [COMMON_STAGES[0], COMMON_STAGES[1], COMMON_STAGES[2]];

/// The breakdown table: our runs' stages beside the slides' and the thesis' figures.
fn breakdown(
    args: &ReproduceArgs,
    scene: &gibench_harness::scene::Scene,
    runs: &[RunResult],
) -> Result<Table> {
    let s = sizes(args);
    let paper = paper()?;
    let ism = runs
        .iter()
        .find(|r| r.technique == "ism")
        .ok_or_else(|| Error::Invalid("ism-breakdown: no ism run".into()))?;
    let columns: Vec<String> = [
        "source",
        "technique",
        "scene (triangles)",
        "resolution",
        "VPLs (mean / min)",
        "map",
        "points / VPL",
        "RSM",
        "VPL sampling",
        "VPL maps",
        "point splat",
        "pull-push",
        "gathering",
        "filter",
        "frame",
        "FPS",
        "maps ÷ ISM maps",
        "FPS ism ÷ FPS",
    ]
    .map(String::from)
    .into();
    let triangles = scene.mesh.triangle_count();
    let mut rows: Vec<Vec<Cell>> = runs
        .iter()
        .map(|r| our_row(r, ism, &s, triangles))
        .collect();
    rows.extend(slides_rows(&paper));
    rows.push(thesis_row(&paper));
    let t = &paper["thesis"];
    let all: Vec<&RunResult> = runs.iter().collect();
    let frames = (ism.frames.measured, ism.frames.warmup);
    Ok(Table {
        title: format!(
            "Imperfect shadow maps (Ritschel et al. 2008): per-stage breakdown on {} (ms), ISM against classic maps on the same VPLs",
            scene.descriptor.name
        ),
        columns,
        rows,
        notes: vec![
            format!(
                "gibench rows: medians over {} frames ({} warm-up frames dropped) of the same animation (light and camera \
                 moving), stages timed with the queue flushed before and after, frame and FPS without added synchronisation. \
                 All three at {} VPLs, {}² paraboloid maps, {} tiles ({} VPLs per pixel): `ism` splats {} points per VPL \
                 (from a pool of {}) and fills holes with pull-push; `ism-classic` takes the same RSM-sampled VPLs \
                 and rasterises every triangle into each VPL's map (32-bit depth); `keller-full` traces its VPLs on the CPU \
                 and rasterises the same way. VPL maps: `ism`'s point splat + pull-push, the others' `vpl-shadow-maps`. \
                 Gathering: split + accumulate + combine. maps ÷ ISM maps: the slides' \"classic shadow maps take 10 to 15 \
                 times longer\"; FPS ism ÷ FPS: their \"around ten times faster than normal instant radiosity\". The direct \
                 light, G-buffer and compose are in the results files.",
                frames.0,
                frames.1,
                s.vpls,
                s.map_size,
                s.tiles,
                s.vpls / tiles_count(s.tiles),
                s.points_per_vpl,
                s.pool
            ),
            format!(
                "Slides rows: {}; {}",
                paper["source"].as_str().unwrap_or(""),
                paper["note"].as_str().unwrap_or("")
            ),
            format!(
                "Thesis row: {}; {}; {}",
                t["source"].as_str().unwrap_or(""),
                t["hardware"].as_str().unwrap_or(""),
                t["note"].as_str().unwrap_or("")
            ),
            device_note(&all),
        ],
    })
}

/// A row of ours: run `r` beside the `ism` run, at sizes `s` on a scene of `triangles`.
fn our_row(r: &RunResult, ism: &RunResult, s: &Sizes, triangles: usize) -> Vec<Cell> {
    let is_ism = r.technique == "ism";
    let frame = r.frame.as_ref().map(|f| f.frame_ms.median);
    vec![
        Cell::text("gibench"),
        Cell::text(&r.technique),
        Cell::text(format!("{} ({triangles})", r.scene)),
        Cell::text(format!("{}x{}", r.resolution[0], r.resolution[1])),
        report::vpl_count_cell(r),
        Cell::text(format!("{0}²", s.map_size)),
        if is_ism {
            Cell::Num(Some(s.points_per_vpl as f64), 0)
        } else {
            Cell::text("triangles")
        },
        Cell::Ms(ms(r, STAGE_RSM)),
        // keller-full traces its VPLs from the light on the CPU.
        Cell::Ms(ms(r, STAGE_VPL_SAMPLING).or_else(|| ms(r, STAGE_VPL_GENERATION))),
        Cell::Ms(maps_ms(r)),
        Cell::Ms(ms(r, STAGE_POINT_SPLAT)),
        Cell::Ms(ms(r, STAGE_PULL_PUSH)),
        Cell::Ms(sum_ms(r, &GATHERING)),
        Cell::Ms(ms(r, STAGE_FILTER)),
        Cell::Ms(frame),
        Cell::Num(fps(r), 1),
        Cell::Num(
            (!is_ism)
                .then(|| maps_ms(r).zip(maps_ms(ism)).map(|(a, b)| a / b))
                .flatten(),
            2,
        ),
        Cell::Num(
            (!is_ism)
                .then(|| fps(ism).zip(fps(r)).map(|(a, b)| a / b))
                .flatten(),
            2,
        ),
    ]
}

/// A scene's name and triangle count (in thousands) as the paper gives them.
fn paper_scene_cell(name: &serde_json::Value, tris: &serde_json::Value) -> Cell {
    Cell::text(format!(
        "{} ({}k)",
        name.as_str().unwrap_or("?"),
        tris.as_f64().unwrap_or(0.0) / 1000.0
    ))
}

/// The rows of the course slides: ISM, classic maps on the same VPLs, instant radiosity.
fn slides_rows(paper: &serde_json::Value) -> Vec<Vec<Cell>> {
    let mut rows = Vec::new();
    let b = &paper["breakdown"];
    let slides = format!(
        "Ritschel et al. 2008, course slides ({}, {})",
        paper["hardware"].as_str().unwrap_or("?"),
        paper["year"]
    );
    let n = |v: &serde_json::Value| v.as_f64();
    let (lo, hi) = (
        n(&b["classic_over_ism"][0]).unwrap_or(f64::NAN),
        n(&b["classic_over_ism"][1]).unwrap_or(f64::NAN),
    );
    let ism_ms = n(&b["ism_ms"]).unwrap_or(f64::NAN);
    let slide_row = |technique: &str, maps: Cell, ratio: Cell, fps: Cell, speedup: Cell| {
        vec![
            Cell::text(&slides),
            Cell::text(technique),
            paper_scene_cell(&b["scene"], &b["triangles"]),
            Cell::text("not stated"),
            Cell::Num(n(&b["vpls"]), 0),
            Cell::text(format!("{}²", b["map_size"])),
            Cell::Num(n(&b["points_per_vpl"]), 0),
            Cell::Ms(None),
            Cell::Ms(None),
            maps,
            Cell::Ms(None),
            Cell::Ms(None),
            Cell::Ms(None),
            Cell::Ms(None),
            Cell::Ms(None),
            fps,
            ratio,
            speedup,
        ]
    };
    rows.push(slide_row(
        "ISM",
        Cell::Ms(Some(ism_ms)),
        Cell::Num(None, 1),
        Cell::text(format!("> {}", b["fps_min"])),
        Cell::Num(None, 1),
    ));
    rows.push(slide_row(
        "classic maps, same VPLs",
        Cell::text(format!("{:.0}–{:.0}", ism_ms * lo, ism_ms * hi)),
        Cell::text(format!("{lo}–{hi}")),
        Cell::Num(None, 1),
        Cell::Num(None, 1),
    ));
    rows.push(slide_row(
        "instant radiosity, classic maps",
        Cell::Ms(None),
        Cell::Num(None, 1),
        Cell::Num(None, 1),
        Cell::text(format!("~{}", b["speedup_over_ir_with_classic_maps"])),
    ));
    rows
}

/// The row of Linke's master's thesis (its per-stage times).
fn thesis_row(paper: &serde_json::Value) -> Vec<Cell> {
    let n = |v: &serde_json::Value| v.as_f64();
    let t = &paper["thesis"];
    let tm = &t["ms"];
    let plus = |a: &str, b: &str| Cell::text(format!("{} + {}", tm[a], tm[b]));
    vec![
        Cell::text("Linke, master's thesis (GTX 980 at base clock)"),
        Cell::text("ISM (points collected per pixel)"),
        paper_scene_cell(&t["scene"], &t["triangles"]),
        Cell::text(format!("{}x{}", t["resolution"][0], t["resolution"][1])),
        Cell::Num(n(&t["vpls"]), 0),
        Cell::text(format!("{}²", t["map_size"])),
        Cell::Ms(None),
        Cell::Ms(n(&tm["rsm"])),
        Cell::text("several µs"),
        Cell::Ms(n(&tm["ism"])),
        plus("point_collection", "point_rendering"),
        plus("pull", "push"),
        Cell::Ms(n(&tm["gathering"])),
        Cell::Ms(n(&tm["blur"])),
        Cell::Ms(n(&tm["total"])),
        Cell::Num(None, 1),
        Cell::Num(None, 1),
        Cell::Num(None, 1),
    ]
}

/// N × M of "NxM".
fn tiles_count(tiles: &str) -> u32 {
    tiles
        .split_once('x')
        .and_then(|(a, b)| Some(a.parse::<u32>().ok()? * b.parse::<u32>().ok()?))
        .unwrap_or(1)
        .max(1)
}
