//! Memory stays flat over long runs: for every registered technique on the Cornell box, on
//! every portable backend present, the process's resident set grows by less than
//! [`MAX_GROWTH_MB`] in at least one of two 25-frame windows (frames 20–45 and 45–70; frame
//! timing, the benchmark's own loop). Steady growth shows in both windows; a one-off step
//! (glibc giving a worker thread its own malloc arena, seen once as 35 MB) in only one. The
//! window is the shortest in which the smallest growth below still clears the bound by a
//! margin: 0.7 MB per frame is 17.5 MB per window, 1.46 times the bound.
//!
//! What it catches: lavapipe (Mesa 22.3) compiling a fresh, never-freed shader variant for
//! every draw whose control flow reads a uniform, which grew the process by 0.7 MB per frame
//! (`direct`) to 1.7 MB per frame (`laine`) before parameter blocks became read-only storage
//! buffers (`passes::params_entry`); also any per-frame resource a technique forgets to reuse.
//! Linux only (reads `/proc/self/status`).
//!
//! A test binary of its own, not a module of `tests/it/`: it needs its own process, since it
//! measures the process's resident set, which every other test running beside it would grow.

use gibench_papers::registry;

use gibench_harness::gpu::profiler::{ProfileMode, Profiler};
use gibench_harness::run::runner::{process_memory_mb, Harness, TimingMode};
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;

const MAX_GROWTH_MB: f64 = 12.0;
const SETTLE: u32 = 20;
const WINDOW: u32 = 25;
const MEASURED: u32 = 2 * WINDOW;

/// The resident set size in MB (`VmRSS`).
fn rss_mb() -> f64 {
    process_memory_mb("VmRSS").expect("VmRSS in /proc/self/status")
}

#[test]
fn memory_stays_flat_over_long_runs() {
    let present = gibench_test_support::backends_for("memory");
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let config = gibench_test_support::one_frame([96, 72])
        .frames(MEASURED)
        .warmup(SETTLE)
        .timing(TimingMode::Frame)
        .shadow_size(128)
        .build();
    let mut failures = Vec::new();
    for backend in present {
        let gpu = gibench_test_support::backend_context(backend);
        let h = Harness::new(&gpu, &scene, &config).unwrap();
        for info in registry::all() {
            let params = info.parse_params(&[]).expect("defaults parse");
            let prepared = h.prepare(info, &params, &config).expect("prepare");
            let (mut t, compose) = h.build(info, &params, &config, &prepared).unwrap();
            let mut profiler = Profiler::new(&gpu, ProfileMode::Frame);
            let mut marks = Vec::new();
            for f in 0..SETTLE + MEASURED {
                if f == SETTLE || f == SETTLE + WINDOW {
                    gpu.flush().unwrap();
                    marks.push(rss_mb());
                }
                let frame = h.clock.frame(f);
                h.render_frame(t.as_mut(), &compose, &mut profiler, &frame, true)
                    .unwrap();
            }
            profiler.finish(&gpu).unwrap();
            marks.push(rss_mb());
            let (a, b) = (marks[1] - marks[0], marks[2] - marks[1]);
            eprintln!(
                "{backend} {}: {a:.1} MB, then {b:.1} MB over two {WINDOW}-frame windows",
                info.name
            );
            if a.min(b) >= MAX_GROWTH_MB {
                failures.push(format!(
                    "{backend} {}: resident set grew {a:.1} MB and then {b:.1} MB over two {WINDOW}-frame windows (bound {MAX_GROWTH_MB} MB in either)",
                    info.name
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
