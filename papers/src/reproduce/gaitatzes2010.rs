//! Gaitatzes, Mavridis and Papaioannou 2010, "Interactive Volume-based Indirect Illumination of
//! Dynamic Scenes": its Table 1 and the room comparison of its Figure 6, regenerated through the
//! typed run API with the paper's figures (`results/papers/gaitatzes2010.json`) beside ours.
//!
//! * `gaitatzes-table1`: per scene (the test scene, the room, the arena, sun-lit Sponza), the
//!   triangles, grid, iterations (the paper's per scene), voxelization, propagation and
//!   reconstruction times and the frame time, with the paper's rows; and a figure of the two
//!   stages against the triangle count (`gaitatzes-scaling.svg`): the paper's claim that the
//!   propagation does not depend on the scene while the voxelization grows with it.
//! * `gaitatzes-quality`: on the room and sun-lit Sponza, `gaitatzes` and its plain-LPV mode
//!   (`mode=lpv`) against the multi-bounce reference: the paper's Figure 6 claim that plain
//!   light propagation volumes fail in the room, where most light arrives after two bounces.
//! * `gaitatzes-cornell`: `gaitatzes`' bias on the Cornell box against the multi-bounce reference
//!   (the default run's scene and reference), taken apart effect by effect: the defaults, then
//!   one change at a time, cumulatively ([`CORNELL_STEPS`]); each row's change of bias is that
//!   effect's share, and the last row is what remains.
//!
//! Paper sizes (512×512, 100 frames) are the defaults, for a GPU; `--quick` runs 256×192 and a
//! few frames (the grid and iterations stay the paper's: the propagation's cost does not depend
//! on the resolution).

use gibench_gaitatzes::{STAGE_PROPAGATION, STAGE_RECONSTRUCTION, STAGE_VOXELIZATION};
use gibench_harness::cpu::reference::ReferenceSettings;
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::technique::TechniqueInfo;
use gibench_harness::measure::results::RunResult;
use gibench_harness::report::{self, Cell, Table};
use gibench_harness::run::quality::{IndirectComponent, QualityConfig};
use gibench_harness::run::session::{RunSpec, TechniqueRun};
use gibench_harness::scene::Scene;
use gibench_harness::{Error, Result};

use super::{device_note, load_scene, ms, PaperModule, ReproduceArgs, Reproduced};
use crate::progress::Bars;

/// The module's entry for `reproduce all`.
pub const MODULE: PaperModule = PaperModule {
    describe,
    owned_folders: |_| &["runs"],
    check,
    work,
    needs_gpu: |_| true,
    reproduce,
    runs_folder,
    figures: |out, target| match target {
        "gaitatzes-table1" => vec![out.join("gaitatzes-scaling.svg")],
        _ => Vec::new(),
    },
};

/// What each target regenerates.
pub fn describe(target: &str) -> &'static str {
    match target {
        "gaitatzes-table1" => {
            "Gaitatzes et al. 2010 Table 1: voxelization and propagation times of four scenes, and their scaling with the triangle count"
        }
        "gaitatzes-quality" => {
            "Gaitatzes et al. 2010 Figure 6: gaitatzes vs plain LPV against the multi-bounce reference on the room and Sponza"
        }
        "gaitatzes-cornell" => {
            "gaitatzes' bias on the Cornell box against the multi-bounce reference, effect by effect (reach, bounce albedo, transport)"
        }
        _ => "",
    }
}

/// The grid of every run (the paper's).
const GRID: u32 = 32;

/// Plain LPV's iteration counts besides the scene's (Figure 6 comparison).
const LPV_FEW: u32 = 8;
const LPV_MANY: u32 = 256;

/// A `gaitatzes-cornell` step: the effect's name, the parameters it changes, what it undoes.
pub type CornellStep = (
    &'static str,
    &'static [(&'static str, &'static str)],
    &'static str,
);

/// The `gaitatzes-cornell` steps, cumulative: a name for the effect, the parameters changed
/// from the previous step (the first: the defaults), and what the change undoes.
pub const CORNELL_STEPS: [CornellStep; 5] = [
    ("defaults", &[], "the default run: 32³, 12 iterations, bounce albedo 0.5, cosine transport"),
    (
        "reach",
        &[("iterations", "64")],
        "light advances at most one cell per iteration: 12 do not cross the box (32 cells)",
    ),
    (
        "bounce albedo",
        &[("albedo", "stored")],
        "secondary bounces reflect the scene's albedo instead of the paper's constant 0.5",
    ),
    (
        "transport",
        &[("transport", "pyramid")],
        "less light diffuses back to its source (and less spurious self-irradiance fills in for it)",
    ),
    (
        "reach of later bounces",
        &[("iterations", "256")],
        "later bounces need more cells of travel",
    ),
];

/// The paper's published figures.
fn paper() -> Result<serde_json::Value> {
    super::paper(
        "gaitatzes2010",
        include_str!("../../../results/papers/gaitatzes2010.json"),
    )
}

/// A row of the paper's Table 1: its scene name, gibench's scene, its values (triangles, grid,
/// iterations, voxelization, propagation, total).
type PaperRow = (String, String, Vec<Option<f64>>);

/// The paper's rows.
fn paper_rows() -> Result<Vec<PaperRow>> {
    let p = paper()?;
    Ok(p["table1"]["rows"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .iter()
        .map(|r| {
            (
                r["scene"].as_str().unwrap_or("?").to_string(),
                r["gibench_scene"].as_str().unwrap_or("?").to_string(),
                r["values"]
                    .as_array()
                    .map(|a| a.iter().map(|v| v.as_f64()).collect())
                    .unwrap_or_default(),
            )
        })
        .collect())
}

/// The scenes of `target` (or `--scenes`) with their iteration counts: the paper's for its
/// scenes, 12 (its outdoor count) for others.
fn scenes_of(target: &str, args: &ReproduceArgs) -> Result<Vec<(String, u32)>> {
    let rows = paper_rows()?;
    let iterations = |scene: &str| {
        rows.iter()
            .find(|r| r.1 == scene)
            .and_then(|r| r.2.get(2).copied().flatten())
            .map(|v| v as u32)
            .unwrap_or(12)
    };
    let names: Vec<String> = if !args.scenes.is_empty() {
        args.scenes.clone()
    } else if target == "gaitatzes-quality" {
        vec!["gaitatzes-room".into(), "sponza-sun".into()]
    } else if target == "gaitatzes-cornell" {
        vec!["cornell".into()]
    } else {
        rows.iter().map(|r| r.1.clone()).collect()
    };
    Ok(names
        .into_iter()
        .map(|n| {
            let it = iterations(&n);
            (n, it)
        })
        .collect())
}

fn check_target(target: &str) -> Result<()> {
    if !matches!(
        target,
        "gaitatzes-table1" | "gaitatzes-quality" | "gaitatzes-cornell"
    ) {
        return Err(Error::param(
            "target",
            format!("not a Gaitatzes 2010 target: '{target}'"),
        ));
    }
    Ok(())
}

/// Sizes: (resolution, measured frames, warm-up frames).
fn sizes(target: &str, args: &ReproduceArgs) -> ([u32; 2], u32, u32) {
    let (res, frames, warmup) = match (target, args.quick) {
        // The quality runs compare one pair of frames at the size the reference can afford.
        ("gaitatzes-quality" | "gaitatzes-cornell", _) => ([256, 192], 2, 3),
        (_, true) => ([256, 192], 4, 3),
        (_, false) => ([512, 512], 100, 10),
    };
    let res = if args.tiny() { [64, 48] } else { res };
    (res, args.frames.unwrap_or(frames), warmup)
}

/// Checks what can be checked before any work: the target, the scenes, the runs' settings.
pub fn check(target: &str, args: &ReproduceArgs) -> Result<()> {
    check_target(target)?;
    for (name, it) in scenes_of(target, args)? {
        let scene = load_scene(&name, args)?;
        spec(target, args, &scene, it)?.validate()?;
    }
    Ok(())
}

/// (frames rendered, frames × pixels).
pub fn work(target: &str, args: &ReproduceArgs) -> (u64, u64) {
    let (res, frames, warmup) = sizes(target, args);
    let scenes = scenes_of(target, args).map(|s| s.len()).unwrap_or(4) as u64;
    // Table 1: one run timed per stage and per frame; quality: six runs, timed and compared.
    let runs = match target {
        "gaitatzes-quality" => 6,
        "gaitatzes-cornell" => CORNELL_STEPS.len() as u64 + 1,
        _ => 2,
    };
    let f = scenes * runs * (frames + warmup) as u64;
    (f, f * res[0] as u64 * res[1] as u64)
}

/// The folder of the runs behind the tables.
pub fn runs_folder(args: &ReproduceArgs) -> std::path::PathBuf {
    super::out_dir(args, "gaitatzes").join("runs")
}

/// The runs of `target` on `scene` with `iterations`.
fn spec<'s>(
    target: &str,
    args: &ReproduceArgs,
    scene: &'s Scene,
    iterations: u32,
) -> Result<RunSpec<'s>> {
    let info = TechniqueInfo::find(crate::registry::all(), "gaitatzes")?;
    let (grid, it) = (GRID.to_string(), iterations.to_string());
    let (res, frames, warmup) = sizes(target, args);
    if target == "gaitatzes-cornell" {
        return cornell_spec(args, scene, info, res, frames, warmup);
    }
    let stem = |suffix: &str| {
        format!(
            "{}-gaitatzes{suffix}-{}x{}",
            scene.descriptor.name, res[0], res[1]
        )
    };
    let mut runs = vec![TechniqueRun::new(
        info,
        &[("grid", grid.as_str()), ("iterations", it.as_str())],
        stem(""),
    )?];
    let quality = (target == "gaitatzes-quality").then(|| QualityConfig {
        pairs: 1,
        all: false,
        // The paper's Figure 6(e): "reference radiosity using 2-bounce path tracing".
        reference: ReferenceSettings {
            bounces: 2,
            ..ReferenceSettings::default()
        },
        component: Some(IndirectComponent::MultiBounce),
    });
    let compared = quality.is_some();
    if compared {
        // gibench's two transports (not the paper's), at the same count.
        for transport in ["carry", "pyramid"] {
            runs.push(TechniqueRun::new(
                info,
                &[
                    ("grid", grid.as_str()),
                    ("iterations", it.as_str()),
                    ("transport", transport),
                ],
                stem(&format!("-{transport}")),
            )?);
        }
        // Plain LPV at several counts: with nothing absorbing, its accumulation grows with
        // every iteration, so its brightness is set by the count, not by the light.
        let mut counts = vec![LPV_FEW, iterations, LPV_MANY];
        counts.sort_unstable();
        counts.dedup();
        for n in counts {
            let n = n.to_string();
            runs.push(TechniqueRun::new(
                info,
                &[
                    ("grid", grid.as_str()),
                    ("iterations", n.as_str()),
                    ("mode", "lpv"),
                ],
                stem(&format!("-lpv-{n}")),
            )?);
        }
    }
    Ok(RunSpec {
        scene,
        runs,
        config: super::paper_config(args, res, frames, warmup, compared),
        quality,
        cache: crate::options::default_reference_cache(),
        out: runs_folder(args),
        images: compared,
    })
}

/// The `gaitatzes-cornell` runs: each of [`CORNELL_STEPS`] with the changes before it, and the
/// paper's transport at the last step's other settings (does it converge too?). Compared with
/// the reference the default run uses.
fn cornell_spec<'s>(
    args: &ReproduceArgs,
    scene: &'s Scene,
    info: &'static TechniqueInfo,
    res: [u32; 2],
    frames: u32,
    warmup: u32,
) -> Result<RunSpec<'s>> {
    let mut params: Vec<(&str, &str)> = Vec::new();
    let mut runs = Vec::new();
    for (k, (_, changes, _)) in CORNELL_STEPS.iter().enumerate() {
        for (name, value) in changes.iter() {
            params.retain(|(n, _)| n != name);
            params.push((name, value));
        }
        runs.push(TechniqueRun::new(
            info,
            &params,
            format!(
                "{}-gaitatzes-step{k}-{}x{}",
                scene.descriptor.name, res[0], res[1]
            ),
        )?);
    }
    params.retain(|(n, _)| *n != "transport");
    runs.push(TechniqueRun::new(
        info,
        &params,
        format!(
            "{}-gaitatzes-step{}-cosine-{}x{}",
            scene.descriptor.name,
            CORNELL_STEPS.len() - 1,
            res[0],
            res[1]
        ),
    )?);
    Ok(RunSpec {
        scene,
        runs,
        config: super::paper_config(args, res, frames, warmup, true),
        quality: Some(QualityConfig {
            pairs: 1,
            all: false,
            reference: ReferenceSettings::default(),
            component: Some(IndirectComponent::MultiBounce),
        }),
        cache: crate::options::default_reference_cache(),
        out: runs_folder(args),
        images: true,
    })
}

/// Runs `target` and builds its table.
pub fn reproduce(
    target: &str,
    args: &ReproduceArgs,
    gpu: Option<&GpuContext>,
    bars: &Bars,
) -> Reproduced {
    check_target(target)?;
    let scenes = scenes_of(target, args)?;
    let loaded = scenes
        .iter()
        .map(|(n, _)| load_scene(n, args))
        .collect::<Result<Vec<_>>>()?;
    let specs = scenes
        .iter()
        .zip(&loaded)
        .map(|((_, it), scene)| spec(target, args, scene, *it))
        .collect::<Result<Vec<_>>>()?;
    let runs = super::run_specs(&specs, args, gpu, bars)?;
    let table = if target == "gaitatzes-quality" {
        (quality_table(&runs)?, "gaitatzes-quality")
    } else if target == "gaitatzes-cornell" {
        (cornell_table(&runs)?, "gaitatzes-cornell")
    } else {
        scaling_figure(args, &runs, &loaded)?;
        (table1(&runs, &loaded)?, "gaitatzes-table1")
    };
    Ok((vec![table], runs))
}

fn iterations(r: &RunResult) -> Option<f64> {
    r.parameters.get("iterations").and_then(|v| v.as_f64())
}

fn table1(runs: &[RunResult], scenes: &[Scene]) -> Result<Table> {
    let paper = paper()?;
    let rows_paper = paper_rows()?;
    let columns: Vec<String> = [
        "source",
        "scene",
        "triangles",
        "grid",
        "iterations",
        "voxelization",
        "propagation",
        "reconstruction",
        "total (frame)",
    ]
    .map(String::from)
    .into();
    let mut rows = Vec::new();
    for (r, scene) in runs.iter().zip(scenes) {
        rows.push(vec![
            Cell::text("gibench"),
            Cell::text(&r.scene),
            Cell::Num(Some(scene.mesh.triangle_count() as f64), 0),
            Cell::text(format!("{GRID}³")),
            Cell::Num(iterations(r), 0),
            Cell::Ms(ms(r, STAGE_VOXELIZATION)),
            Cell::Ms(ms(r, STAGE_PROPAGATION)),
            Cell::Ms(ms(r, STAGE_RECONSTRUCTION)),
            Cell::Ms(r.frame.as_ref().map(|f| f.frame_ms.median)),
        ]);
        if let Some((name, _, v)) = rows_paper.iter().find(|p| p.1 == r.scene) {
            let get = |i: usize| v.get(i).copied().flatten();
            rows.push(vec![
                Cell::text(format!(
                    "Gaitatzes et al. 2010, Table 1 ({}, {})",
                    paper["hardware"].as_str().unwrap_or("?"),
                    paper["year"]
                )),
                Cell::text(name),
                Cell::Num(get(0), 0),
                Cell::text(format!("{}³", get(1).unwrap_or(0.0))),
                Cell::Num(get(2), 0),
                Cell::Ms(get(3)),
                Cell::Ms(get(4)),
                Cell::Ms(None),
                Cell::Ms(get(5)),
            ]);
        }
    }
    let all: Vec<&RunResult> = runs.iter().collect();
    let frames = runs
        .first()
        .map(|r| (r.frames.measured, r.frames.warmup, r.resolution))
        .unwrap_or_default();
    Ok(Table {
        title: "Gaitatzes et al. 2010, Table 1: time measurements (ms)".into(),
        columns,
        rows,
        notes: vec![
            format!(
                "gibench rows: `gaitatzes` at {}x{}, medians over {} frames ({} warm-up frames dropped), the whole scene \
                 voxelized every frame (fully dynamic, as the paper treats every scene); stages timed with the queue flushed \
                 before and after. Voxelization: the three axes' slice passes ({GRID} draws of the scene each), the MAX \
                 combine and the injection; propagation: every iteration; reconstruction: per pixel. Total (frame): the \
                 whole frame (G-buffer, direct light, the technique, compose) without added synchronisation; the paper's \
                 total also holds its direct lighting and other effects. The test scene, room and arena are generated in \
                 code (the paper gives only their triangle counts); Sponza is the shared asset, lit by the sun.",
                frames.2[0], frames.2[1], frames.0, frames.1
            ),
            format!(
                "Paper rows: {}; {}",
                paper["source"].as_str().unwrap_or(""),
                paper["note"].as_str().unwrap_or("")
            ),
            device_note(&all),
        ],
    })
}

/// `gaitatzes-scaling.svg`: voxelization and propagation against the triangle count, ours and
/// the paper's.
fn scaling_figure(args: &ReproduceArgs, runs: &[RunResult], scenes: &[Scene]) -> Result<()> {
    let mut ours_vox = Vec::new();
    let mut ours_prop = Vec::new();
    for (r, s) in runs.iter().zip(scenes) {
        let t = s.mesh.triangle_count() as f64;
        if let (Some(v), Some(p), Some(it)) = (
            ms(r, STAGE_VOXELIZATION),
            ms(r, STAGE_PROPAGATION),
            iterations(r),
        ) {
            ours_vox.push((t.log10(), v));
            // Per iteration: the scenes run different iteration counts.
            ours_prop.push((t.log10(), p / it.max(1.0)));
        }
    }
    let mut paper_vox = Vec::new();
    let mut paper_prop = Vec::new();
    for (_, _, v) in paper_rows()? {
        if let (Some(t), Some(it), Some(vx), Some(p)) = (v[0], v[2], v[3], v[4]) {
            paper_vox.push((t.log10(), vx));
            paper_prop.push((t.log10(), p / it.max(1.0)));
        }
    }
    for series in [
        &mut ours_vox,
        &mut ours_prop,
        &mut paper_vox,
        &mut paper_prop,
    ] {
        series.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let out = super::out_dir(args, "gaitatzes");
    report::lines_svg(
        &[
            ("gibench voxelization (ms)".to_string(), ours_vox),
            (
                "gibench propagation per iteration (ms)".to_string(),
                ours_prop,
            ),
            ("paper voxelization (ms, GTX 285)".to_string(), paper_vox),
            (
                "paper propagation per iteration (ms, GTX 285)".to_string(),
                paper_prop,
            ),
        ],
        &out.join("gaitatzes-scaling.svg"),
        "Voxelization grows with the scene, propagation does not (Gaitatzes et al. 2010)",
        "log10(triangles)",
        "ms",
    )?;
    Ok(())
}

fn quality_table(runs: &[RunResult]) -> Result<Table> {
    let columns: Vec<String> = [
        "scene",
        "mode",
        "transport",
        "iterations",
        "relMSE",
        "RMSE",
        "bias",
        "FLIP",
        "propagation",
    ]
    .map(String::from)
    .into();
    let mut rows = Vec::new();
    for r in runs {
        let q = r.quality.as_ref().ok_or_else(|| {
            Error::Invalid(format!("gaitatzes-quality: {} has no quality", r.scene))
        })?;
        rows.push(vec![
            Cell::text(&r.scene),
            Cell::text(
                r.parameters
                    .get("mode")
                    .and_then(|v| v.as_str())
                    .unwrap_or("occluded"),
            ),
            Cell::text(
                r.parameters
                    .get("transport")
                    .and_then(|v| v.as_str())
                    .unwrap_or("cosine"),
            ),
            Cell::Num(iterations(r), 0),
            Cell::Num(Some(q.rel_mse.mean), 4),
            Cell::Num(Some(q.rmse.mean), 4),
            Cell::Num(Some(q.bias.mean), 3),
            Cell::Num(Some(q.flip_mean.mean), 4),
            Cell::Ms(ms(r, STAGE_PROPAGATION)),
        ]);
    }
    let all: Vec<&RunResult> = runs.iter().collect();
    let reference = runs
        .first()
        .and_then(|r| r.quality.as_ref())
        .map(|q| q.reference.clone())
        .unwrap_or_default();
    Ok(Table {
        title: "Gaitatzes et al. 2010, Figure 6: occluded multi-bounce propagation vs plain light propagation volumes".into(),
        columns,
        rows,
        notes: vec![
            format!(
                "Both modes on the same grid ({GRID}³) and reconstruction, \
                 against the reference's two-bounce indirect irradiance ({reference}; the paper's Figure 6(e) is a \
                 2-bounce path-traced reference), over one pair of consecutive \
                 frames at 256x192. occluded: `gaitatzes` at the paper's iterations per scene (the voxels' direct radiosity injected, propagation through void cells, reflection at occupied ones, \
                 accumulation where light arrives); transport carry / pyramid: the same with each lobe's direction kept through \
                 void cells / with the light of each face's pyramid passed on (gibench's variants, not the paper's); lpv: Kaplanyan's light propagation volumes (2009: \
                 a 64² reflective shadow map's texels injected as VPLs, his face weights, every step accumulated, no occlusion, no secondary bounces) at {LPV_FEW}, the scene's and {LPV_MANY} iterations; \
                 his faces' solid angles pass on 1.14 times what a cell holds each step (`slab::kaplanyan_weights`), so its brightness grows with the count. The paper (Figure 6): plain LPV \"completely fails to reproduce the indirect \
                 lighting in the room\"; two bounces are needed there."
            ),
            device_note(&all),
        ],
    })
}

/// The `gaitatzes-cornell` table: per step its parameters, bias, the change of bias from the
/// previous step (the effect's share), relMSE and RMSE; then the paper's transport at the last
/// step's settings.
fn cornell_table(runs: &[RunResult]) -> Result<Table> {
    let columns: Vec<String> = [
        "step",
        "parameters",
        "bias",
        "change of bias",
        "relMSE",
        "RMSE",
        "propagation",
        "what the step undoes",
    ]
    .map(String::from)
    .into();
    let params = |r: &RunResult| {
        ["grid", "iterations", "albedo", "transport"]
            .iter()
            .filter_map(|k| {
                r.parameters.get(*k).map(|v| {
                    format!(
                        "{k}={}",
                        v.as_str().map(String::from).unwrap_or(v.to_string())
                    )
                })
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut rows = Vec::new();
    let mut previous: Option<f64> = None;
    for (k, r) in runs.iter().enumerate() {
        let q = r.quality.as_ref().ok_or_else(|| {
            Error::Invalid(format!("gaitatzes-cornell: {} has no quality", r.scene))
        })?;
        let bias = q.bias.mean;
        let (step, why) = match CORNELL_STEPS.get(k) {
            Some((name, _, why)) => (name.to_string(), why.to_string()),
            None => (
                "(the paper's transport)".to_string(),
                "the last step's settings with cosine transport: its spurious self-irradiance keeps growing".to_string(),
            ),
        };
        let change = match (k, previous) {
            (k, Some(p)) if k < CORNELL_STEPS.len() => Some(bias - p),
            _ => None,
        };
        if k < CORNELL_STEPS.len() {
            previous = Some(bias);
        }
        rows.push(vec![
            Cell::text(step),
            Cell::text(params(r)),
            Cell::Num(Some(bias), 3),
            Cell::Num(change, 3),
            Cell::Num(Some(q.rel_mse.mean), 3),
            Cell::Num(Some(q.rmse.mean), 3),
            Cell::Ms(ms(r, STAGE_PROPAGATION)),
            Cell::text(why),
        ]);
    }
    let all: Vec<&RunResult> = runs.iter().collect();
    let reference = runs
        .first()
        .and_then(|r| r.quality.as_ref())
        .map(|q| q.reference.clone())
        .unwrap_or_default();
    Ok(Table {
        title: "gaitatzes on the Cornell box: its bias against the multi-bounce reference, effect by effect".into(),
        columns,
        rows,
        notes: vec![
            format!(
                "Each step keeps the changes of the steps above it and adds its own; its change of bias is the effect's share \
                 at that point (the effects interact: their order matters, and the steps' shares add up to the last \
                 step's bias minus the defaults'). The reference is the default run's ({reference}); one pair of \
                 consecutive frames at 256x192. transport=pyramid is gibench's variant, not the paper's; \
                 albedo=stored and iterations beyond the paper's 64 are options the paper names or implies."
            ),
            device_note(&all),
        ],
    })
}
