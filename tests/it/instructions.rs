//! The instruction-count gate (`gibench instructions`): five runs in a row against a baseline
//! written by the same build report no regression; a kernel slowed on purpose
//! (`GIBENCH_TEST_SLOW_KERNEL`, which runs its body twice) is reported as a regression, and
//! only it. Needs valgrind; without it the test says so on standard error and checks nothing
//! else.

use crate::support;

use std::process::Command;

const KERNELS: &str = "domain-delete-insert-disc-256,bvh-shadow-cornell";

fn gate(baseline: &std::path::Path, slow: Option<&str>, write: bool) -> (bool, String) {
    let mut c = support::GIBENCH.command();
    c.args(["instructions", "--kernels", KERNELS, "--baseline"])
        .arg(baseline);
    if write {
        c.arg("--write");
    }
    match slow {
        Some(k) => c.env("GIBENCH_TEST_SLOW_KERNEL", k),
        None => c.env_remove("GIBENCH_TEST_SLOW_KERNEL"),
    };
    let o = c.output().unwrap();
    (
        o.status.success(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ),
    )
}

#[test]
fn the_gate_reports_a_slowed_kernel_and_nothing_else() {
    if Command::new("valgrind").arg("--version").output().is_err() {
        gibench_test_support::say_uncaptured(
            "instructions: valgrind is not installed; the instruction-count gate was not checked",
        );
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let baseline = tmp.path().join("instructions.json");
    let (ok, out) = gate(&baseline, None, true);
    assert!(ok, "{out}");
    for i in 0..5 {
        let (ok, out) = gate(&baseline, None, false);
        assert!(
            ok && !out.contains("instruction-count regression"),
            "unchanged run {i}: {out}"
        );
    }
    let (ok, out) = gate(&baseline, Some("bvh-shadow-cornell"), false);
    assert!(!ok, "{out}");
    assert!(
        out.contains("regression beyond 2.0 %: bvh-shadow-cornell (+"),
        "{out}"
    );
    assert!(!out.contains("domain-delete-insert-disc-256 (+"), "{out}");
}
