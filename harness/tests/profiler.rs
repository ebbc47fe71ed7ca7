//! The profiler's CPU stages: in both timing modes their CPU time counts the calling thread and
//! every worker of rayon's pool (a stage whose work runs across cores, as `laine`'s management
//! does), and no other thread of the process (the GPU driver's, which on lavapipe and llvmpipe
//! run the GPU's work on the CPU).
//!
//! A test binary of its own, not a module of `tests/it/`: it needs its own process, since it
//! sums the CPU time of every worker of rayon's global pool, to which any other test's parallel
//! work in the same process would add.

use gibench_harness::gpu::profiler::{ProfileMode, Profiler};
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::measure::calibrate::thread_cpu_ms;

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

/// A stage whose work is 40 ms of CPU on each of rayon's N workers and on the calling thread
/// (N + 1 threads' clocks each advance by at least 40 ms: a bound by construction, whatever
/// else the machine runs) records at least (N + 1) × 40 ms less 5 % in both modes; a thread
/// outside the pool (as a GPU driver's) that burns 200 ms during the stage adds nothing: the
/// stage records less than (N + 1) × 40 + 100 ms (the margin, half that thread's work, covers
/// rayon's workers spinning before they sleep). Catches a stage timed by the calling thread's
/// clock alone (it records 40 ms, as frame timing did) and one timed by the process's clock
/// (it counts the outside thread, as stage timing did).
#[test]
fn cpu_stages_count_the_calling_thread_and_rayons_workers_and_no_other_thread() {
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    let workers = rayon::current_num_threads();
    let least = (workers + 1) as f64 * 40.0;
    for mode in [ProfileMode::Stages, ProfileMode::Frame] {
        let mut p = Profiler::new(&gpu, mode);
        p.begin_frame(true);
        p.cpu_stage("parallel", || {
            std::thread::scope(|s| {
                s.spawn(|| burn(200.0));
                rayon::broadcast(|_| burn(40.0));
                burn(40.0);
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
        assert!(
            cpu >= 0.95 * least,
            "{mode:?}: {cpu} ms of CPU for 40 ms on each of {workers} workers and the caller"
        );
        assert!(
            cpu < least + 100.0,
            "{mode:?}: {cpu} ms of CPU: a thread outside the pool was counted"
        );
    }
}
