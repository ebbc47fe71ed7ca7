//! The roofline's bound kernels ([`gibench_harness::measure::roofline`]): the copy moves what it claims,
//! the FMA kernel does the operations it claims, and the bounds are those counts over the
//! kernels' times. On every portable backend present.

use gibench_harness::measure::roofline::{roofline, Binding, BoundTimer, StageCost};
use gibench_harness::run::bounds::{
    copy_pattern, fma_model, measure_bounds, BoundKernels, FmaParams, FMA_WORKGROUP,
};
use gibench_test_support::gpu::{gpus, GpuTest};

/// The copy kernel over a buffer of B bytes writes every one of its B / 16 elements with the
/// source's pattern, and counts 2B bytes moved (B read, B written). Catches a copy that skips
/// elements (a grid-stride loop that stops early, a dispatch too small for the buffer: the
/// bandwidth would then count bytes never moved), one that reads the wrong element, and a
/// byte count of B or 4B. B is 3 MiB + 16 bytes: not a multiple of the workgroup's span, so
/// the tail is checked too.
#[test]
fn the_copy_kernel_moves_every_byte_it_counts() {
    for (backend, gpu) in gpus("the_copy_kernel_moves_every_byte_it_counts") {
        let bytes = (3 << 20) + 16;
        let kernels = BoundKernels::new(&gpu, bytes).unwrap();
        let t = kernels.copy(&gpu).unwrap();
        assert!(t.ms > 0.0, "{backend}: a copy timed at {} ms", t.ms);
        assert_eq!(kernels.copy_bytes(), 2.0 * bytes as f64, "{backend}");
        let out = kernels.read_copy(&gpu).unwrap();
        assert_eq!(out.len() as u64, bytes / 16, "{backend}");
        for (i, v) in out.iter().enumerate() {
            assert_eq!(
                *v,
                copy_pattern(i as u32),
                "{backend}: element {i} of the copy"
            );
        }
    }
}

/// The FMA kernel's output equals the same chains run on the CPU, for two chain lengths: each
/// invocation really ran `iterations` steps of its eight vec4 chains, so a run does
/// `invocations × iterations × 8 × 4` FMAs, the 2 operations each that `fma_ops` counts. The
/// chain x ← x·1 + 1 keeps integers (exact whether or not the device fuses), and its result
/// is the start plus the step count, so a kernel doing fewer steps (a loop the compiler cut
/// short, a wrong bound) or skipping invocations fails, as does an `fma_ops` that is not the
/// count of the kernel's FMAs × 2.
#[test]
fn the_fma_kernel_does_the_operations_it_counts() {
    for (backend, gpu) in gpus("the_fma_kernel_does_the_operations_it_counts") {
        let kernels = BoundKernels::new(&gpu, 1 << 20).unwrap();
        for (workgroups, iterations) in [(3, 100), (5, 1000)] {
            let params = FmaParams {
                a: 1.0,
                b: 1.0,
                iterations,
                pad: 0,
            };
            kernels.fma(&gpu, workgroups, &params).unwrap();
            let n = (workgroups * FMA_WORKGROUP) as usize;
            let out = kernels.read_fma(&gpu, n).unwrap();
            for (i, v) in out.iter().enumerate() {
                assert_eq!(
                    *v,
                    fma_model(i as u32, &params),
                    "{backend}: invocation {i}, {iterations} steps"
                );
            }
            // Eight chains of vec4 FMAs per step, two operations each.
            let fmas = n as f64 * iterations as f64 * 8.0 * 4.0;
            assert_eq!(BoundKernels::fma_ops(workgroups, &params), 2.0 * fmas);
        }
        // The model itself: start s + lane + 4c, plus one per step, summed over 8 chains.
        let p = FmaParams {
            a: 1.0,
            b: 1.0,
            iterations: 10,
            pad: 0,
        };
        assert_eq!(fma_model(2, &p)[1], 8.0 * (2.0 + 1.0 + 10.0) + 4.0 * 28.0);
    }
}

/// The measured bounds are the kernels' counts over their times: bandwidth = bytes read and
/// written / copy time, rate = operations / FMA time. Catches a bandwidth over the wrong byte count or
/// time unit (ticks not scaled by the timestamp period, ms taken for s), a timer that is not
/// the one recorded, and a stage's roofline that does not follow time_min = max(bytes / BW,
/// ops / rate), efficiency = time_min / time.
#[test]
fn the_bounds_are_the_kernels_counts_over_their_times() {
    for (backend, gpu) in gpus("the_bounds_are_the_kernels_counts_over_their_times") {
        let b = measure_bounds(&gpu).unwrap();
        let expected_timer = if gpu.timestamps {
            BoundTimer::Timestamps
        } else {
            BoundTimer::Wall
        };
        assert_eq!(b.timer, expected_timer, "{backend}");
        let rel = |a: f64, e: f64| ((a - e) / e).abs() < 1e-12;
        assert!(
            rel(b.bandwidth(), b.copy_bytes / (b.copy_ms / 1e3)),
            "{b:?}"
        );
        assert!(rel(b.ops_per_s(), b.fma_ops / (b.fma_ms / 1e3)), "{b:?}");
        assert!(b.copy_ms > 0.0 && b.fma_ms > 0.0, "{backend}: {b:?}");

        // A stage of exactly one bandwidth-second's bytes and half a rate-second's
        // operations, measured at 4 s: memory-bound, time_min 1 s, 25 % efficient.
        let cost = StageCost {
            bytes_read: b.bandwidth() * 0.75,
            bytes_written: b.bandwidth() * 0.25,
            ops: b.ops_per_s() * 0.5,
        };
        let r = roofline(&cost, &b, 4000.0).unwrap();
        assert_eq!(r.binding, Binding::Memory);
        assert!(rel(r.time_min_ms, 1000.0), "{r:?}");
        assert!(rel(r.efficiency, 0.25), "{r:?}");
        assert!(rel(r.bandwidth_fraction, 0.25), "{r:?}");
        assert!(rel(r.ops_fraction, 0.125), "{r:?}");
        assert!(roofline(&cost, &b, 0.0).is_none());
    }
}

/// With timestamp queries (a declared need: backends without them are skipped, saying so), a
/// kernel's time lies within its flushed submission's wall time. Catches ticks not scaled by
/// the timestamp period and a time taken from another kernel's queries.
#[test]
fn a_kernels_timestamps_lie_within_its_submission() {
    GpuTest::new("a_kernels_timestamps_lie_within_its_submission")
        .features(gibench_harness::wgpu::Features::TIMESTAMP_QUERY)
        .run(|backend, gpu| {
            let kernels = BoundKernels::new(gpu, 1 << 20).unwrap();
            let t = kernels.copy(gpu).unwrap();
            assert!(
                t.ms > 0.0 && t.ms <= t.wall_ms,
                "{backend}: kernel {} ms, its submission {} ms",
                t.ms,
                t.wall_ms
            );
        });
}
