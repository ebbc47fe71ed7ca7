//! The CPU thread pool every parallel section shares (rayon's global pool), with the thread
//! that sets it up as one of its workers.
//!
//! A parallel section started from a thread outside the pool hands all of its work to the
//! pool's workers and sleeps until they finish; when the workers are asleep too, every section
//! pays for waking one and then for being woken, and on a virtual machine an idle virtual CPU
//! can take hundreds of microseconds to wake. Laine's VPL management runs two or three such
//! sections a frame (validity rays, miss rays, creation rays from 64 on): called from outside
//! the pool, its median frame at 1024 VPLs (omni) on Sibenik took 0.43 ms wall on the 2-core
//! development machine, its p99 1.3 to 2.0 times that; with the calling thread a worker,
//! 0.35 ms and 1.2 to 1.3 times (three runs each, alternating; `results/laine` holds the
//! latter). A worker runs its own first part at once and takes back any part no other worker
//! has taken yet, so a slow wake-up costs at most the parallelism, never a wait.

/// Makes the calling thread a worker of rayon's global pool (of `RAYON_NUM_THREADS` threads, or
/// as many as the machine has). Call it first thing in `main`, before anything runs in
/// parallel: once the global pool exists it cannot change, and the call then does nothing.
/// Parallel sections started from threads other than this one still work, as before.
pub fn join_global_pool() {
    // The only error is a global pool that already exists (built by an earlier call, or by a
    // parallel section that ran first): nothing to do then.
    let _ = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .build_global();
}

/// The CPU time, in milliseconds, of the calling thread and of every worker of rayon's global
/// pool, summed (`None` where the platform has no per-thread CPU clocks): what a CPU stage
/// costs when its work runs on the pool (`laine`'s rays, the reference) and the calling thread
/// waits for or joins it, without the process's other threads — the GPU driver's, which on
/// lavapipe and llvmpipe run the GPU's work on the CPU. The workers' clocks are found once, by
/// a broadcast to the pool (which builds the default pool if none exists yet).
pub fn pool_cpu_ms() -> Option<f64> {
    #[cfg(target_os = "linux")]
    {
        let own = own_cpu_clock()?;
        let workers = worker_cpu_clocks();
        let mut ms = 0.0;
        for &clock in workers {
            ms += crate::measure::calibrate::cpu_clock_ms(clock)?;
        }
        if !workers.contains(&own) {
            ms += crate::measure::calibrate::cpu_clock_ms(own)?;
        }
        Some(ms)
    }
    #[cfg(not(target_os = "linux"))]
    {
        crate::measure::calibrate::thread_cpu_ms()
    }
}

/// The calling thread's CPU clock.
#[cfg(target_os = "linux")]
fn own_cpu_clock() -> Option<libc::clockid_t> {
    let mut clock: libc::clockid_t = 0;
    // SAFETY: `pthread_self` is the calling, live thread; `clock` is writable.
    let rc = unsafe { libc::pthread_getcpuclockid(libc::pthread_self(), &mut clock) };
    (rc == 0).then_some(clock)
}

/// The CPU clocks of the global pool's workers (their threads live as long as the process).
#[cfg(target_os = "linux")]
fn worker_cpu_clocks() -> &'static [libc::clockid_t] {
    static CLOCKS: std::sync::OnceLock<Vec<libc::clockid_t>> = std::sync::OnceLock::new();
    CLOCKS.get_or_init(|| {
        rayon::broadcast(|_| own_cpu_clock())
            .into_iter()
            .flatten()
            .collect()
    })
}
