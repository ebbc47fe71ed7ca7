//! End to end: `gibench run` writes a complete results file, images and tables.

use crate::support;

use gibench_harness::measure::results::RunResult;

fn run_ok(args: &[&str], out: &std::path::Path) -> String {
    let o = support::GIBENCH
        .command()
        .arg("run")
        .args(args)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "gibench run {args:?} failed:\n{stderr}");
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    // The terminal table fits 120 columns (before: over 300 with every technique's stages).
    let widest = stdout.lines().map(|l| l.chars().count()).max().unwrap_or(0);
    assert!(widest <= 120, "a line of {widest} characters:\n{stdout}");
    stdout
}

#[test]
fn cornell_run_writes_results_images_and_tables() {
    let tmp = tempfile::tempdir().unwrap();
    let stdout = run_ok(&["--frames", "4", "--warmup", "3"], tmp.path());
    for col in [
        "gbuffer",
        "direct-shadow-map",
        "direct-light",
        "compose",
        "FPS",
    ] {
        assert!(stdout.contains(col), "table lacks '{col}':\n{stdout}");
    }
    let r = RunResult::read(&tmp.path().join("cornell-direct.json")).unwrap();
    assert_eq!(r.scene, "cornell");
    assert_eq!(r.technique, "direct");
    assert_eq!(r.frames.measured, 4);
    assert_eq!(r.frames.warmup, 3);
    for s in &r.stages {
        let wall = s.wall_ms.expect("flushed wall time");
        assert_eq!(wall.count, 4, "stage {}", s.name);
        if r.device.timestamp_queries {
            assert_eq!(s.gpu_ms.expect("timestamps").count, 4);
        }
    }
    assert_eq!(r.frame.as_ref().expect("frame timing").frame_ms.count, 4);
    // The run records the commit the binary was built from (stamped by build.rs), and that
    // stamp is the checkout's current one: a stale stamp (the build script not rerun after a
    // commit or an edit) would name another.
    let version = support::GIBENCH
        .command()
        .arg("--version")
        .output()
        .unwrap();
    let version = String::from_utf8_lossy(&version.stdout).into_owned();
    assert!(
        version.contains(&format!("({})", r.git_commit)),
        "results name {} but the binary says {version}",
        r.git_commit
    );
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    assert_eq!(r.git_commit, gibench_harness::run::commit::describe(root));
    for f in [
        "cornell-direct.png",
        "cornell-direct-indirect.exr",
        "cornell-direct-direct.exr",
        "cornell-summary.md",
        "cornell-summary.csv",
        "cornell-summary.tex",
        "cornell-summary.svg",
    ] {
        assert!(tmp.path().join(f).is_file(), "{f} missing");
    }
    let png = image::open(tmp.path().join("cornell-direct.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(png.dimensions(), (256, 192));
    // The spot light lights the floor: the image is not black.
    assert!(png.pixels().any(|p| p[0] > 64), "image is black");
}

/// Sibenik (found through the asset search path) with `laine` and `keller-full` at the same
/// small VPL count: the results record the loaded scene's triangle counts (its tessellated
/// shadow-map copy has more), both techniques light every frame with the same number of VPLs
/// (`laine` with at most as many), and `laine` renders only its new VPLs' maps after the first
/// frame while `keller-full` renders all of them.
#[test]
fn sibenik_loads_through_the_asset_search_path() {
    let tmp = tempfile::tempdir().unwrap();
    run_ok(
        &[
            "--scene",
            "sibenik",
            "--technique",
            "laine,keller-full",
            "--param",
            "vpls=16",
            "--param",
            "vpl-map-size=32",
            "--resolution",
            "64x48",
            "--frames",
            "3",
            "--warmup",
            "1",
            "--timing",
            "stages",
            "--no-images",
        ],
        tmp.path(),
    );
    let laine = RunResult::read(&tmp.path().join("sibenik-laine.json")).unwrap();
    let keller = RunResult::read(&tmp.path().join("sibenik-keller-full.json")).unwrap();
    let triangles = |r: &RunResult, key: &str| r.settings[key].as_u64().unwrap();
    assert!(triangles(&laine, "scene_triangles") > 70_000);
    assert!(triangles(&laine, "shadow_mesh_triangles") > triangles(&laine, "scene_triangles"));
    let counter = |r: &RunResult, name: &str| r.counters[name];
    assert_eq!(counter(&keller, "vpls").min, 16.0);
    assert!(counter(&laine, "vpls").max <= 16.0 && counter(&laine, "vpls").min >= 8.0);
    assert_eq!(counter(&keller, "shadow-maps").mean, 16.0);
    assert!(
        counter(&laine, "shadow-maps").max <= 8.0,
        "laine re-renders only new maps"
    );
    assert!(laine.stage("vpl-management").is_some());
}

#[test]
fn quality_columns_and_results() {
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let stdout = run_ok(
        &[
            "--frames",
            "3",
            "--warmup",
            "3",
            "--quality",
            "--quality-pairs",
            "1",
            "--spp",
            "16",
            "--cache",
            cache.to_str().unwrap(),
        ],
        tmp.path(),
    );
    for col in ["RMSE", "relMSE", "FLIP", "flicker", "flicker floor"] {
        assert!(stdout.contains(col), "table lacks '{col}':\n{stdout}");
    }
    let r = RunResult::read(&tmp.path().join("cornell-direct.json")).unwrap();
    let q = r.quality.expect("quality in the results");
    // Frames 4 and 5 (a consecutive pair ending at the last measured frame).
    assert_eq!(
        q.frames.iter().map(|f| f.frame).collect::<Vec<_>>(),
        vec![4, 5]
    );
    assert!(q.frames[1].temporal.is_some());
    // The reference's own flicker floor, from the pair rendered again with the next seed: above
    // 0 at 16 spp (0: the pair compared with itself, the same seed).
    assert!(
        q.flicker_floor.is_some_and(|f| f > 0.0 && f.is_finite()),
        "{:?}",
        q.flicker_floor
    );
    // `direct` has no indirect light: its relative MSE against one bounce is close to 1.
    assert!(
        q.rel_mse.mean > 0.5 && q.rel_mse.mean <= 1.0,
        "relMSE {}",
        q.rel_mse.mean
    );
    assert!(q.rmse.mean > 0.0 && q.flip_mean.mean > 0.0);
    assert!(
        support::reference_image(&tmp.path().join("cornell-direct.json"), "-reference.png")
            .is_file()
    );
    assert!(tmp.path().join("cornell-direct-flip.png").is_file());
    // The references were cached: frames 4 and 5, one-bounce (the VPL techniques) and
    // multi-bounce (`gaitatzes`), each with the run's seed and the next (the floor).
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 8);
}

/// README: two seeds of the reference at the default spp agree to a relative MSE below 0.02.
#[test]
fn reference_two_seeds_agree_at_default_spp() {
    let tmp = tempfile::tempdir().unwrap();
    let o = support::GIBENCH
        .command()
        .args([
            "reference",
            "--scene",
            "cornell",
            "--resolution",
            "128x96",
            "--error-estimate",
            "--no-cache",
            "--out",
        ])
        .arg(tmp.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let info: serde_json::Value = serde_json::from_slice(
        &std::fs::read(tmp.path().join("cornell-f0-reference.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(info["spp"], 256);
    // The render call's CPU time (every thread), beside its wall time.
    let cpu = info["cpu_seconds"].as_f64().unwrap();
    let wall = info["seconds"].as_f64().unwrap();
    assert!(cpu > 0.0 && wall > 0.0, "{info}");
    // Within it, the BVH build's (rendered here, not read from a cache): a part of each.
    let build = info["bvh_build_seconds"].as_f64().unwrap();
    let build_cpu = info["bvh_build_cpu_seconds"].as_f64().unwrap();
    assert!(
        (0.0..wall).contains(&build) && (0.0..cpu).contains(&build_cpu),
        "{info}"
    );
    // The rays it traced (for scripts/compare_mitsuba.py's per-ray ratio): one camera ray per
    // pixel, at most 8 segments per path (256 paths a pixel), a shadow ray at most per vertex.
    let rays = &info["rays"];
    let (closest, shadow) = (rays["closest"].as_u64(), rays["shadow"].as_u64());
    let (Some(closest), Some(shadow)) = (closest, shadow) else {
        panic!("no ray counts: {info}");
    };
    let pixels = 128 * 96;
    let most = pixels * (1 + 256 * 8);
    assert!(
        (pixels..=most).contains(&closest) && (1..=most).contains(&shadow),
        "{info}"
    );
    assert_eq!(rays["total"].as_u64(), Some(closest + shadow), "{info}");
    let e = &info["error_estimate"];
    for k in ["one_bounce_rel_mse", "multi_bounce_rel_mse"] {
        let v = e[k].as_f64().unwrap();
        assert!(v > 0.0 && v < 0.02, "{k} = {v}");
    }
    for f in [
        "-direct.exr",
        "-one-bounce.exr",
        "-multi-bounce.exr",
        "-radiance.exr",
        ".png",
    ] {
        assert!(
            tmp.path()
                .join(format!("cornell-f0-reference{f}"))
                .is_file(),
            "{f}"
        );
    }
}

/// `barczak set=direct` on `cornell-area` subtracts its occluded lights' exact contributions
/// from an interpolated light map, which undershoots below zero at a few pixels (49 of 3,072 at
/// 64x48 before this was handled). The written irradiance holds no negative value and the
/// results file says how many pixels were set to 0. Caught by: the technique's output written
/// as read back (negative EXR pixels), or clamped without a warning.
#[test]
fn negative_irradiance_is_set_to_zero_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    run_ok(
        &[
            "--scene",
            "cornell-area",
            "--technique",
            "barczak",
            "--param",
            "set=direct",
            "--resolution",
            "64x48",
            "--frames",
            "1",
            "--warmup",
            "0",
            "--timing",
            "stages",
        ],
        dir.path(),
    );
    let text = std::fs::read_to_string(dir.path().join("cornell-area-barczak.json")).unwrap();
    let result: RunResult = serde_json::from_str(&text).unwrap();
    let warned = result
        .warnings
        .iter()
        .find(|w| w.contains("negative"))
        .unwrap_or_else(|| panic!("no warning of negative irradiance: {:?}", result.warnings));
    let exr = dir.path().join("cornell-area-barczak-indirect.exr");
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &exr,
        |size, _| vec![[0f32; 3]; size.0 * size.1],
        |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = 64;
            px[pos.1 * w + pos.0] = [r, g, b];
        },
    )
    .unwrap();
    let pixels = &image.layer_data.channel_data.pixels;
    let negative = pixels.iter().filter(|p| p.iter().any(|c| *c < 0.0)).count();
    assert_eq!(
        negative,
        0,
        "{negative} negative pixels in {} ({warned})",
        exr.display()
    );
}

/// A run over every technique does not die for one that cannot take the scene: on the arena
/// (10,592 triangles, no recorded patches) with `barczak` allowed fewer charts than the
/// arena makes (`-p barczak.max-charts=10`), `barczak` is left out with its reason, on
/// standard error and in the summary table's notes, and the others run; named with
/// `--technique`, it is an error before any frame, and no results file is written. Caught by:
/// the run failing as a whole (as before), or leaving the technique out silently.
#[test]
fn a_run_over_every_technique_skips_one_that_cannot_take_the_scene() {
    let small = [
        "--scene",
        "gaitatzes-arena",
        "--resolution",
        "64x48",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--timing",
        "stages",
        "--no-images",
        "-p",
        "barczak.max-charts=10",
    ];
    let dir = tempfile::tempdir().unwrap();
    let o = support::GIBENCH
        .command()
        .arg("run")
        .args(small)
        .arg("--out")
        .arg(dir.path())
        .arg("--quiet")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("skipped barczak on gaitatzes-arena: ") && stderr.contains("patches"),
        "{stderr}"
    );
    assert!(!dir.path().join("gaitatzes-arena-barczak.json").exists());
    for t in ["direct", "keller-full", "laine", "ism", "gaitatzes"] {
        let f = dir.path().join(format!("gaitatzes-arena-{t}.json"));
        assert!(f.is_file(), "{} missing; {stderr}", f.display());
    }
    let md = std::fs::read_to_string(dir.path().join("gaitatzes-arena-summary.md")).unwrap();
    assert!(md.contains("Skipped barczak: "), "{md}");
    let text = std::fs::read_to_string(dir.path().join("gaitatzes-arena-skipped.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let list = v["skipped"].as_array().unwrap();
    assert_eq!(list.len(), 1, "{text}");
    assert_eq!(list[0]["technique"], "barczak", "{text}");
    assert!(
        list[0]["reason"].as_str().unwrap().contains("patches"),
        "{text}"
    );
    // The folder's results are still read as results (the list is not one).
    let o = support::GIBENCH
        .command()
        .arg("report")
        .arg(dir.path())
        .arg("--out")
        .arg(dir.path().join("report"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let named = tempfile::tempdir().unwrap();
    let o = support::GIBENCH
        .command()
        .arg("run")
        .args(small)
        .args(["--technique", "barczak", "--out"])
        .arg(named.path())
        .arg("--quiet")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("patches"),
        "{stderr}"
    );
    assert!(!named.path().join("gaitatzes-arena-barczak.json").exists());
    assert!(!named.path().join("gaitatzes-arena-skipped.json").exists());
}

/// A run over every technique that skips none removes an earlier run's list of skipped
/// techniques from its folder (a stale list would name a technique whose results are there).
#[test]
fn a_run_that_skips_nothing_leaves_no_list_of_skipped_techniques() {
    let dir = tempfile::tempdir().unwrap();
    let stale = dir.path().join("cornell-skipped.json");
    std::fs::write(&stale, r#"{"scene": "cornell", "skipped": []}"#).unwrap();
    let o = support::GIBENCH
        .command()
        .arg("run")
        .args(["--resolution", "64x48", "--frames", "1", "--warmup", "0"])
        .args(["--timing", "stages", "--no-images", "--quiet", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        dir.path().join("cornell-barczak.json").is_file(),
        "{stderr}"
    );
    assert!(!stale.exists(), "{stderr}");
}

/// A multi-frame quality run on the Cornell box with its walking bunny builds the static
/// mesh's tree once for the whole run (the techniques' CPU rays and every reference frame share
/// it) and the bunny's tree once per rendered reference frame (frames 1 to 3, then both pairs,
/// 1–2 and 2–3, again with the next seed for the flicker floor: three more rendered, frame 2's
/// second request read from the cache; then frames 1 to 3 with all bounces, the multi-bounce
/// component every run is also scored against: three more), and says so in the results
/// (`quality.reference_work`); run again over the same cache, it renders no reference and
/// builds no mover tree, and its reference images are the first run's. Catches the reference
/// building its own trees per frame again (its mover builds then go uncounted), a static tree
/// built more than once, and a second run that renders what the cache holds.
#[test]
fn quality_run_builds_the_static_tree_once_and_movers_per_frame() {
    use gibench_harness::measure::metrics::ReferenceWork;
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let run = |out: &str| {
        let out = tmp.path().join(out);
        #[rustfmt::skip]
        run_ok(
            &["--scene", "cornell-bunny", "--technique", "direct", "--resolution", "64x48",
              "--frames", "3", "--warmup", "1", "--timing", "stages", "--quality",
              "--quality-all", "--spp", "4", "--cache", cache.to_str().unwrap()],
            &out,
        );
        let r = RunResult::read(&out.join("cornell-bunny-direct.json")).unwrap();
        // The per-frame flicker plot draws the reference's floor beside the run's line.
        let svg = std::fs::read_to_string(out.join("cornell-bunny-flicker-per-frame.svg")).unwrap();
        assert!(
            svg.contains("flicker floor @ cornell-bunny"),
            "no floor line"
        );
        let json = out.join("cornell-bunny-direct.json");
        let png = std::fs::read(support::reference_image(&json, "-reference-frames.png")).unwrap();
        (
            r.quality.unwrap().reference_work.expect("reference_work"),
            png,
        )
    };
    let (first, png) = run("first");
    assert_eq!(
        first,
        ReferenceWork {
            rendered: 9,
            cached: 1,
            static_tree_builds: 1,
            mover_tree_builds: 9
        }
    );
    let (again, png_again) = run("again");
    assert_eq!(
        again,
        ReferenceWork {
            rendered: 0,
            cached: 10,
            static_tree_builds: 1,
            mover_tree_builds: 0
        }
    );
    assert!(png == png_again, "the cached references' images differ");
}

/// Catches: a terminal table over 120 columns in some timing mode (`run_ok` checks every line's
/// width in characters: the dash of a missing cell, U+2013, is one column but three bytes, so a
/// byte count reads 120-column lines with dashes as 124-126). Every technique at once, the
/// widest table, in each mode, with the error columns in one.
#[test]
fn the_terminal_table_fits_120_columns_in_every_timing_mode() {
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache").to_string_lossy().into_owned();
    for (i, timing) in ["stages", "frame", "both"].into_iter().enumerate() {
        #[rustfmt::skip]
        let mut args = vec!["--frames", "2", "--warmup", "3", "--resolution", "64x48",
                            "--no-images", "--timing", timing];
        if timing == "both" {
            args.extend(["--quality", "--spp", "4", "--cache", &cache]);
        }
        let out = run_ok(&args, &tmp.path().join(format!("r{i}")));
        assert!(
            out.contains("gaitatzes") && out.contains("barczak"),
            "{out}"
        );
    }
}

/// `run --equal-time`: each technique with a knob runs at the value its search kept, the
/// largest whose step fitted the budget (within `equal_time::FIT` of it), within the knob's
/// range; its results record the search (every step, the budget, the value), `direct` (no knob)
/// says so, and the equal-time table lists both with their errors. The frame times themselves
/// are the machine's (a benchmark, not asserted). Catches a run at the defaults after the
/// search, a kept value that did not fit, and a search left out of the results.
#[test]
fn equal_time_runs_each_technique_at_the_value_its_search_kept() {
    use gibench_papers::equal_time::{FIT, MAX_STEPS, REPEATS};
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    #[rustfmt::skip]
    let stdout = run_ok(
        &["--technique", "laine,direct", "--equal-time", "8ms", "--quality", "--resolution",
          "64x48", "--frames", "6", "--warmup", "3", "--timing", "frame", "--quality-pairs", "1",
          "--spp", "4", "--no-images", "--cache", cache.to_str().unwrap()],
        tmp.path(),
    );
    assert!(stdout.contains("Error at equal time"), "{stdout}");
    let laine = RunResult::read(&tmp.path().join("cornell-laine.json")).unwrap();
    let e = &laine.settings["equal_time"];
    let steps = e["steps"].as_array().unwrap();
    let ran = (steps.iter()).filter(|s| !s["frame_ms"].is_null()).count();
    assert!((1..=MAX_STEPS).contains(&ran), "{e}");
    let kept = e["value"].as_i64().unwrap();
    let fitted = (steps.iter())
        .filter(|s| s["frame_ms"].as_f64().is_some_and(|ms| ms <= FIT * 8.0))
        .map(|s| s["value"].as_i64().unwrap())
        .max();
    match fitted {
        Some(v) => {
            assert_eq!(kept, v, "{e}");
            // The kept value was timed again (and a run off the mark adds its timing): its
            // figure is its timings' median.
            let step = (steps.iter()).find(|s| s["value"] == kept).unwrap();
            let mut t: Vec<f64> = (step["timings"].as_array().unwrap().iter())
                .map(|t| t.as_f64().unwrap())
                .collect();
            assert!(t.len() >= REPEATS, "{e}");
            t.sort_by(f64::total_cmp);
            let n = t.len();
            let median = if n % 2 == 1 {
                t[n / 2]
            } else {
                0.5 * (t[n / 2 - 1] + t[n / 2])
            };
            assert_eq!(step["frame_ms"].as_f64(), Some(median), "{e}");
        }
        // Nothing fitted this machine's 8 ms: the smallest value that ran, said.
        None => assert!(
            matches!(e["end"].as_str(), Some("min" | "over budget")),
            "{e}"
        ),
    }
    assert_eq!(laine.parameters["vpls"], serde_json::json!(kept));
    assert_eq!(e["budget_ms"], 8.0);
    let direct = RunResult::read(&tmp.path().join("cornell-direct.json")).unwrap();
    assert!(direct.settings["equal_time"]["knob"].is_null());
    let csv = std::fs::read_to_string(tmp.path().join("cornell-equal-time.csv")).unwrap();
    assert!(
        csv.contains(&format!("cornell,laine,vpls={kept}"))
            && csv.contains("cornell,direct,– (no knob)"),
        "{csv}"
    );
}
