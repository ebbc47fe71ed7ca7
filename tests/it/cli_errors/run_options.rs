//! `run` and `sweep` options refused before anything runs: unknown techniques and parameters,
//! bad sizes and counts, parameters given twice, quality options without `--quality`.

use super::*;

#[test]
fn unknown_technique() {
    fails(&["--technique", "direct,nope"], "unknown technique 'nope'");
}

#[test]
fn unknown_parameter() {
    fails(&["--technique", "direct", "--param", "vpls=64"], "vpls");
    fails(
        &["--technique", "direct", "--param", "direct.vpls=64"],
        "technique 'direct' has no such parameter",
    );
}

#[test]
fn bad_resolutions() {
    fails(&["--resolution", "0x192"], "resolution");
    fails(&["--resolution", "100000x192"], "exceeds");
    fails(&["--resolution", "256by192"], "WIDTHxHEIGHT");
}

#[test]
fn zero_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let o = support::GIBENCH
        .command()
        .args(["run", "--frames", "0", "--quiet", "--out"])
        .arg(tmp.path().join("out"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("frames") && stderr.contains("got 0"),
        "{stderr}"
    );
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn bad_timing_mode_and_backend() {
    fails(&["--timing", "sometimes"], "timing");
    fails(&["--backend", "glide"], "unknown backend 'glide'");
}

/// Timing whole frames with fewer warm-up frames than the frames in flight plus one would let
/// the first (fill) frame's work land in a measured interval; `laine`'s recalc-min above its
/// recalc-max would drain its VPL count. Both are refused before anything runs.
#[test]
fn short_warmup_and_draining_laine_parameters() {
    fails(&["--warmup", "1"], "warmup");
    fails(
        &[
            "--technique",
            "laine",
            "--param",
            "recalc-min=9",
            "--warmup",
            "3",
        ],
        "laine.recalc-min",
    );
}

/// Overflowing frame counts, a descriptor name that would climb out of the output folder, a
/// technique or sweep value listed twice, `--assets` that is not a folder: clear errors, nothing
/// written.
#[test]
fn overflow_names_duplicates_and_assets() {
    fails(&["--frames", "4294967295"], "frames");
    fails(&["--first-frame", "4294967295"], "first-frame");
    let tmp = tempfile::tempdir().unwrap();
    for bad in ["../../x", "", ".hidden", "a/b"] {
        let d = descriptor(tmp.path(), "named.json", |v| {
            v["name"] = serde_json::json!(bad)
        });
        fails(&["--scene", d.to_str().unwrap()], "name");
    }
    fails(&["--technique", "direct,direct"], "listed twice");
    fails(&["--assets", "/no/such/folder"], "assets");
    let file = tmp.path().join("not-a-folder");
    std::fs::write(&file, b"x").unwrap();
    fails(&["--assets", file.to_str().unwrap()], "not a folder");
    let o = support::GIBENCH
        .command()
        .args([
            "sweep",
            "--technique",
            "keller-full",
            "--sweep",
            "vpls=8,8",
            "--frames",
            "2",
        ])
        .arg("--out")
        .arg(tmp.path().join("sweep"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("listed twice"));
    let o = support::GIBENCH
        .command()
        .args(["reproduce", "laine-dispersion", "--frames", "0"])
        .arg("--out")
        .arg(tmp.path().join("repro"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("frames") && !stderr.contains("panicked"));
    assert!(!tmp.path().join("repro").exists());
}

/// A parameter given twice for one technique, or both with `--param` and as the swept one, is
/// refused naming it; the same name for two different techniques is fine.
#[test]
fn parameter_given_twice() {
    fails(&["-p", "vpls=8", "-p", "vpls=16"], "given twice");
    fails(
        &[
            "--technique",
            "laine,keller-full",
            "-p",
            "vpls=8",
            "-p",
            "laine.vpls=16",
        ],
        "parameter 'laine.vpls': given twice",
    );
    // Two techniques' own values pass the parameter check (and fail later, on the scene).
    fails(
        &[
            "--technique",
            "laine,keller-full",
            "-p",
            "laine.vpls=8",
            "-p",
            "keller-full.vpls=16",
            "--scene",
            "atlantis",
        ],
        "unknown scene 'atlantis'",
    );
    let tmp = tempfile::tempdir().unwrap();
    command_fails(
        tmp.path(),
        &[],
        &[
            "sweep",
            "--technique",
            "keller-full",
            "--sweep",
            "vpls=8,16",
            "-p",
            "vpls=32",
            "--out",
            "out",
        ],
        &["parameter 'vpls'", "given both as --param"],
    );
}

/// Sweep values are compared as the technique reads them: `08` and `8`, `1` and `1.0` are one
/// setting, refused naming both values.
#[test]
fn sweep_values_compared_as_parsed() {
    let tmp = tempfile::tempdir().unwrap();
    for (technique, sweep, values) in [
        ("keller-full", "vpls=08,8", ["'08'", "'8'"]),
        ("laine", "clamp=1,1.0", ["'1'", "'1.0'"]),
    ] {
        command_fails(
            tmp.path(),
            &[],
            &[
                "sweep",
                "--technique",
                technique,
                "--sweep",
                sweep,
                "--out",
                "out",
            ],
            &["listed twice", values[0], values[1]],
        );
    }
    assert!(!tmp.path().join("out").exists());
}

/// An unknown backend from the environment names `GIBENCH_BACKEND` and the accepted values.
#[test]
fn backend_from_the_environment() {
    let tmp = tempfile::tempdir().unwrap();
    command_fails(
        tmp.path(),
        &[("GIBENCH_BACKEND", "bogus")],
        &["run", "--frames", "2", "--quiet", "--out", "out"],
        &["GIBENCH_BACKEND", "'bogus'", "vulkan, gl, metal, dx12"],
    );
    assert!(!tmp.path().join("out").exists());
}

/// Options of the error measurement given without `--quality` are refused (they used to be
/// ignored: nothing was compared), as are zero frame pairs, and reference sample and bounce
/// counts past their limits (a run that would not end in hours), before any work. The sizes
/// are tiny, so that without the checks each command would succeed at once.
#[test]
fn quality_options_need_quality_and_reference_sizes_have_limits() {
    let tmp = tempfile::tempdir().unwrap();
    let run = [
        "run",
        "--technique",
        "direct",
        "--resolution",
        "16x12",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--timing",
        "stages",
        "--no-images",
        "--quiet",
        "--spp",
        "1",
        "--no-cache",
        "--out",
        "o",
    ];
    for (extra, expect) in [
        (
            &["--quality-all"][..],
            &["quality-all", "add --quality"][..],
        ),
        (
            &["--quality-pairs", "3"][..],
            &["quality-pairs", "add --quality"][..],
        ),
        (
            &["--quality-reference", "direct"][..],
            &["quality-reference", "add --quality"][..],
        ),
        (
            &["--quality", "--quality-pairs", "0"][..],
            &["quality-pairs", "at least one"][..],
        ),
        (
            &["--equal-time", "0ms"][..],
            &["equal-time", "milliseconds above 0", "'0ms'"][..],
        ),
        (
            &["--equal-time", "soon"][..],
            &["equal-time", "e.g. 33ms", "'soon'"][..],
        ),
    ] {
        let mut args = run.to_vec();
        args.extend(extra);
        command_fails(tmp.path(), &[], &args, expect);
    }
    #[rustfmt::skip]
    command_fails(
        tmp.path(),
        &[],
        &["sweep", "--technique", "laine", "--sweep", "vpls=8,16", "--equal-time", "9ms", "--out", "o"],
        &["equal-time", "applies to gibench run"],
    );
    let reference = [
        "reference",
        "--resolution",
        "1x1",
        "--no-cache",
        "--out",
        "r",
    ];
    for (extra, expect) in [
        (["--spp", "65537"], &["spp", "1..=65536"][..]),
        (["--bounces", "65"], &["bounces", "1..=64"][..]),
    ] {
        let mut args = reference.to_vec();
        args.extend(extra);
        command_fails(tmp.path(), &[], &args, expect);
    }
    assert!(!tmp.path().join("o").exists() && !tmp.path().join("r").exists());
}

/// The component each run is compared with follows its parameters (`keller-full bounces=3`
/// computes several bounces, `barczak set=direct` the area light's direct light), and
/// `--quality-reference` naming another one warns, naming the technique (checked at planning:
/// an unwritable `--out` then stops the run before any work). Caught by: the component
/// declared once per technique (no warning for bounces=3 against one bounce, a false one for
/// set=direct against direct).
#[test]
fn quality_reference_other_than_the_computed_component_warns() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("file"), b"").unwrap();
    let planned = |args: &[&str]| {
        let mut all = vec!["run", "--quality", "--out", "file/out"];
        all.extend_from_slice(args);
        command_fails(tmp.path(), &[], &all, &["parameter 'out'"])
    };
    let warned = |stderr: &str, technique: &str| {
        stderr
            .lines()
            .any(|l| l.starts_with("warning: --quality-reference") && l.contains(technique))
    };
    let e = planned(&[
        "--technique",
        "keller-full",
        "--param",
        "bounces=3",
        "--quality-reference",
        "one-bounce",
    ]);
    assert!(warned(&e, "keller-full computes the multi-bounce"), "{e}");
    let e = planned(&[
        "--technique",
        "keller-full",
        "--quality-reference",
        "one-bounce",
    ]);
    assert!(!warned(&e, "keller-full"), "{e}");
    let e = planned(&[
        "--technique",
        "barczak",
        "--param",
        "set=direct",
        "--quality-reference",
        "direct",
    ]);
    assert!(!warned(&e, "barczak"), "{e}");
    let e = planned(&[
        "--technique",
        "barczak",
        "--param",
        "set=direct",
        "--quality-reference",
        "multi-bounce",
    ]);
    assert!(warned(&e, "barczak computes the direct"), "{e}");
}
