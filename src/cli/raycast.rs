//! `gibench raycast`: the reference BVH's raw ray throughput on the ray sets `export-scene
//! --rays N` wrote (the file format is [`crate::rays`]'s): closest-hit and shadow rays timed
//! by wall clock and CPU time, with the hits written for comparison with another caster.

use std::path::PathBuf;

use clap::Args;
use gibench_harness::cpu::reference::ReferenceTracer;
use gibench_harness::measure::calibrate::timed;
use gibench_harness::output::OutputSet;
use gibench_harness::scene::anim::FrameClock;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::{Scene, SceneDescriptor};
use gibench_harness::{Error, Result};
use rayon::prelude::*;

use crate::rays::{read_rays, CLOSEST, SHADOW};

/// Timed passes `raycast --repeats` takes at most.
const MAX_REPEATS: u32 = 1000;

#[derive(Args)]
pub(crate) struct RaycastArgs {
    /// Folder written by `export-scene --rays N` (`scene.json`, `rays-closest.bin`,
    /// `rays-shadow.bin`); the scene and frame are the ones it records.
    #[arg(long)]
    rays: PathBuf,
    /// Timed passes over each ray set.
    #[arg(long, default_value_t = 3)]
    repeats: u32,
    /// Output directory (`raycast.json`, `closest-t.bin`, `shadow-hit.bin`).
    #[arg(long)]
    out: PathBuf,
    /// Extra directory searched first for scene assets.
    #[arg(long)]
    assets: Option<PathBuf>,
}

pub(crate) fn exec(args: &RaycastArgs) -> Result<()> {
    if !(1..=MAX_REPEATS).contains(&args.repeats) {
        return Err(Error::param(
            "repeats",
            format!("expected 1..={MAX_REPEATS} (got {})", args.repeats),
        ));
    }
    let meta_path = args.rays.join("scene.json");
    let meta: serde_json::Value = gibench_harness::error::read_bounded(&meta_path, 1 << 20)
        .map_err(|e| Error::param("rays", format!("cannot read {}: {e}", meta_path.display())))
        .and_then(|b| {
            serde_json::from_slice(&b).map_err(|e| {
                Error::param("rays", format!("{}: not JSON: {e}", meta_path.display()))
            })
        })?;
    let field = |name: &str| {
        meta.get(name).ok_or_else(|| {
            Error::param(
                "rays",
                format!("{}: no field '{name}'", meta_path.display()),
            )
        })
    };
    let scene_arg = field("scene_argument")?
        .as_str()
        .ok_or_else(|| {
            Error::param(
                "rays",
                format!("{}: 'scene_argument' is not a string", meta_path.display()),
            )
        })?
        .to_string();
    let frame_index = field("frame")?
        .as_u64()
        .and_then(|f| u32::try_from(f).ok())
        .ok_or_else(|| {
            Error::param(
                "rays",
                format!("{}: 'frame' is not a frame number", meta_path.display()),
            )
        })?;
    let recorded = field("rays")?.as_u64().ok_or_else(|| {
        Error::param(
            "rays",
            format!("{}: 'rays' is not a ray count", meta_path.display()),
        )
    })?;
    if recorded == 0 {
        return Err(Error::param(
            "rays",
            format!(
                "{} records no rays: export them with `gibench export-scene --rays N`",
                meta_path.display()
            ),
        ));
    }
    let closest = read_rays(&args.rays.join(CLOSEST))?;
    let shadow = read_rays(&args.rays.join(SHADOW))?;
    for (file, set) in [(CLOSEST, &closest), (SHADOW, &shadow)] {
        if set.len() as u64 != recorded {
            return Err(Error::param(
                "rays",
                format!(
                    "{} holds {} rays where {} records {recorded}: not the rays of this export",
                    args.rays.join(file).display(),
                    set.len(),
                    meta_path.display()
                ),
            ));
        }
    }
    gibench_papers::files::writable_dir("out", &args.out)?;
    let desc = SceneDescriptor::resolve(&scene_arg).map_err(|e| {
        Error::param(
            "rays",
            format!("{}: 'scene_argument': {e}", meta_path.display()),
        )
    })?;
    let scene = Scene::load(&desc, &AssetPaths::standard(args.assets.as_deref()))?;
    let frame = FrameClock::new(&desc).frame(frame_index);
    let (tracer, build_wall, _) = timed(|| ReferenceTracer::new(&scene, &frame));
    let bvh = tracer.bvh();
    let mut passes = Vec::new();
    let mut last = None;
    for _ in 0..args.repeats {
        let (t, cw, cc) = timed(|| {
            closest
                .par_iter()
                .with_min_len(256)
                .map(|r| {
                    bvh.closest_hit(r.origin, r.dir, 0.0, r.t_max)
                        .map_or(f32::INFINITY, |h| h.t)
                })
                .collect::<Vec<f32>>()
        });
        let (s, sw, sc) = timed(|| {
            shadow
                .par_iter()
                .with_min_len(256)
                .map(|r| bvh.any_hit(r.origin, r.dir, 0.0, r.t_max))
                .collect::<Vec<bool>>()
        });
        passes.push(serde_json::json!({
            "closest_wall_s": cw, "closest_cpu_s": cc, "shadow_wall_s": sw, "shadow_cpu_s": sc,
        }));
        last = Some((t, s));
    }
    let (t, s) = last.expect("at least one pass");
    let set = OutputSet::begin("out", &args.out)?;
    let t_bytes: Vec<u8> = t.iter().flat_map(|x| x.to_le_bytes()).collect();
    gibench_harness::output::write_atomic(&args.out.join("closest-t.bin"), &t_bytes)?;
    let s_bytes: Vec<u8> = s.iter().map(|&b| b as u8).collect();
    gibench_harness::output::write_atomic(&args.out.join("shadow-hit.bin"), &s_bytes)?;
    let json = serde_json::json!({
        "scene": desc.name, "frame": frame_index, "git_commit": gibench_harness::run::runner::git_commit(),
        "threads": rayon::current_num_threads(),
        "tree_triangles": bvh.tree_triangle_count(), "bvh_build_wall_s": build_wall,
        "closest_rays": closest.len(), "closest_hits": t.iter().filter(|x| x.is_finite()).count(),
        "shadow_rays": shadow.len(), "shadow_blocked": s.iter().filter(|&&b| b).count(),
        "passes": passes,
        "notes": "closest: SceneBvh::closest_hit (the full hit record: distance, barycentrics, \
                  normals, uv, material); shadow: SceneBvh::any_hit. CPU: every thread of the \
                  process during the pass (rayon over all cores).",
    });
    let bytes = serde_json::to_vec_pretty(&json).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::output::write_atomic(&args.out.join("raycast.json"), &bytes)?;
    set.publish()?;
    eprintln!(
        "raycast: {} closest-hit and {} shadow rays on '{}', {} passes: wrote {}",
        closest.len(),
        shadow.len(),
        desc.name,
        args.repeats,
        args.out.join("raycast.json").display()
    );
    Ok(())
}
