//! Laine, Saransaari, Kontkanen, Lehtinen and Aila 2007, "Incremental Instant Radiosity for
//! Real-Time Indirect Illumination": its Tables 1 and 2, the VPL management cost of §6 and the
//! dispersion of the sampling points, regenerated through the typed run API with the paper's
//! figures (`results/papers/laine2007.json`, labelled with their source) beside ours.
//!
//! * `laine-table1`: per scene × resolution, `laine` and its comparison method `keller-full` on
//!   the same frames: direct illumination (shadow map + PCF), G-buffer, Σ common (split,
//!   accumulate, combine, filter), shadow-map rendering of both methods, FPS of both, and the
//!   speedups. The paper's indirect speedup is (frame_comp − direct) / (frame_ours − direct),
//!   which reproduces its printed values from its own columns.
//! * `laine-table2`: split, accumulate, combine, filter and Σ common per resolution.
//! * `laine-management`: VPL management cost on the CPU, spot vs omni, at 256 and 1024 VPLs
//!   (median and p99 per frame), the figures of the paper's §6.
//! * `laine-dispersion`: the sampling points' dispersion over the animation.
//!
//! Paper sizes (1024×768 and 1600×1200, 256 VPLs with 256² maps, 1000 frames) are the
//! defaults, for a GPU; `--quick` runs small sizes that finish on a CPU adapter. The two
//! CPU-only targets (management and dispersion) take seconds at full length and keep it with
//! `--quick`, so the files `reproduce all --quick` writes are the ones their own commands
//! write.

use gibench_harness::kit::ir::gather::{COMMON_STAGES, STAGE_VPL_SHADOW_MAPS};
use gibench_harness::kit::technique::TechniqueInfo;
use gibench_harness::measure::results::RunResult;
use gibench_harness::report::{self, Cell, Table};
use gibench_harness::run::runner::{STAGE_DIRECT_LIGHT, STAGE_DIRECT_SHADOW_MAP, STAGE_GBUFFER};
use gibench_harness::run::session::{RunSpec, TechniqueRun};
use gibench_harness::{Error, Result};

use super::{
    device_note, load_scene, ms, paper_cells, sum_ms, PaperModule, ReproduceArgs, Reproduction,
};
use crate::progress::Bars;
use gibench_harness::gpu::GpuContext;

/// The module's entry for `reproduce all`.
pub const MODULE: PaperModule = PaperModule {
    describe,
    owned_folders,
    check,
    work,
    needs_gpu: |target| !matches!(target, "laine-management" | "laine-dispersion"),
    reproduce,
    runs_folder,
    figures: |out, target| match target {
        "laine-dispersion" => vec![out.join("laine-dispersion.svg")],
        _ => Vec::new(),
    },
};

/// What each target regenerates (for `gibench reproduce all --list` and its manifest).
pub fn describe(target: &str) -> &'static str {
    match target {
        "laine-table1" => "Laine et al. 2007 Table 1: per-stage times of laine and keller-full",
        "laine-table2" => "Laine et al. 2007 Table 2: the common steps per resolution",
        "laine-tables" => "Laine et al. 2007 Tables 1 and 2 from one set of runs",
        "laine-management" => {
            "Laine et al. 2007 §6: VPL management cost on the CPU (the same sizes with and without --quick)"
        }
        "laine-dispersion" => {
            "Laine et al. 2007 §4.3: dispersion of the sampling points (the same sizes with and without --quick)"
        }
        _ => "",
    }
}

/// Subfolders of its output folder that `target` owns entirely (replaced by `reproduce all`).
pub fn owned_folders(target: &str) -> &'static [&'static str] {
    match target {
        "laine-table1" | "laine-table2" | "laine-tables" => &["runs"],
        _ => &[],
    }
}

/// The scenes `target` runs on.
fn scenes_of(target: &str, args: &ReproduceArgs) -> Vec<String> {
    match target {
        "laine-management" | "laine-dispersion" => {
            let default = if target == "laine-management" {
                "sibenik"
            } else {
                "cornell"
            };
            vec![args
                .scenes
                .first()
                .cloned()
                .unwrap_or_else(|| default.to_string())]
        }
        _ if args.scenes.is_empty() && args.tiny() => vec!["cornell".to_string()],
        _ if args.scenes.is_empty() => ["cornell", "maze", "sibenik"].map(String::from).to_vec(),
        _ => args.scenes.clone(),
    }
}

/// Checks what can be checked before any work: the scenes load, the frame counts suffice.
pub fn check(target: &str, args: &ReproduceArgs) -> Result<()> {
    if target == "laine-dispersion" {
        dispersion_frames(args)?;
    }
    if matches!(target, "laine-management" | "laine-dispersion") && args.scenes.len() > 1 {
        return Err(Error::param(
            "scenes",
            format!(
                "{target} runs on one scene (got {}: {})",
                args.scenes.len(),
                args.scenes.join(", ")
            ),
        ));
    }
    for name in scenes_of(target, args) {
        load_scene(&name, args)?;
    }
    Ok(())
}

/// The work `target` does: (frames rendered or stepped, work units: frames × pixels for
/// rendered frames, frames × VPLs for the CPU-only targets). Estimates scale with the units.
pub fn work(target: &str, args: &ReproduceArgs) -> (u64, u64) {
    match target {
        "laine-management" => {
            let frames = management_frames(args) as u64 * MANAGEMENT_PASSES as u64;
            (4 * frames, frames * 2 * (256 + 1024))
        }
        "laine-dispersion" => {
            let frames = dispersion_frames(args).unwrap_or(2) as u64;
            (4 * frames, 4 * frames * 256)
        }
        _ => {
            let s = sizes(args);
            let scenes = scenes_of(target, args).len() as u64;
            // Two techniques, timed per stage and per frame.
            let per_res = 2 * 2 * (s.frames + s.warmup) as u64 * scenes;
            s.resolutions.iter().fold((0, 0), |(f, u), r| {
                (f + per_res, u + per_res * r[0] as u64 * r[1] as u64)
            })
        }
    }
}

/// Regenerates `target` (a `laine-*` target of [`super::all::TARGETS`]) on `gpu` (opened
/// here if `None` and needed): its tables, and the runs behind them with their folder (none
/// for the CPU-only targets).
pub fn reproduce(
    target: &str,
    args: &ReproduceArgs,
    gpu: Option<&GpuContext>,
    bars: &Bars,
) -> Result<(Vec<Reproduction>, Vec<RunResult>)> {
    let runs = |pairs: &[Pair]| -> Vec<RunResult> {
        pairs
            .iter()
            .flat_map(|p| [p.2.clone(), p.3.clone()])
            .collect()
    };
    Ok(match target {
        "laine-table1" | "laine-table2" | "laine-tables" => {
            let pairs = run_pairs(args, gpu, bars)?;
            let mut tables = Vec::new();
            if target != "laine-table2" {
                tables.push((table1(&pairs)?, "laine-table1"));
            }
            if target != "laine-table1" {
                tables.push((table2(&pairs)?, "laine-table2"));
            }
            (tables, runs(&pairs))
        }
        "laine-management" => (vec![(management(args)?, "laine-management")], Vec::new()),
        "laine-dispersion" => (vec![(dispersion(args)?, "laine-dispersion")], Vec::new()),
        other => {
            return Err(Error::param(
                "target",
                format!("not a Laine 2007 target: '{other}'"),
            ))
        }
    })
}

/// The folder of the runs behind the tables.
pub fn runs_folder(args: &ReproduceArgs) -> std::path::PathBuf {
    out(args).join("runs")
}

/// The paper's published figures.
fn paper() -> Result<serde_json::Value> {
    super::paper(
        "laine2007",
        include_str!("../../../results/papers/laine2007.json"),
    )
}

struct Sizes {
    resolutions: Vec<[u32; 2]>,
    frames: u32,
    warmup: u32,
}

/// The target's sizes: the paper's, or `--quick`'s; `--frames` overrides the frame count.
fn sizes(args: &ReproduceArgs) -> Sizes {
    let mut s = if args.quick {
        Sizes {
            resolutions: vec![[256, 192], [400, 300]],
            frames: 12,
            warmup: 3,
        }
    } else {
        Sizes {
            resolutions: vec![[1024, 768], [1600, 1200]],
            frames: 1000,
            warmup: 20,
        }
    };
    if let Some(f) = args.frames {
        s.frames = f;
    }
    if args.tiny() {
        s.resolutions = vec![[64, 48], [96, 72]];
    }
    s
}

/// VPL map size per scene: the paper's 256², or quick ones.
fn map_size(scene: &str, quick: bool) -> u32 {
    match (quick, scene) {
        (false, _) => 256,
        (true, "sibenik" | "maze") => 64,
        (true, _) => 128,
    }
}

/// The paper's VPL count.
const VPLS: u32 = 256;

/// One table row's runs: (scene, resolution, `laine` result, `keller-full` result).
type Pair = (String, [u32; 2], RunResult, RunResult);

/// Runs `laine` and `keller-full` on each scene and resolution.
fn run_pairs(args: &ReproduceArgs, gpu: Option<&GpuContext>, bars: &Bars) -> Result<Vec<Pair>> {
    let s = sizes(args);
    let scenes = scenes_of("laine-tables", args);
    let laine = TechniqueInfo::find(crate::registry::all(), "laine")?;
    let keller = TechniqueInfo::find(crate::registry::all(), "keller-full")?;
    // Everything that can be checked is checked before the first frame.
    let loaded = scenes
        .iter()
        .map(|name| load_scene(name, args))
        .collect::<Result<Vec<_>>>()?;
    let mut specs = Vec::new();
    for (name, scene) in scenes.iter().zip(&loaded) {
        let size = map_size(name, args.quick).to_string();
        let vpls = VPLS.to_string();
        let gather = [
            ("vpl-map-size", size.as_str()),
            ("tiles", "4x4"),
            ("depth-bits", "16"),
        ];
        for res in &s.resolutions {
            let stem = |t: &str| format!("{}-{t}-{}x{}", scene.descriptor.name, res[0], res[1]);
            // The same VPL count for both (the paper's 256).
            let mut params = vec![("vpls", vpls.as_str())];
            params.extend(gather);
            specs.push((
                name.clone(),
                *res,
                RunSpec {
                    scene,
                    runs: vec![
                        TechniqueRun::new(laine, &params, stem(laine.name))?,
                        TechniqueRun::new(keller, &params, stem(keller.name))?,
                    ],
                    config: super::paper_config(args, *res, s.frames, s.warmup, false),
                    quality: None,
                    cache: crate::options::default_reference_cache(),
                    out: out(args).join("runs"),
                    images: false,
                },
            ));
        }
    }
    for (_, _, spec) in &specs {
        spec.validate()?;
    }
    let mut opened = None;
    let gpu = super::gpu_or_open(gpu, args, &mut opened)?;
    let mut out = Vec::new();
    for (name, res, spec) in &specs {
        let mut results = crate::progress::execute_with_bar(bars, gpu, spec)?;
        let keller = results.pop().expect("two runs");
        let laine = results.pop().expect("two runs");
        out.push((name.clone(), *res, laine, keller));
    }
    Ok(out)
}

fn table1(pairs: &[Pair]) -> Result<Table> {
    let paper = paper()?;
    let mut columns: Vec<String> = ["source", "scene", "resolution"].map(String::from).into();
    columns.extend(
        [
            "VPLs ours (mean / min)",
            "VPLs comp.",
            "direct SM+PCF",
            "G-buffer",
            "Σ common",
            "SM ours",
            "SM comp.",
            "VPL mgmt (CPU)",
            "fill frame ours",
            "FPS comp.",
            "FPS ours",
            "speedup indirect",
            "speedup frame",
        ]
        .map(String::from),
    );
    let mut rows = Vec::new();
    for (scene, res, laine, keller) in pairs {
        let direct = sum_ms(laine, &[STAGE_DIRECT_SHADOW_MAP, STAGE_DIRECT_LIGHT]);
        let fps = |r: &RunResult| r.frame.as_ref().map(|f| f.fps);
        let (fc, fo) = (fps(keller), fps(laine));
        let speedup_indirect = match (fc, fo, direct) {
            (Some(c), Some(o), Some(d)) => Some((1000.0 / c - d) / (1000.0 / o - d)),
            _ => None,
        };
        let speedup_frame = fc.zip(fo).map(|(c, o)| o / c);
        rows.push(vec![
            Cell::text("gibench"),
            Cell::text(scene),
            Cell::text(format!("{}x{}", res[0], res[1])),
            report::vpl_count_cell(laine),
            report::vpl_count_cell(keller),
            Cell::Ms(direct),
            Cell::Ms(ms(laine, STAGE_GBUFFER)),
            Cell::Ms(sum_ms(laine, &COMMON_STAGES)),
            Cell::Ms(ms(laine, STAGE_VPL_SHADOW_MAPS)),
            Cell::Ms(ms(keller, STAGE_VPL_SHADOW_MAPS)),
            Cell::Ms(ms(laine, gibench_laine::STAGE_VPL_MANAGEMENT)),
            Cell::Ms(laine.first_frame_ms),
            Cell::Num(fc, 1),
            Cell::Num(fo, 1),
            Cell::Num(speedup_indirect, 1),
            Cell::Num(speedup_frame, 1),
        ]);
        // The paper's row for the same scene, at the paper resolution in the same position.
        let name = scene.to_uppercase();
        let paper_rows = paper["table1"]["rows"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        let index = pairs
            .iter()
            .filter(|p| &p.0 == scene)
            .position(|p| p.1 == *res)
            .unwrap_or(0);
        if let Some(row) = paper_rows
            .iter()
            .filter(|r| r["scene"] == name.as_str())
            .nth(index)
        {
            let mut cells = vec![
                Cell::text("Laine et al. 2007, Table 1 (GeForce 8800 GTX)"),
                Cell::text(&name),
                Cell::text(format!("{}x{}", row["resolution"][0], row["resolution"][1])),
                Cell::text("≤ 256"),
                Cell::text("256"),
            ];
            let v = paper_cells(&row["values"]);
            cells.extend(v[..5].iter().cloned());
            cells.push(Cell::Num(None, 1));
            cells.push(Cell::Num(None, 1));
            cells.extend(v[5..].iter().cloned());
            rows.push(cells);
        }
    }
    let all: Vec<&RunResult> = pairs.iter().flat_map(|p| [&p.2, &p.3]).collect();
    let frames = all
        .first()
        .map(|r| (r.frames.measured, r.frames.warmup))
        .unwrap_or_default();
    Ok(Table {
        title: "Laine et al. 2007, Table 1: timings (ms) with the light and the camera moving".into(),
        columns,
        rows,
        notes: vec![
            format!(
                "gibench rows: medians over {} frames ({} warm-up frames dropped), stages timed with the queue flushed before \
                 and after (the paper's per-task method), FPS without added synchronisation. `laine` vs `keller-full` (the \
                 comparison method) on the same frames with the same gathering; VPL management runs on the CPU on the frame's \
                 critical path here (the paper overlapped it with GPU work). VPLs: the VPLs lighting each measured frame, \
                 mean / min, at the same `vpls` (the paper's 256): `keller-full` traces until it has that many; `laine` keeps at \
                 most that many and loses some to sampling points whose rays miss or graze the light's plane. Speedup indirect \
                 = (frame_comp − direct) / (frame_ours − direct); speedup frame = FPS ours / FPS comp. Fill frame ours: `laine`'s first frame (warm-up), \
                 which fills every slot and renders every map, as the sum of its flushed stages: the paper's start-up \
                 \"stutter\", kept out of the medians.",
                frames.0, frames.1
            ),
            format!("Paper rows: {}; {}", paper["source"].as_str().unwrap_or(""), paper["note"].as_str().unwrap_or("")),
            device_note(&all),
        ],
    })
}

fn table2(pairs: &[Pair]) -> Result<Table> {
    let paper = paper()?;
    let mut columns: Vec<String> = ["source", "scene", "resolution"].map(String::from).into();
    columns.extend(["split", "accum.", "combine", "filter", "Σ common"].map(String::from));
    let mut rows = Vec::new();
    let mut seen = Vec::new();
    for (scene, res, laine, _) in pairs {
        let mut row = vec![
            Cell::text("gibench"),
            Cell::text(scene),
            Cell::text(format!("{}x{}", res[0], res[1])),
        ];
        row.extend(COMMON_STAGES.iter().map(|s| Cell::Ms(ms(laine, s))));
        row.push(Cell::Ms(sum_ms(laine, &COMMON_STAGES)));
        rows.push(row);
        if !seen.contains(res) {
            seen.push(*res);
        }
    }
    for (i, row) in paper["table2"]["rows"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .iter()
        .enumerate()
    {
        let mut cells = vec![
            Cell::text("Laine et al. 2007, Table 2 (GeForce 8800 GTX)"),
            Cell::text("(scene-independent)"),
            Cell::text(format!("{}x{}", row["resolution"][0], row["resolution"][1])),
        ];
        cells.extend(paper_cells(&row["values"]));
        if i < seen.len() {
            rows.push(cells);
        }
    }
    let all: Vec<&RunResult> = pairs.iter().map(|p| &p.2).collect();
    Ok(Table {
        title: "Laine et al. 2007, Table 2: scene-independent common steps (ms)".into(),
        columns,
        rows,
        notes: vec![
            "gibench rows: `laine`'s stages, medians over the measured frames, flushed per stage. The paper's split and \
             combine were fragment passes over textures; gibench's are compute passes over storage buffers (see \
             docs/deviations.md)."
                .into(),
            format!("Paper rows: {}.", paper["source"].as_str().unwrap_or("")),
            device_note(&all),
        ],
    })
}

/// The scene a CPU-only target runs on (the first `--scenes` entry, else `default`) and the
/// BVH of its static geometry.
fn cpu_scene(
    args: &ReproduceArgs,
    default: &str,
) -> Result<(
    String,
    gibench_harness::scene::Scene,
    gibench_harness::cpu::bvh::SceneBvh,
)> {
    let name = args
        .scenes
        .first()
        .cloned()
        .unwrap_or_else(|| default.to_string());
    let scene = load_scene(&name, args)?;
    let bvh = gibench_harness::cpu::bvh::SceneBvh::new(&scene.mesh);
    Ok((name, scene, bvh))
}

/// The animation of `scene` with its light turned into a light of `kind` (same path).
fn clock_with_light(
    scene: &gibench_harness::scene::Scene,
    kind: gibench_harness::scene::descriptor::LightKind,
) -> gibench_harness::scene::anim::FrameClock {
    let mut d = scene.descriptor.clone();
    d.light.kind = kind;
    gibench_harness::scene::anim::FrameClock::new(&d)
}

/// VPL management cost per frame on the CPU (spot and omni, 256 and 1024 VPLs) on Sibenik's
/// animation: a CPU-only run of the `laine` manager.
fn management(args: &ReproduceArgs) -> Result<Table> {
    use gibench_harness::measure::stats::Stats;
    use gibench_harness::scene::descriptor::LightKind;
    let frames = management_frames(args);
    let (name, scene, bvh) = cpu_scene(args, "sibenik")?;
    let paper = paper()?;
    let mut rows = Vec::new();
    let mut records = serde_json::Map::new();
    // Every configuration's animation, MANAGEMENT_PASSES times, the passes taking turns: a
    // shared machine's slow minutes fall on every row alike, and the rows show how far one
    // pass's median moves from the next.
    let configs: Vec<(LightKind, u32)> = [LightKind::Spot, LightKind::Omni]
        .into_iter()
        .flat_map(|kind| [256u32, 1024].map(|vpls| (kind, vpls)))
        .collect();
    let measured = measure_management(&scene, &bvh, &configs, frames);
    for (&(kind, vpls), acc) in configs.iter().zip(&measured) {
        let used = Stats::of(&acc.used);
        let s = Stats::of(&acc.wall);
        let cpu: Option<Vec<f64>> = acc.cpu.iter().copied().collect();
        let c = cpu.as_deref().map(Stats::of);
        let passes = Stats::of(&acc.pass_medians);
        let fill = Stats::of(&acc.fill).max;
        let fill_cpu: Option<Vec<f64>> = acc.fill_cpu.iter().copied().collect();
        let (rebuilt, repaired) = (acc.rebuilt, acc.repaired);
        let timed = frames as f64 * MANAGEMENT_PASSES as f64;
        let label = format!("{kind:?}").to_lowercase();
        let parts = acc.parts.each_ref().map(|p| Stats::of(p));
        rows.push(vec![
            Cell::text("gibench"),
            Cell::text(&label),
            Cell::Num(Some(vpls as f64), 0),
            Cell::Num(Some(used.mean), 1),
            Cell::Num(Some(used.min), 0),
            Cell::Ms(Some(s.median)),
            Cell::text(format!("{:.2}–{:.2}", passes.min, passes.max)),
            Cell::Ms(c.map(|c| c.median)),
            Cell::Ms(Some(s.p99)),
            Cell::Ms(Some(s.max)),
            Cell::Ms(Some(fill)),
            Cell::Num(Some(rebuilt as f64), 0),
            Cell::Num(Some(repaired as f64 / timed), 1),
            Cell::text(
                parts
                    .iter()
                    .map(|p| format!("{:.3}", p.median))
                    .collect::<Vec<_>>()
                    .join(" / "),
            ),
        ]);
        records.insert(
            format!("{label}-{vpls}"),
            serde_json::json!({
                "wall_ms": s, "cpu_ms": c, "pass_median_wall_ms": acc.pass_medians,
                "fill_frame_wall_ms": fill, "fill_frame_wall_ms_per_pass": acc.fill,
                "fill_frame_cpu_ms_per_pass": fill_cpu,
                "vpls_used": used, "frames_rebuilt": rebuilt,
                "sites_repaired_per_frame": repaired as f64 / timed,
                "part_wall_ms": gibench_laine::StepTimes::NAMES.iter().zip(&parts)
                    .map(|(n, p)| (n.to_string(), serde_json::json!(p)))
                    .collect::<serde_json::Map<_, _>>(),
            }),
        );
        if vpls < 1024 {
            continue;
        }
        // The paper's range after each light's rows.
        let range = &paper["section6"]["vpl_management_ms"][format!("{kind:?}").to_lowercase()];
        rows.push(vec![
            Cell::text("Laine et al. 2007, §6 (Athlon 64, one core, CGAL)"),
            Cell::text(format!("{kind:?}").to_lowercase()),
            Cell::Num(Some(256.0), 0),
            Cell::Num(None, 1),
            Cell::Num(None, 0),
            Cell::text(format!("{}–{}", range[0], range[1])),
            Cell::text("–"),
            Cell::Ms(None),
            Cell::Ms(None),
            Cell::Ms(None),
            Cell::Ms(None),
            Cell::Num(None, 0),
            Cell::Num(None, 1),
            Cell::text("–"),
        ]);
    }
    let json = serde_json::json!({
        "scene": name, "frames": frames, "passes": MANAGEMENT_PASSES,
        "git_commit": gibench_harness::run::runner::git_commit(),
        "cpu_threads": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "per_frame_ms": records,
    });
    let bytes = serde_json::to_vec_pretty(&json).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::output::write_atomic(&out(args).join("laine-management.json"), &bytes)?;
    Ok(Table {
        title: format!("VPL management per frame on the CPU ({name}, {MANAGEMENT_PASSES} passes of {frames} frames, recalcMin 4, recalcMax 8)"),
        columns: ["source", "light", "VPLs", "VPLs used mean", "VPLs used min", "median ms", "pass medians ms", "median CPU ms", "p99 ms", "max ms", "fill frame ms", "frames rebuilt", "sites repaired per frame", "part medians ms: validity / update / deletion / creation / intensities"]
            .map(String::from)
            .into(),
        rows,
        notes: vec![
            format!(
                "gibench: validity rays, deletion, creation rays and Voronoi intensities of `laine`'s manager per frame \
                 after the first, over {MANAGEMENT_PASSES} passes of the animation (the rows' passes taking turns; a fresh \
                 manager each): wall time (median, p99, max over every pass's frames; pass medians: the lowest and highest \
                 of the passes' own medians) and CPU time of every thread (median; the validity and \
                 miss rays run across the machine's {} cores, as do the first frame's creation rays; the rest on one). VPLs used: the VPLs lighting each frame after the first (a \
                 sampling point whose ray misses makes none; deletions free recalcMin slots each frame). Fill frame: \
                 the first frame, which creates every VPL (wall, the slowest pass's). Frames rebuilt: frames after the first whose \
                 triangulation was built from scratch (a bulk load) instead of moving last frame's with its points \
                 (`SamplingDomain::update_sites`); sites repaired: per frame after the first on average, the sampling points whose \
                 motion broke last frame's triangulation, taken out and put back. Part medians: the wall time of each part of \
                 the step, median over the same frames (`laine::StepTimes`; the medians need not add up to the step's): \
                 validity — the paper's step 1 (§4.4), the validity rays; update — the surviving sampling points from the new \
                 light position and their triangulation moved there, the invalid ones taken out; deletion — step 2's redundant \
                 VPLs (§4.5); creation — step 3 (§4.6), sampling points at the largest empty circle and their rays; \
                 intensities — step 4 (§4.7), the Voronoi areas. The sphere is triangulated on its surface (no 3D tetrahedralisation).",
                std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
            ),
            format!("Paper: {} — a range over its test scenes, median only.", paper["source"].as_str().unwrap_or("")),
        ],
    })
}

/// Steps a fresh `laine` manager through the animation of `scene` once per configuration
/// (light kind, VPLs) and pass, [`MANAGEMENT_PASSES`] passes taking turns; returns each
/// configuration's measurements.
fn measure_management(
    scene: &gibench_harness::scene::Scene,
    bvh: &gibench_harness::cpu::bvh::SceneBvh,
    configs: &[(gibench_harness::scene::descriptor::LightKind, u32)],
    frames: u32,
) -> Vec<ManagementPasses> {
    use gibench_harness::measure::stats::Stats;
    let mut measured: Vec<ManagementPasses> = configs.iter().map(|_| Default::default()).collect();
    for _ in 0..MANAGEMENT_PASSES {
        for (&(kind, vpls), acc) in configs.iter().zip(&mut measured) {
            let clock = clock_with_light(scene, kind);
            let mut m = gibench_laine::Manager::new(vpls, 4, 8);
            // Wall and CPU time (every thread of the process: the rays run across cores) of
            // one step; then (untimed) the VPLs lighting the frame.
            let mut step = |f: u32| {
                let light = clock.frame(f).light;
                let (s, wall, cpu) =
                    gibench_harness::measure::calibrate::timed(|| m.step(scene, bvh, light));
                if f > 0 {
                    acc.used.push(m.vpls().len() as f64);
                    acc.rebuilt += s.rebuilt as u32;
                    acc.repaired += s.repaired as u64;
                    for (part, t) in acc.parts.iter_mut().zip(s.times.parts()) {
                        part.push(t.as_secs_f64() * 1e3);
                    }
                }
                (wall * 1e3, cpu.map(|c| c * 1e3))
            };
            let (fill, fill_cpu) = step(0);
            let (times, cpu): (Vec<f64>, Vec<Option<f64>>) = (1..=frames).map(&mut step).unzip();
            acc.pass_medians.push(Stats::of(&times).median);
            acc.fill.push(fill);
            acc.fill_cpu.push(fill_cpu);
            acc.wall.extend(times);
            acc.cpu.extend(cpu);
        }
    }
    measured
}

/// Dispersion of `laine`'s sampling points over the animation (Laine §4.3: the radius of the
/// largest empty circle), spot and omni, with the light moving along the scene's path and with
/// it still at frame 0's pose: a table of statistics, a JSON of every frame and an SVG plot.
fn dispersion(args: &ReproduceArgs) -> Result<Table> {
    use gibench_harness::measure::stats::Stats;
    use gibench_harness::scene::descriptor::LightKind;
    let frames = dispersion_frames(args)?;
    let (name, scene, bvh) = cpu_scene(args, "cornell")?;
    let mut lines = Vec::new();
    let mut rows = Vec::new();
    let mut records = serde_json::Map::new();
    for kind in [LightKind::Spot, LightKind::Omni] {
        let clock = clock_with_light(&scene, kind);
        for moving in [true, false] {
            let mut m = gibench_laine::Manager::new(256, 4, 8);
            let series: Vec<(f64, f64)> = (0..frames)
                .map(|f| {
                    let light = clock.frame(if moving { f } else { 0 }).light;
                    m.step(&scene, &bvh, light);
                    (f as f64, m.dispersion())
                })
                .collect();
            let label = format!(
                "{} light, {}",
                format!("{kind:?}").to_lowercase(),
                if moving { "moving" } else { "still" }
            );
            let values: Vec<f64> = series.iter().skip(1).map(|p| p.1).collect();
            let st = Stats::of(&values);
            rows.push(vec![
                Cell::text(&label),
                Cell::Num(Some(series[0].1), 4),
                Cell::Num(Some(st.median), 4),
                Cell::Num(Some(st.max), 4),
                Cell::Num(series.last().map(|p| p.1), 4),
            ]);
            records.insert(label.clone(), serde_json::json!(values));
            lines.push((label, series));
        }
    }
    let json = serde_json::json!({
        "scene": name, "frames": frames, "vpls": 256, "recalc_min": 4, "recalc_max": 8,
        "git_commit": gibench_harness::run::runner::git_commit(), "dispersion_per_frame_after_the_first": records,
    });
    let bytes = serde_json::to_vec_pretty(&json).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::output::write_atomic(&out(args).join("laine-dispersion.json"), &bytes)?;
    report::lines_svg(
        &lines,
        &out(args).join("laine-dispersion.svg"),
        &format!("Dispersion of laine's sampling points on {name} (256 VPLs)"),
        "frame",
        "dispersion (largest empty circle radius)",
    )?;
    Ok(Table {
        title: format!("Dispersion of the sampling points ({name}, {frames} frames, 256 VPLs, recalcMin 4, recalcMax 8)"),
        columns: ["light", "after frame 0", "median", "max", "last frame"].map(String::from).into(),
        rows,
        notes: vec![
            "Dispersion is the radius of the largest empty circle among the sampling points (unit disc for spot lights, \
             chordal on the unit sphere for omni lights; Laine et al. 2007 §4.3). Frame 0 fills every slot; a still \
             light keeps the first frame's pose."
                .into(),
        ],
    })
}

/// Passes of the management table's animation per row.
const MANAGEMENT_PASSES: usize = 3;

/// One management row's measurements over its passes.
#[derive(Default)]
struct ManagementPasses {
    wall: Vec<f64>,
    cpu: Vec<Option<f64>>,
    pass_medians: Vec<f64>,
    fill: Vec<f64>,
    fill_cpu: Vec<Option<f64>>,
    used: Vec<f64>,
    rebuilt: u32,
    repaired: u64,
    /// Per part of the step ([`gibench_laine::StepTimes::NAMES`]), its wall time per frame.
    parts: [Vec<f64>; 5],
}

/// Frames of the management table (CPU only, seconds: `--quick` keeps them).
fn management_frames(args: &ReproduceArgs) -> u32 {
    args.frames.unwrap_or(1000)
}

/// Frames of the dispersion table (at least two: the median and maximum are over the frames
/// after the fill frame; CPU only, about a second: `--quick` keeps them).
fn dispersion_frames(args: &ReproduceArgs) -> Result<u32> {
    let frames = args.frames.unwrap_or(600);
    if frames < 2 {
        return Err(Error::param(
            "frames",
            format!("the dispersion table needs at least 2 frames: frame 0 and one after it (got {frames})"),
        ));
    }
    Ok(frames)
}

/// Where this paper's files go.
fn out(args: &ReproduceArgs) -> std::path::PathBuf {
    super::out_dir(args, "laine")
}
