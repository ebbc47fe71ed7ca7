//! What does not fit the image or the device: found before the first frame, or reported
//! (half-float saturation) instead of hidden.

use super::*;

/// Irradiance past the half-float limit of the irradiance buffers is reported, in the results
/// file and on standard error, instead of being clamped silently.
#[test]
fn half_float_saturation_is_reported() {
    let tmp = tempfile::tempdir().unwrap();
    let d = descriptor(tmp.path(), "bright.json", |v| {
        v["light"]["power"] = serde_json::json!([1e12, 1e12, 1e12])
    });
    let out = tmp.path().join("out");
    let o = one_direct_frame("64x48", Some(&d), &out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.contains("half-float limit"), "{stderr}");
    let name = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| {
            p.extension().is_some_and(|x| x == "json") && !p.to_string_lossy().contains("summary")
        })
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(name).unwrap()).unwrap();
    assert!(v["warnings"][0]
        .as_str()
        .unwrap()
        .contains("direct irradiance"));
    // The ordinary scene gets no such warning.
    let o = one_direct_frame("64x48", None, tmp.path().join("plain"));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("half-float"));
}

/// What does not fit the device is found before the first technique's first frame: a VPL atlas
/// too large for the adapter fails at once even after a long `direct` run in the same command
/// (3000 frames, tens of seconds), and a cube-map atlas past the texture limit names
/// `--shadow-size`.
#[test]
fn device_limits_are_checked_before_any_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let start = std::time::Instant::now();
    let o = support::GIBENCH
        .command()
        .args([
            "run",
            "--technique",
            "direct,laine",
            "--frames",
            "3000",
            "--quiet",
        ])
        .args([
            "--param",
            "vpl-map-size=4096",
            "--param",
            "vpls=1024",
            "--out",
        ])
        .arg(tmp.path().join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("do not fit"),
        "{stderr}"
    );
    assert!(
        start.elapsed() < std::time::Duration::from_secs(15),
        "found only after {:?}",
        start.elapsed()
    );
    fails(&["--shadow-size", "8000"], "parameter 'shadow-size'");
}

/// Parameters past what the image or the device allows are refused by name before any frame:
/// a tile grid with more tiles along an axis than the image has pixels (before: an all-zero
/// image for `laine` and `ism`, +20 % with hot spots for `keller-full`), an `ism` point pool or
/// reflective shadow map larger than the adapter's largest storage buffer (before: a raw GPU
/// validation error after seconds of sampling, or the blame put on `vpl-map-size`).
#[test]
fn parameters_past_the_image_or_the_device() {
    for t in ["laine", "ism", "keller-full"] {
        fails(
            &[
                "--technique",
                t,
                "--resolution",
                "64x48",
                "--param",
                "tiles=64x64",
            ],
            "parameter 'tiles'",
        );
    }
    fails(
        &[
            "--technique",
            "laine",
            "--resolution",
            "64x48",
            "--param",
            "tiles=8x49",
        ],
        "8x49 tiles on a 64x48 image",
    );
    let gpu = gibench_harness::gpu::GpuContext::new(&Default::default()).expect("an adapter");
    let limits = gpu.device.limits();
    let max = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    drop(gpu);
    if (1u64 << 24) * 16 > max {
        fails(
            &[
                "--technique",
                "ism",
                "--resolution",
                "32x24",
                "--param",
                "point-pool=16777216",
                "--param",
                "points-per-vpl=1",
            ],
            "parameter 'point-pool'",
        );
    } else {
        gibench_test_support::say_uncaptured(&format!(
            "cli_errors: this adapter's storage buffers ({max} bytes) take ism's largest point pool; the pool's check was not tried"
        ));
    }
    if 6 * 2048u64 * 2048 * 16 > max {
        fails(
            &[
                "--technique",
                "ism",
                "--resolution",
                "32x24",
                "--param",
                "rsm-size=2048",
            ],
            "parameter 'rsm-size'",
        );
    }
}
