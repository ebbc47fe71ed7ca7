//! `gibench reference`: the CPU reference (direct, one-bounce, multi-bounce) of one frame as
//! EXR and PNG images and a JSON of its settings and timings.

use std::path::PathBuf;

use clap::Args;
use gibench_harness::cpu::reference::ReferenceSettings;
use gibench_harness::output::OutputSet;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::{Scene, SceneDescriptor};
use gibench_harness::{Error, Result};

use crate::files::{cache_dir, writable_dir};
use crate::options::ReferenceOpts;
use crate::params::{check_frame_number, parse_resolution};
use crate::progress::Bars;

#[derive(Args)]
pub struct ReferenceArgs {
    /// Scene: a built-in name or a descriptor JSON.
    #[arg(long, default_value = "cornell")]
    pub scene: String,
    /// Animation frame.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "256x192")]
    pub resolution: String,
    /// Output directory.
    #[arg(long, default_value = "results/local")]
    pub out: PathBuf,
    /// Extra directory searched first for scene assets.
    #[arg(long)]
    pub assets: Option<PathBuf>,
    /// Also render with the next seed and report the relative MSE between the two (an
    /// estimate of the reference's own noise).
    #[arg(long)]
    pub error_estimate: bool,
    #[command(flatten)]
    pub reference: ReferenceOpts,
}

/// `gibench reference`: plan, render into an output set, publish.
pub fn exec(args: &ReferenceArgs) -> Result<()> {
    let planned = reference_plan(args)?;
    let set = OutputSet::begin("out", &args.out)?;
    let done = reference_planned(args, &planned, &Bars::Own(false))?;
    set.publish()?;
    eprintln!("{done}");
    Ok(())
}

/// A reference render checked before it runs.
pub struct ReferencePlan {
    pub resolution: [u32; 2],
    pub settings: ReferenceSettings,
    pub desc: SceneDescriptor,
    pub scene: Scene,
}

/// Checks a reference render's arguments and loads its scene.
pub fn reference_plan(args: &ReferenceArgs) -> Result<ReferencePlan> {
    let resolution = parse_resolution(&args.resolution)?;
    gibench_harness::run::runner::check_resolution(resolution)?;
    check_frame_number("frame", args.frame)?;
    let settings = args.reference.settings()?;
    let desc = SceneDescriptor::resolve(&args.scene)?;
    let scene = Scene::load(&desc, &AssetPaths::standard(args.assets.as_deref()))?;
    if !args.reference.no_cache {
        cache_dir("cache", &args.reference.cache)?;
    }
    writable_dir("out", &args.out)?;
    Ok(ReferencePlan {
        resolution,
        settings,
        desc,
        scene,
    })
}

/// The work of `gibench reference` once planned and its output set is open. Returns what it
/// wrote, as a line for the terminal.
pub fn reference_planned(
    args: &ReferenceArgs,
    planned: &ReferencePlan,
    bars: &Bars,
) -> Result<String> {
    let ReferencePlan {
        resolution,
        settings,
        desc,
        scene,
    } = planned;
    let (resolution, settings) = (*resolution, *settings);
    let frame = gibench_harness::scene::anim::FrameClock::new(desc).frame(args.frame);
    let cache = args.reference.cache();
    bars.note(&format!(
        "gibench: reference for '{}' frame {} at {}x{}: {} spp, {} bounces, seed {}",
        desc.name,
        args.frame,
        resolution[0],
        resolution[1],
        settings.spp,
        settings.bounces,
        settings.seed
    ));
    // Wall and all-thread CPU of the call (BVH build included; `setup` has its share).
    let (r, seconds, cpu_seconds) = gibench_harness::measure::calibrate::timed(|| {
        cache.get_timed(scene, &frame, resolution, &settings)
    });
    let (r, setup) = r?;
    let mut estimate = None;
    if args.error_estimate {
        let other = ReferenceSettings {
            seed: settings.seed + 1,
            ..settings
        };
        let r2 = cache.get(scene, &frame, resolution, &other)?;
        let one =
            gibench_harness::measure::metrics::relative_mse(&r.one_bounce, &r2.one_bounce, &r.hit);
        let multi = gibench_harness::measure::metrics::relative_mse(
            &r.multi_bounce,
            &r2.multi_bounce,
            &r.hit,
        );
        bars.note(&format!(
            "relative MSE between seeds {} and {}: one-bounce {one:.5}, multi-bounce {multi:.5}",
            settings.seed, other.seed
        ));
        estimate = Some(
            serde_json::json!({"seeds": [settings.seed, other.seed], "one_bounce_rel_mse": one, "multi_bounce_rel_mse": multi}),
        );
    }
    let stem = format!("{}-f{}-reference", desc.name, args.frame);
    let out = |suffix: &str| args.out.join(format!("{stem}{suffix}"));
    let arr =
        |v: &[gibench_harness::glam::Vec3]| v.iter().map(|c| c.to_array()).collect::<Vec<_>>();
    gibench_harness::gpu::image_io::write_exr(&out("-direct.exr"), resolution, &arr(&r.direct))?;
    gibench_harness::gpu::image_io::write_exr(
        &out("-one-bounce.exr"),
        resolution,
        &arr(&r.one_bounce),
    )?;
    gibench_harness::gpu::image_io::write_exr(
        &out("-multi-bounce.exr"),
        resolution,
        &arr(&r.multi_bounce),
    )?;
    gibench_harness::gpu::image_io::write_exr(
        &out("-radiance.exr"),
        resolution,
        &arr(&r.radiance),
    )?;
    let exposure = desc.settings.exposure;
    let png = |radiance: &[gibench_harness::glam::Vec3]| -> Vec<u8> {
        gibench_harness::measure::metrics::tonemap_srgb8(radiance, exposure)
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect()
    };
    gibench_harness::gpu::image_io::write_png(&out(".png"), resolution, &png(&r.radiance))?;
    gibench_harness::gpu::image_io::write_png(
        &out("-one-bounce.png"),
        resolution,
        &png(&r.radiance_with(&r.one_bounce)),
    )?;
    gibench_harness::gpu::image_io::write_png(
        &out("-direct.png"),
        resolution,
        &png(&r.radiance_with(&vec![Default::default(); r.direct.len()])),
    )?;
    let info = serde_json::json!({
        "scene": desc.name, "frame": args.frame, "resolution": resolution, "spp": settings.spp,
        "bounces": settings.bounces, "seed": settings.seed, "seconds": seconds,
        "cpu_seconds": cpu_seconds,
        "bvh_build_seconds": setup.map(|t| t.seconds),
        "bvh_build_cpu_seconds": setup.and_then(|t| t.cpu_seconds),
        "rays": setup.map(|t| serde_json::json!({
            "closest": t.rays.closest, "shadow": t.rays.shadow, "total": t.rays.total(),
        })),
        "reference_version": gibench_harness::cpu::reference::REFERENCE_VERSION,
        "git_commit": gibench_harness::run::runner::git_commit(), "error_estimate": estimate,
    });
    let json = serde_json::to_vec_pretty(&info).map_err(|e| Error::Invalid(e.to_string()))?;
    gibench_harness::output::write_atomic(&out(".json"), &json)?;
    Ok(format!("wrote {stem}.png, .json and -direct/-one-bounce/-multi-bounce/-radiance.exr to {} ({seconds:.1} s)", args.out.display()))
}
