//! Barczak 2006, "Interactive Illumination Using Large Sets of Point Lights" (M.S. thesis):
//! its performance Figures 5-2 to 5-6 regenerated through the typed run API. Our copy of the
//! thesis has the figures' captions and the text about them but not their data, so each figure
//! is regenerated from our runs with a table of the numbers behind it, and its notes set what the
//! thesis says the figure shows (`results/papers/barczak2006.json`) beside what ours shows,
//! computed from our numbers.
//!
//! One target, `barczak2006`, three sets of runs:
//!
//! * **Figure 5-2** — frame rate against the light count, static views of the three rooms
//!   (`barczak-area`, `barczak-table` and `barczak-pillars` with their movers held at the first
//!   frame), level Full, indirect light samples.
//! * **Figure 5-3** — the same sweep on the area-light room at each optimisation level (Full,
//!   VD+LP, VD, Naive), for the indirect and the direct light samples; the Full/Naive ratio at
//!   the largest light count is printed.
//! * **Figures 5-4, 5-5, 5-6** — from one set of runs: the mover following its path, the frame
//!   rate, the shadow-map time and the fraction of the frame spent on updates (visibility
//!   determination and shadow maps) against the shadow maps re-rendered per frame, for the
//!   thesis' four cases — the bunny and the torus, each in the table room and in the pillar room
//!   (the two rooms as built carry the bunny and the torus; the other two cases swap the movers,
//!   keeping the room's path: the bunny walks the pillar room's circle on the floor, the torus,
//!   at 0.6 scale, the table's loop on the table top) — with each case's static view as the
//!   reference.
//!
//! Paper sizes (the thesis: 1024×768, up to 300 lights, 200 frames per case) are the default, for
//! a GPU; `--quick` runs 256×192, 25/100/300 lights, 100 lights for the update cases and a few
//! frames.

use std::path::{Path, PathBuf};

use gibench_barczak::{STAGES, STAGE_SHADOW_MAPS, STAGE_VISIBILITY};
use gibench_harness::gpu::GpuContext;
use gibench_harness::quality::{IndirectComponent, QualityConfig};
use gibench_harness::reference::ReferenceSettings;
use gibench_harness::report::{self, Cell, Table};
use gibench_harness::results::RunResult;
use gibench_harness::scene::{Scene, SceneDescriptor};
use gibench_harness::session::{RunSpec, TechniqueRun};
use gibench_harness::technique::TechniqueInfo;
use gibench_harness::{Error, Result};

use super::{device_note, ms, sum_ms, PaperModule, ReproduceArgs, Reproduced};
use crate::cli::progress::Bars;

/// The module's entry for `reproduce all`.
pub const MODULE: PaperModule = PaperModule {
    describe,
    owned_folders: |_| &["runs"],
    check,
    work,
    needs_gpu: |_| true,
    reproduce,
    runs_folder,
    figures: |out, _| FIGURES.iter().map(|(f, _)| out.join(f)).collect(),
};

/// The figures' files and the tables' stems, in the thesis' order.
const FIGURES: [(&str, &str); 5] = [
    ("barczak-fig5-2.svg", "barczak-fig5-2"),
    ("barczak-fig5-3.svg", "barczak-fig5-3"),
    ("barczak-fig5-4.svg", "barczak-fig5-4"),
    ("barczak-fig5-5.svg", "barczak-fig5-5"),
    ("barczak-fig5-6.svg", "barczak-fig5-6"),
];

/// What the target regenerates.
pub fn describe(_: &str) -> &'static str {
    "Barczak 2006 Figures 5-2 to 5-6: frame rate against lights (three rooms; four optimisation levels), and against shadow-map updates per frame with moving objects (frame rate, shadow-map time, fraction in updates), plots and tables"
}

/// The thesis' settings and what it says of each figure.
fn paper() -> Result<serde_json::Value> {
    super::paper(
        "barczak2006",
        include_str!("../../../results/papers/barczak2006.json"),
    )
}

/// The sizes of a run set.
struct Sizes {
    resolution: [u32; 2],
    frames: u32,
    warmup: u32,
    /// Light counts of Figures 5-2 and 5-3.
    lights: Vec<u32>,
    /// Lights of the update cases.
    update_lights: u32,
    /// Shadow maps re-rendered per frame, Figures 5-4 to 5-6.
    updates: Vec<u32>,
    /// Measured frames of the update cases.
    update_frames: u32,
}

fn sizes(args: &ReproduceArgs) -> Sizes {
    let s = if args.quick {
        Sizes {
            resolution: [256, 192],
            frames: 4,
            warmup: 3,
            lights: vec![25, 100, 300],
            update_lights: 100,
            updates: vec![10, 25, 50, 100],
            update_frames: 12,
        }
    } else {
        Sizes {
            resolution: [1024, 768],
            frames: 100,
            warmup: 10,
            lights: vec![25, 50, 100, 150, 200, 250, 300],
            update_lights: 300,
            updates: vec![25, 50, 100, 150, 200, 300],
            update_frames: 200,
        }
    };
    Sizes {
        frames: args.frames.unwrap_or(s.frames),
        update_frames: args.frames.unwrap_or(s.update_frames),
        ..s
    }
}

const ROOMS: [&str; 3] = ["barczak-area", "barczak-table", "barczak-pillars"];

/// A Figure 5-4 case: its name, the room, and the mover from which room.
const CASES: [(&str, &str, &str); 4] = [
    ("bunny-table", "barczak-table", "barczak-table"),
    ("torus-table", "barczak-table", "barczak-pillars"),
    ("bunny-pillars", "barczak-pillars", "barczak-table"),
    ("torus-pillars", "barczak-pillars", "barczak-pillars"),
];

fn check_target(target: &str) -> Result<()> {
    if target != "barczak2006" {
        return Err(Error::param(
            "target",
            format!("not a Barczak 2006 target: '{target}'"),
        ));
    }
    Ok(())
}

/// `room` with its movers held at their first key (a static view).
fn still(mut desc: SceneDescriptor) -> SceneDescriptor {
    for m in &mut desc.movers {
        m.path.keys.truncate(1);
    }
    if !desc.movers.is_empty() {
        desc.name = format!("{}-static", desc.name);
    }
    desc
}

/// Case `name`: `room` with the mover of `from`, following `room`'s path (see the module
/// docs).
fn case(name: &str, room: &str, from: &str) -> Result<SceneDescriptor> {
    let mut desc = SceneDescriptor::resolve(room)?;
    if room != from {
        let mut mover = SceneDescriptor::resolve(from)?.movers[0].clone();
        let path = desc.movers[0].path.clone();
        mover.path = path;
        let torus = mover.mesh.generated.is_some();
        if torus {
            // The torus (0.1 m tube) at 0.6 scale on the table top (0.9 m) instead of the bunny.
            mover.scale = 0.6;
            for k in &mut mover.path.keys {
                k.position[1] = 0.9 + 0.1 * 0.6 + 0.002;
            }
        } else {
            // The bunny on the floor below the torus' circle.
            for k in &mut mover.path.keys {
                k.position[1] = 0.0;
            }
        }
        desc.movers = vec![mover];
    }
    desc.name = format!("barczak-{name}");
    Ok(desc)
}

/// Every scene of the target with its run set: (descriptor, which figure set).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Set {
    /// Figure 5-2 (and 5-3 on the area room).
    Lights,
    /// Figures 5-4 to 5-6, moving.
    Updates,
    /// Figures 5-4 to 5-6, the static reference.
    UpdatesStatic,
    /// The quality of a light-sample set against its reference component.
    Quality(&'static str),
}

fn descriptors() -> Result<Vec<(SceneDescriptor, Set)>> {
    let mut out = Vec::new();
    for room in ROOMS {
        out.push((still(SceneDescriptor::resolve(room)?), Set::Lights));
    }
    for (name, room, from) in CASES {
        let d = case(name, room, from)?;
        out.push((still(d.clone()), Set::UpdatesStatic));
        out.push((d, Set::Updates));
    }
    for set in ["indirect", "direct"] {
        out.push((SceneDescriptor::resolve("barczak-area")?, Set::Quality(set)));
    }
    Ok(out)
}

fn params_of(lights: u32, set: &str, level: &str, updates: u32) -> Vec<(String, String)> {
    vec![
        ("vpls".into(), lights.to_string()),
        ("set".into(), set.into()),
        ("level".into(), level.into()),
        ("updates".into(), updates.to_string()),
    ]
}

/// The runs of one scene.
fn spec<'s>(args: &ReproduceArgs, scene: &'s Scene, set: Set) -> Result<RunSpec<'s>> {
    let info = TechniqueInfo::find(crate::registry::all(), "barczak")?;
    let s = sizes(args);
    let name = &scene.descriptor.name;
    let mut runs = Vec::new();
    let mut add = |p: Vec<(String, String)>, stem: String| -> Result<()> {
        let pairs: Vec<(&str, &str)> = p.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect();
        runs.push(TechniqueRun::new(info, &pairs, stem)?);
        Ok(())
    };
    match set {
        Set::Lights => {
            let levels: &[&str] = if name == "barczak-area" {
                &["full", "vd-lp", "vd", "naive"]
            } else {
                &["full"]
            };
            let sets: &[&str] = if name == "barczak-area" {
                &["indirect", "direct"]
            } else {
                &["indirect"]
            };
            for light_set in sets {
                for level in levels {
                    for &n in &s.lights {
                        add(
                            params_of(n, light_set, level, n),
                            format!("{name}-{light_set}-{level}-{n}"),
                        )?;
                    }
                }
            }
        }
        Set::UpdatesStatic => add(
            params_of(s.update_lights, "indirect", "full", 0),
            format!("{name}-{}", s.update_lights),
        )?,
        Set::Quality(light_set) => add(
            params_of(s.update_lights, light_set, "full", 0),
            format!("{name}-quality-{light_set}-{}", s.update_lights),
        )?,
        Set::Updates => {
            for &u in &s.updates {
                add(
                    params_of(s.update_lights, "indirect", "full", u),
                    format!("{name}-{}-updates-{u}", s.update_lights),
                )?;
            }
            // The most updates again without face culling (§4.2.2), for its effect.
            if let Some(&u) = s.updates.last() {
                let mut p = params_of(s.update_lights, "indirect", "full", u);
                p.push(("face-cull".into(), "off".into()));
                add(p, format!("{name}-{}-updates-{u}-no-cull", s.update_lights))?;
            }
        }
    }
    let frames = match set {
        Set::Lights => s.frames,
        Set::Quality(_) => 2,
        _ => s.update_frames,
    };
    let quality = match set {
        Set::Quality(light_set) => Some(QualityConfig {
            pairs: 1,
            all: false,
            reference: ReferenceSettings::default(),
            component: Some(if light_set == "direct" {
                IndirectComponent::Direct
            } else {
                IndirectComponent::MultiBounce
            }),
        }),
        _ => None,
    };
    Ok(RunSpec {
        scene,
        runs,
        config: super::paper_config(args, s.resolution, frames, s.warmup, quality.is_some()),
        // The quality runs at the size the reference affords (as every quality target).
        quality,
        cache: Default::default(),
        out: runs_folder(args),
        images: false,
    })
}

fn load(desc: &SceneDescriptor, args: &ReproduceArgs) -> Result<Scene> {
    Scene::load(
        desc,
        &gibench_harness::assets::AssetPaths::standard(args.assets.as_deref()),
    )
}

/// Checks what can be checked before any work: the target, the scenes, the runs' settings.
pub fn check(target: &str, args: &ReproduceArgs) -> Result<()> {
    check_target(target)?;
    if !args.scenes.is_empty() {
        return Err(Error::param(
            "scenes",
            "barczak2006 runs the thesis' rooms and cases; it takes no --scenes",
        ));
    }
    for (desc, set) in descriptors()? {
        let scene = load(&desc, args)?;
        spec(args, &scene, set)?.validate()?;
    }
    Ok(())
}

/// (frames rendered, frames × pixels).
pub fn work(_: &str, args: &ReproduceArgs) -> (u64, u64) {
    let s = sizes(args);
    let per = |frames: u32| 2 * (frames + s.warmup) as u64;
    let lights = s.lights.len() as u64;
    // Area room: 4 levels × 2 sets; the other rooms: Full, indirect.
    let f = (8 + 2) * lights * per(s.frames)
        + CASES.len() as u64 * (2 + s.updates.len() as u64) * per(s.update_frames)
        + 2 * (2 + s.warmup) as u64;
    (f, f * s.resolution[0] as u64 * s.resolution[1] as u64)
}

/// The folder of the runs behind the tables.
pub fn runs_folder(args: &ReproduceArgs) -> PathBuf {
    super::out_dir(args, "barczak2006").join("runs")
}

/// Runs the target and builds its five tables and figures.
pub fn reproduce(
    target: &str,
    args: &ReproduceArgs,
    gpu: Option<&GpuContext>,
    bars: &Bars,
) -> Reproduced {
    check_target(target)?;
    let descs = descriptors()?;
    let scenes = descs
        .iter()
        .map(|(d, _)| load(d, args))
        .collect::<Result<Vec<_>>>()?;
    let specs = scenes
        .iter()
        .zip(&descs)
        .map(|(scene, (_, set))| spec(args, scene, *set))
        .collect::<Result<Vec<_>>>()?;
    let runs = super::run_specs(&specs, args, gpu, bars)?;
    let out = super::out_dir(args, "barczak2006");
    let movers: Vec<(String, usize)> = scenes
        .iter()
        .filter_map(|s| {
            s.movers
                .first()
                .map(|m| (s.descriptor.name.clone(), m.mesh.positions.len()))
        })
        .collect();
    let paper = paper()?;
    let tables = vec![
        (fig5_2(&out, &runs, &paper)?, FIGURES[0].1),
        (fig5_3(&out, &runs, &paper)?, FIGURES[1].1),
        (fig5_4(&out, &runs, &paper)?, FIGURES[2].1),
        (fig5_5(&out, &runs, &paper, &movers)?, FIGURES[3].1),
        (fig5_6(&out, &runs, &paper)?, FIGURES[4].1),
        (quality_table(&runs)?, "barczak-quality"),
    ];
    Ok((tables, runs))
}

fn param<'r>(r: &'r RunResult, name: &str) -> Option<&'r str> {
    r.parameters.get(name).and_then(|v| v.as_str())
}

fn int_param(r: &RunResult, name: &str) -> Option<f64> {
    r.parameters.get(name).and_then(|v| v.as_f64())
}

fn frame_ms(r: &RunResult) -> Option<f64> {
    r.frame.as_ref().map(|f| f.frame_ms.median)
}

fn fps(r: &RunResult) -> Option<f64> {
    frame_ms(r).map(|m| 1000.0 / m)
}

fn counter(r: &RunResult, name: &str) -> Option<f64> {
    r.counters.get(name).map(|s| s.mean)
}

/// The thesis' words on figure `key`, and its setting.
fn thesis(paper: &serde_json::Value, key: &str) -> String {
    format!(
        "The thesis ({}, {}, {}, {}): \"{}\" — {}",
        paper["hardware"].as_str().unwrap_or("?"),
        paper["resolution"].as_str().unwrap_or("?"),
        paper["api"].as_str().unwrap_or("?"),
        paper["year"],
        paper["figures"][key]["caption"].as_str().unwrap_or("?"),
        paper["figures"][key]["shows"].as_str().unwrap_or("?"),
    )
}

fn timing_note(runs: &[&RunResult]) -> String {
    let (frames, warmup, res) = runs
        .first()
        .map(|r| (r.frames.measured, r.frames.warmup, r.resolution))
        .unwrap_or_default();
    format!(
        "gibench: `barczak` at {}x{}, {} measured frames after {} warm-up frames (the first frame, which renders every shadow map, is the warm-up's); \
         frame: median time between frame starts without added synchronisation (FPS = 1000 / it); stages: medians with the queue flushed \
         before and after each. Light draws: mean per frame, the low-resolution pass counting its two renderings.",
        res[0], res[1], frames, warmup
    )
}

/// Least-squares line y = a + b x and its R².
fn fit(points: &[(f64, f64)]) -> Option<(f64, f64, f64)> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mx, my) = (sx / n, sy / n);
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let b = sxy / sxx;
    let r2 = if syy == 0.0 {
        1.0
    } else {
        sxy * sxy / (sxx * syy)
    };
    Some((my - b * mx, b, r2))
}

fn lights_runs<'r>(
    runs: &'r [RunResult],
    scene: &str,
    set: &str,
    level: &str,
) -> Vec<&'r RunResult> {
    let mut v: Vec<&RunResult> = runs
        .iter()
        .filter(|r| {
            r.quality.is_none()
                && r.scene == scene
                && param(r, "set") == Some(set)
                && param(r, "level") == Some(level)
        })
        .collect();
    v.sort_by(|a, b| {
        int_param(a, "vpls")
            .unwrap_or(0.0)
            .total_cmp(&int_param(b, "vpls").unwrap_or(0.0))
    });
    v
}

fn svg(
    out: &Path,
    file: &str,
    lines: Vec<(String, Vec<(f64, f64)>)>,
    title: &str,
    x: &str,
    y: &str,
) -> Result<()> {
    report::lines_svg(&lines, &out.join(file), title, x, y)
}

fn fig5_2(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut shows = Vec::new();
    let mut all = Vec::new();
    for room in ROOMS {
        let scene = still_name(room);
        let rs = lights_runs(runs, &scene, "indirect", "full");
        let mut points = Vec::new();
        for r in &rs {
            rows.push(vec![
                Cell::text(&r.scene),
                Cell::Num(int_param(r, "vpls"), 0),
                Cell::Ms(frame_ms(r)),
                Cell::Num(fps(r), 1),
                Cell::Ms(sum_ms(r, &present(r))),
                Cell::Num(counter(r, "light-draws"), 0),
            ]);
            if let (Some(n), Some(m)) = (int_param(r, "vpls"), frame_ms(r)) {
                points.push((n, m));
            }
            all.push(*r);
        }
        if let Some((a, b, r2)) = fit(&points) {
            shows.push(format!(
                "{scene}: frame time ≈ {a:.1} ms + {b:.3} ms per light (R² = {r2:.3})"
            ));
        }
        lines.push((
            scene.clone(),
            points.iter().map(|(n, m)| (*n, 1000.0 / m)).collect(),
        ));
    }
    svg(
        out,
        FIGURES[0].0,
        lines,
        "Figure 5-2: frame rate against lights, static views (barczak, Full)",
        "light samples",
        "frames per second",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-2: rendering performance for fixed views of each test scene"
            .into(),
        columns: cols(&["scene", "lights", "frame", "FPS", "Σ stages", "light draws"]),
        rows,
        notes: vec![
            thesis(paper, "5-2"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "{} Level Full, indirect light samples (5 bounces), movers held at their first pose.",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// The static view's scene name of `room`.
fn still_name(room: &str) -> String {
    if room == "barczak-area" {
        room.to_string()
    } else {
        format!("{room}-static")
    }
}

/// The stages `r` has (the low-resolution ones only at its levels).
fn present(r: &RunResult) -> Vec<&'static str> {
    STAGES
        .iter()
        .copied()
        .filter(|s| r.stage(s).is_some())
        .collect()
}

fn cols(names: &[&str]) -> Vec<String> {
    names.iter().map(|s| s.to_string()).collect()
}

fn fig5_3(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut shows = Vec::new();
    let mut all = Vec::new();
    for set in ["indirect", "direct"] {
        let mut at_max = Vec::new();
        for level in ["full", "vd-lp", "vd", "naive"] {
            let rs = lights_runs(runs, "barczak-area", set, level);
            let mut points = Vec::new();
            for r in &rs {
                rows.push(vec![
                    Cell::text(set),
                    Cell::text(level),
                    Cell::Num(int_param(r, "vpls"), 0),
                    Cell::Ms(frame_ms(r)),
                    Cell::Num(fps(r), 1),
                    Cell::Num(counter(r, "light-draws"), 0),
                    Cell::Num(counter(r, "elements"), 0),
                ]);
                if let (Some(n), Some(f)) = (int_param(r, "vpls"), fps(r)) {
                    points.push((n, f));
                }
                all.push(*r);
            }
            if let Some(r) = rs.last() {
                at_max.push((level, int_param(r, "vpls"), frame_ms(r)));
            }
            lines.push((format!("{level} ({set})"), points));
        }
        let get = |l: &str| at_max.iter().find(|(n, _, _)| *n == l).and_then(|x| x.2);
        if let (Some(full), Some(naive)) = (get("full"), get("naive")) {
            let n = at_max.first().and_then(|x| x.1).unwrap_or(0.0);
            let ratio = naive / full;
            let line = format!(
                "{set} samples at {n:.0} lights: Full {full:.1} ms, Naive {naive:.1} ms per frame — Full is {ratio:.2}x {} than Naive",
                if ratio >= 1.0 { "faster" } else { "slower" }
            );
            println!("barczak2006: {line}");
            let mut order: Vec<(&str, f64)> = at_max
                .iter()
                .filter_map(|(l, _, m)| m.map(|m| (*l, m)))
                .collect();
            order.sort_by(|a, b| a.1.total_cmp(&b.1));
            shows.push(format!(
                "{line}; fastest to slowest: {}",
                order
                    .iter()
                    .map(|(l, m)| format!("{l} {m:.1} ms"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    svg(
        out,
        FIGURES[1].0,
        lines,
        "Figure 5-3: frame rate against lights per optimisation level, area-light room",
        "light samples",
        "frames per second",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-3: effect of each optimisation on rendering performance (area-light room)".into(),
        columns: cols(&["samples", "level", "lights", "frame", "FPS", "light draws", "elements"]),
        rows,
        notes: vec![
            thesis(paper, "5-3"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "{} full: light maps minus the occluded partial lights, drawn at low resolution (factor 2, edges redrawn), elements merged by the pass optimiser (K = 7 lights per draw); \
                 vd-lp: visibility determination and the low-resolution pass; vd: visibility determination at full resolution; naive: every light with a shadow-map lookup on every patch. \
                 indirect: random-walk samples (5 bounces); direct: points on the area light (the thesis' room has two area lights, ours one).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// The update runs of a case, sorted by updates, and its static run.
/// Whether run `r` drew its shadow maps without face culling (`face-cull=off`).
fn unculled(r: &RunResult) -> bool {
    r.parameters.get("face-cull").and_then(|v| v.as_str()) == Some("off")
}

/// Case `case`'s run without face culling, if any.
fn unculled_run<'r>(runs: &'r [RunResult], case: &str) -> Option<&'r RunResult> {
    let scene = format!("barczak-{case}");
    runs.iter().find(|r| r.scene == scene && unculled(r))
}

/// Case `case`'s moving runs with face culling (by updates) and its static view.
fn case_runs<'r>(runs: &'r [RunResult], case: &str) -> (Vec<&'r RunResult>, Option<&'r RunResult>) {
    let scene = format!("barczak-{case}");
    let mut moving: Vec<&RunResult> = (runs.iter())
        .filter(|r| r.scene == scene && !unculled(r))
        .collect();
    moving.sort_by(|a, b| {
        int_param(a, "updates")
            .unwrap_or(0.0)
            .total_cmp(&int_param(b, "updates").unwrap_or(0.0))
    });
    let still = runs.iter().find(|r| r.scene == format!("{scene}-static"));
    (moving, still)
}

fn fig5_4(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut shows = Vec::new();
    let mut all = Vec::new();
    for (name, _, _) in CASES {
        let (moving, still) = case_runs(runs, name);
        if let Some(s) = still {
            rows.push(vec![
                Cell::text(name),
                Cell::text("static"),
                Cell::Num(int_param(s, "vpls"), 0),
                Cell::Ms(frame_ms(s)),
                Cell::Num(fps(s), 1),
                Cell::Num(counter(s, "maps-rendered"), 1),
                Cell::Num(faces_per_map(s), 2),
                Cell::Num(counter(s, "light-map-changes"), 1),
            ]);
            all.push(s);
        }
        let mut points = Vec::new();
        for r in &moving {
            rows.push(vec![
                Cell::text(name),
                Cell::Num(int_param(r, "updates"), 0),
                Cell::Num(int_param(r, "vpls"), 0),
                Cell::Ms(frame_ms(r)),
                Cell::Num(fps(r), 1),
                Cell::Num(counter(r, "maps-rendered"), 1),
                Cell::Num(faces_per_map(r), 2),
                Cell::Num(counter(r, "light-map-changes"), 1),
            ]);
            if let (Some(u), Some(f)) = (int_param(r, "updates"), fps(r)) {
                points.push((u, f));
            }
            all.push(*r);
        }
        if let (Some(s), Some(last)) = (still.and_then(fps), points.last()) {
            let faces = moving.last().and_then(|r| faces_per_map(r));
            shows.push(format!(
                "{name}: {s:.1} FPS static, {:.1} FPS at {:.0} updates per frame ({:.0} % of static), {} octahedral faces drawn per map",
                last.1,
                last.0,
                100.0 * last.1 / s,
                faces.map_or("–".to_string(), |f| format!("{f:.2}"))
            ));
            let (x0, x1) = (points[0].0, last.0);
            lines.push((format!("{name} static"), vec![(x0, s), (x1, s)]));
        }
        lines.push((name.to_string(), points));
    }
    svg(
        out,
        FIGURES[2].0,
        lines,
        "Figure 5-4: frame rate against shadow-map updates per frame, moving objects",
        "shadow maps updated per frame",
        "frames per second",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-4: rendering performance in dynamic scenes against visibility updates per frame".into(),
        columns: cols(&["case", "updates", "lights", "frame", "FPS", "maps rendered", "faces per map", "light-map changes"]),
        rows,
        notes: vec![
            thesis(paper, "5-4"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "{} The mover follows its path (the thesis: a fixed path, 200 frames, fixed camera); updates: the shadow maps re-rendered per frame at \
                 most, brightest and longest out of date first; maps rendered: the mean actually rendered (only out-of-date maps are); faces per map: the octahedral faces drawn into per map rendered, of \
                 four (§4.2.2: a face holding no shadow caster is not drawn; the room's shell casts none). Level Full, \
                 indirect samples. Cases: the rooms as built (bunny on the table, torus among the pillars) and swapped (the torus at 0.6 scale on the \
                 table's loop, the bunny on the floor under the pillar room's circle).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// Octahedral faces drawn into per shadow map rendered (`map-faces` / `maps-rendered`).
fn faces_per_map(r: &RunResult) -> Option<f64> {
    let maps = counter(r, "maps-rendered")?;
    (maps > 0.0).then(|| counter(r, "map-faces").map(|f| f / maps))?
}

fn fig5_5(
    out: &Path,
    runs: &[RunResult],
    paper: &serde_json::Value,
    movers: &[(String, usize)],
) -> Result<Table> {
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    let mut all = Vec::new();
    let mut at_max = Vec::new();
    let mut culling = Vec::new();
    for (name, _, _) in CASES {
        let (moving, _) = case_runs(runs, name);
        let vertices = movers
            .iter()
            .find(|(s, _)| *s == format!("barczak-{name}"))
            .map(|m| m.1 as f64);
        let mut points = Vec::new();
        for r in &moving {
            let sm = ms(r, STAGE_SHADOW_MAPS);
            let maps = counter(r, "maps-rendered");
            rows.push(vec![
                Cell::text(name),
                Cell::Num(vertices, 0),
                Cell::Num(int_param(r, "updates"), 0),
                Cell::Num(maps, 1),
                Cell::Ms(sm),
                Cell::Ms(sm.zip(maps).map(|(t, m)| t / m.max(1.0))),
            ]);
            if let (Some(u), Some(t)) = (int_param(r, "updates"), sm) {
                points.push((u, t));
            }
            all.push(*r);
        }
        if let (Some(last), Some(v)) = (
            moving.last().and_then(|r| ms(r, STAGE_SHADOW_MAPS)),
            vertices,
        ) {
            at_max.push((name, v, last));
        }
        let per_map = |r: &RunResult| {
            let maps = counter(r, "maps-rendered").filter(|m| *m > 0.0)?;
            Some(ms(r, STAGE_SHADOW_MAPS)? / maps)
        };
        if let (Some(off), Some(on)) = (
            unculled_run(runs, name).and_then(per_map),
            moving.last().and_then(|r| per_map(r)),
        ) {
            culling.push(format!(
                "{name} {on:.2} ms per map with face culling against {off:.2} without ({:.2}x)",
                off / on
            ));
        }
        lines.push((name.to_string(), points));
    }
    let mut shows = Vec::new();
    for room in ["table", "pillars"] {
        let get = |m: &str| at_max.iter().find(|c| c.0 == format!("{m}-{room}"));
        if let (Some(b), Some(t)) = (get("bunny"), get("torus")) {
            shows.push(format!(
                "in the {room} room, bunny/torus shadow-map time {:.2} at the most updates against a vertex ratio of {:.2}",
                b.2 / t.2,
                b.1 / t.1
            ));
        }
    }
    svg(
        out,
        FIGURES[3].0,
        lines,
        "Figure 5-5: shadow-map rendering time against updates per frame",
        "shadow maps updated per frame",
        "shadow-map stage (ms)",
    )?;
    Ok(Table {
        title: "Barczak 2006, Figure 5-5: shadow-map rendering times for each test case".into(),
        columns: cols(&["case", "mover vertices", "updates", "maps rendered", "shadow maps", "per map"]),
        rows,
        notes: vec![
            thesis(paper, "5-5"),
            format!("Ours shows: {}.", shows.join("; ")),
            format!(
                "Face culling (§4.2.2) at the most updates, the same case run again with face-cull=off: {}.",
                culling.join("; ")
            ),
            format!(
                "{} Shadow maps: the stage rendering the out-of-date octahedral maps, each only into the faces that hold a shadow caster \
                 (§4.2.2), the room's casters (not its shell) and the mover in each (the kit's atlas rasteriser; the thesis re-rendered the \
                 occluders of each map).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

fn fig5_6(out: &Path, runs: &[RunResult], paper: &serde_json::Value) -> Result<Table> {
    let (moving, _) = case_runs(runs, "bunny-pillars");
    let mut rows = Vec::new();
    let (mut vis, mut maps) = (Vec::new(), Vec::new());
    for r in &moving {
        let total = sum_ms(r, &present(r));
        let v = ms(r, STAGE_VISIBILITY);
        let s = ms(r, STAGE_SHADOW_MAPS);
        let frac = |x: Option<f64>| x.zip(total).map(|(x, t)| x / t);
        rows.push(vec![
            Cell::Num(int_param(r, "updates"), 0),
            Cell::Ms(v),
            Cell::Ms(s),
            Cell::Ms(total),
            Cell::Num(frac(v).map(|f| 100.0 * f), 1),
            Cell::Num(frac(s).map(|f| 100.0 * f), 1),
            Cell::Num(frac(v.zip(s).map(|(a, b)| a + b)).map(|f| 100.0 * f), 1),
        ]);
        if let Some(u) = int_param(r, "updates") {
            if let Some(f) = frac(v) {
                vis.push((u, 100.0 * f));
            }
            if let Some(f) = frac(s) {
                maps.push((u, 100.0 * f));
            }
        }
    }
    let shows = match (maps.first(), maps.last(), vis.first(), vis.last()) {
        (Some(m0), Some(m1), Some(v0), Some(v1)) => format!(
            "shadow maps take {:.0} % of the frame at {:.0} updates and {:.0} % at {:.0}; visibility determination {:.1} % and {:.1} %",
            m0.1, m0.0, m1.1, m1.0, v0.1, v1.1
        ),
        _ => "no runs".into(),
    };
    svg(
        out,
        FIGURES[4].0,
        vec![
            ("shadow maps (% of Σ stages)".into(), maps),
            ("visibility determination (% of Σ stages)".into(), vis),
        ],
        "Figure 5-6: fraction of the frame in updates, bunny in the pillar room",
        "shadow maps updated per frame",
        "% of the frame",
    )?;
    let all: Vec<&RunResult> = moving.to_vec();
    Ok(Table {
        title: "Barczak 2006, Figure 5-6: fraction of rendering time taken by visibility updates (bunny, pillar room)".into(),
        columns: cols(&["updates", "visibility", "shadow maps", "Σ stages", "visibility %", "shadow maps %", "updates %"]),
        rows,
        notes: vec![
            thesis(paper, "5-6"),
            format!("Ours shows: {shows}."),
            format!(
                "{} Visibility: the CPU stage moving the mover in the visibility database (Table 4-1), updating light maps and planning the draws; \
                 shadow maps: the GPU stage; both as fractions of the sum of every stage of the frame (G-buffer, direct light and compose included).",
                timing_note(&all)
            ),
            device_note(&all),
        ],
    })
}

/// Each light-sample set against its reference component (§4.1's two sets; the quality
/// check): the indirect samples against the multi-bounce reference, the direct ones against the
/// reference's direct light (soft shadows).
fn quality_table(runs: &[RunResult]) -> Result<Table> {
    let mut rows = Vec::new();
    let mut all = Vec::new();
    for r in runs.iter().filter(|r| r.quality.is_some()) {
        let q = r.quality.as_ref().expect("filtered");
        rows.push(vec![
            Cell::text(param(r, "set").unwrap_or("?")),
            Cell::text(&q.reference),
            Cell::Num(int_param(r, "vpls"), 0),
            Cell::Num(Some(q.rel_mse.mean), 4),
            Cell::Num(Some(q.rmse.mean), 4),
            Cell::Num(Some(q.bias.mean), 3),
            Cell::Num(Some(q.flip_mean.mean), 4),
        ]);
        all.push(r);
    }
    let res = all.first().map(|r| r.resolution).unwrap_or_default();
    Ok(Table {
        title: "Barczak 2006: the light-sample sets against the reference (area-light room)".into(),
        columns: cols(&["samples", "reference", "lights", "relMSE", "RMSE", "bias", "FLIP"]),
        rows,
        notes: vec![
            format!(
                "gibench: `barczak` level Full at {}x{}, one pair of consecutive frames. indirect: the random-walk samples (5 bounces) \
                 against the reference's multi-bounce indirect irradiance; direct: points on the area light against the reference's \
                 direct irradiance (stratified points on the light at every pixel). relMSE: relative MSE (Rousselle et al. 2011); bias: \
                 signed relative error of the mean. No clamp (the thesis has none): samples near a surface make hot spots.",
                res[0], res[1]
            ),
            device_note(&all),
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_a_line() {
        let (a, b, r2) = fit(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]).unwrap();
        assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12 && (r2 - 1.0).abs() < 1e-12);
        assert!(fit(&[(1.0, 1.0)]).is_none());
    }

    #[test]
    fn swapped_cases_carry_the_other_mover_on_this_rooms_path() {
        let d = case("torus-table", "barczak-table", "barczak-pillars").unwrap();
        assert!(d.movers[0].mesh.generated.is_some());
        let table = SceneDescriptor::resolve("barczak-table").unwrap();
        for (k, t) in d.movers[0].path.keys.iter().zip(&table.movers[0].path.keys) {
            assert_eq!(
                [k.position[0], k.position[2]],
                [t.position[0], t.position[2]]
            );
            assert!(k.position[1] > 0.95);
        }
        let s = still(d);
        assert_eq!(s.movers[0].path.keys.len(), 1);
        assert_eq!(s.name, "barczak-torus-table-static");
    }
}
