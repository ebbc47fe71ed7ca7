//! The profiler's CPU stages: with stage timing their CPU time counts every thread of the
//! process (a stage whose work runs across cores, as `laine`'s management does), with frame
//! timing only the calling thread's (earlier frames' GPU work may run beside it).

use gibench_harness::calibrate::thread_cpu_ms;
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::profiler::{ProfileMode, Profiler};

/// Keeps the calling thread busy until it has used `ms` of CPU time.
fn burn(ms: f64) {
    let start = thread_cpu_ms().expect("a per-thread CPU clock");
    let mut x = 1u64;
    while thread_cpu_ms().unwrap() - start < ms {
        for _ in 0..1000 {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
    }
}

#[test]
fn cpu_stages_count_every_threads_work_with_stage_timing_and_the_callers_with_frame_timing() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    for mode in [ProfileMode::Stages, ProfileMode::Frame] {
        let mut p = Profiler::new(&gpu, mode);
        p.begin_frame(true);
        // Two helper threads use 40 ms of CPU each while the calling thread waits for them.
        p.cpu_stage("parallel", || {
            std::thread::scope(|s| {
                for _ in 0..2 {
                    s.spawn(|| burn(40.0));
                }
            })
        });
        p.end_frame(&gpu).unwrap();
        p.finish(&gpu).unwrap();
        let r = p
            .stage_results()
            .into_iter()
            .find(|s| s.name == "parallel")
            .expect("the stage is recorded");
        let cpu = r.cpu_ms.expect("CPU time recorded").median;
        match mode {
            ProfileMode::Stages => assert!(
                cpu >= 75.0,
                "stage timing: {cpu} ms of CPU for 80 ms of work on two threads"
            ),
            ProfileMode::Frame => assert!(
                cpu < 20.0,
                "frame timing: {cpu} ms of CPU for a thread that only waited"
            ),
        }
    }
}
