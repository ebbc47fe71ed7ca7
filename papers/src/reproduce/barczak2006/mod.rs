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
//!
//! This file plans and runs the target; [`figures`] builds its figures and tables.

mod figures;

use std::path::PathBuf;

use gibench_harness::cpu::reference::ReferenceSettings;
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::technique::TechniqueInfo;
use gibench_harness::run::quality::{IndirectComponent, QualityConfig};
use gibench_harness::run::session::{RunSpec, TechniqueRun};
use gibench_harness::scene::{Scene, SceneDescriptor};
use gibench_harness::{Error, Result};

use super::{PaperModule, ReproduceArgs, Reproduced};
use crate::progress::Bars;
use figures::{fig5_2, fig5_3, fig5_4, fig5_5, fig5_6, quality_table};

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
        include_str!("../../../../results/papers/barczak2006.json"),
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
        // The test size: every run (and its reference) at 64x48.
        resolution: if args.tiny() { [64, 48] } else { s.resolution },
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
        cache: crate::options::default_reference_cache(),
        out: runs_folder(args),
        images: false,
    })
}

fn load(desc: &SceneDescriptor, args: &ReproduceArgs) -> Result<Scene> {
    Scene::load(
        desc,
        &gibench_harness::scene::assets::AssetPaths::standard(args.assets.as_deref()),
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

#[cfg(test)]
mod tests {
    use super::*;

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
