//! The roofline end to end: a run stores the device's bounds and its stages' declared costs,
//! `gibench report --detailed` prints each GPU stage's fraction of the bounds, and a stage
//! slowed on purpose (the test hook `GIBENCH_TEST_SLOW_STAGE`, which adds to the stage's
//! flushed wall time) shows a lower fraction.

use crate::support;

use std::path::Path;

use gibench_harness::measure::results::RunResult;
use gibench_harness::measure::roofline::roofline;

/// `direct` on the Cornell box, 3 frames of stage timing at 64x48, into `out`; with the hook
/// adding `slow_ms` to `direct-light` when given.
fn run_direct(out: &Path, slow_ms: Option<u32>) -> RunResult {
    let mut c = support::GIBENCH.command();
    c.args([
        "run",
        "--technique",
        "direct",
        "--frames",
        "3",
        "--warmup",
        "1",
    ])
    .args(["--timing", "stages", "--resolution", "64x48"])
    .args(["--quiet", "--no-images", "--out"])
    .arg(out);
    match slow_ms {
        Some(ms) => c.env("GIBENCH_TEST_SLOW_STAGE", format!("direct-light:{ms}")),
        None => c.env_remove("GIBENCH_TEST_SLOW_STAGE"),
    };
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    RunResult::read(&out.join("cornell-direct.json")).unwrap()
}

/// `gibench report --detailed` of the run in `dir`: its text, and the last column ("eff %") of
/// `stage`'s row in the roofline table (`None` for "–").
fn reported_efficiency(dir: &Path, out: &Path, stage: &str) -> (String, Option<f64>) {
    let o = support::GIBENCH.run_ok(&[
        "report".as_ref(),
        dir.as_os_str(),
        "--detailed".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let row = text
        .lines()
        .skip_while(|l| !l.contains("stage efficiency (roofline)"))
        .find(|l| l.split_whitespace().next() == Some(stage))
        .unwrap_or_else(|| panic!("no {stage} row in the roofline table:\n{text}"))
        .to_string();
    let eff = row.split_whitespace().last().and_then(|v| v.parse().ok());
    (text, eff)
}

/// Base run against one with 40 ms added to `direct-light`. Catches: bounds or costs not
/// stored in the results; an efficiency taken from the GPU timestamps instead of the tables'
/// flushed wall time (the hook adds to the wall time only, so the fraction would not drop); a
/// report that does not print the roofline table, its bounds or the "–" of a stage without a
/// cost (every GPU stage declares one now, so the slowed run's file is written again without
/// `compose`'s: a report that took another stage's cost, or showed 0, for it fails).
#[test]
fn a_slowed_stage_shows_a_lower_fraction_of_the_bounds() {
    let tmp = tempfile::tempdir().unwrap();
    let base = run_direct(&tmp.path().join("base"), None);
    let slow = run_direct(&tmp.path().join("slow"), Some(40));
    for r in [&base, &slow] {
        assert!(r.device_bounds.is_some());
        assert!(r.stage_costs.contains_key("gbuffer"), "{:?}", r.stage_costs);
        assert!(r.stage_costs.contains_key("direct-light"));
        assert!(r.stage_costs.contains_key("compose"));
    }
    // 64x48 pixels, 12 bytes read and 8 written each (the declaration in runner.rs).
    let declared = base.stage_costs["direct-light"];
    assert_eq!(declared.bytes(), 64.0 * 48.0 * 20.0);

    let (_, e_base) = reported_efficiency(
        &tmp.path().join("base"),
        &tmp.path().join("rb"),
        "direct-light",
    );
    let (text, e_slow) = reported_efficiency(
        &tmp.path().join("slow"),
        &tmp.path().join("rs"),
        "direct-light",
    );
    let (e_base, e_slow) = (
        e_base.expect("a base efficiency"),
        e_slow.expect("a slowed efficiency"),
    );
    // The slowed stage's time is at least the 40 ms added: its efficiency is at most its
    // time_min over 40 ms (in percent, as printed to one decimal), and below the base run's.
    let b = slow.device_bounds.as_ref().unwrap();
    let time_min = roofline(&declared, b, 1.0).unwrap().time_min_ms;
    assert!(
        e_slow <= 100.0 * time_min / 40.0 + 0.05,
        "{e_slow} % > {time_min} / 40 ms"
    );
    assert!(e_slow < e_base, "slowed {e_slow} %, base {e_base} %");
    // Only direct-light is slowed.
    let g = slow.stage("gbuffer").unwrap().best_ms().unwrap();
    assert!(g < 40.0, "gbuffer {g} ms");
    assert!(
        text.contains("direct @ cornell: stage efficiency (roofline)"),
        "{text}"
    );
    assert!(text.contains("Bounds measured on this device"), "{text}");
    let (_, compose) =
        reported_efficiency(&tmp.path().join("slow"), &tmp.path().join("rs"), "compose");
    assert!(compose.is_some(), "compose declares a cost: {compose:?}");
    // The same results without compose's cost (as a file from before it declared one).
    let mut undeclared = slow.clone();
    assert!(undeclared.stage_costs.remove("compose").is_some());
    let edited = tmp.path().join("edited");
    std::fs::create_dir(&edited).unwrap();
    undeclared
        .write(&edited.join("cornell-direct.json"))
        .unwrap();
    let (_, compose) = reported_efficiency(&edited, &tmp.path().join("re"), "compose");
    assert_eq!(compose, None, "a stage without a cost shows \"–\"");
    let (_, direct) = reported_efficiency(&edited, &tmp.path().join("re2"), "direct-light");
    assert!(direct.is_some(), "the other stages keep their fractions");
}
