//! **Calibration**: a fixed CPU workload timed in the same session as a run, so that timings
//! taken at different moments on a shared machine can be compared as ratios to it
//! (`gibench compare`), and CPU clocks: the calling thread's, the whole process's (a CPU
//! stage's, the calling thread and rayon's pool together, is `crate::cpu::threads::pool_cpu_ms`).

use std::time::Instant;

/// The calling thread's CPU time in milliseconds (`None` where the platform has no per-thread
/// clock).
pub fn thread_cpu_ms() -> Option<f64> {
    #[cfg(unix)]
    {
        cpu_clock_ms(libc::CLOCK_THREAD_CPUTIME_ID)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// The CPU time of every thread of this process in milliseconds (`None` where the platform has
/// no such clock): the cost of CPU work that runs across cores.
pub fn process_cpu_ms() -> Option<f64> {
    #[cfg(unix)]
    {
        cpu_clock_ms(libc::CLOCK_PROCESS_CPUTIME_ID)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// `f`'s result with the wall seconds it took and the CPU seconds every thread of the process
/// spent meanwhile (`None` without a process CPU clock): the timer of CPU work that may run
/// across cores.
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, Option<f64>) {
    let (cpu, wall) = (process_cpu_ms(), Instant::now());
    let out = f();
    let wall = wall.elapsed().as_secs_f64();
    let cpu = cpu.zip(process_cpu_ms()).map(|(a, b)| (b - a) * 1e-3);
    (out, wall, cpu)
}

/// The CPU clock `clock` (a process's, a thread's) in milliseconds.
#[cfg(unix)]
pub(crate) fn cpu_clock_ms(clock: libc::clockid_t) -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes it.
    let rc = unsafe { libc::clock_gettime(clock, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 * 1e-6)
}

/// One pass of the workload: ray–triangle tests and a dependent floating-point chain over a
/// fixed pseudo-random set (a few milliseconds on a 2020s CPU core). Returns a value that depends on
/// every step, so the work cannot be optimised away.
fn workload() -> f64 {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut acc = 0.0f64;
    for _ in 0..1_000_000 {
        let (a, b, c) = (next(), next(), next());
        // A cheap Möller–Trumbore-like determinant and a square root per step.
        let det = a * (b - c) + b * (c - a) + 1.5;
        acc = (acc + (det * det + c).sqrt()) * 0.999_999;
    }
    acc
}

/// The calibration time: the median of 7 passes of the workload, milliseconds of wall time.
pub fn calibration_ms() -> f64 {
    let mut times: Vec<f64> = (0..7)
        .map(|_| {
            let t0 = Instant::now();
            std::hint::black_box(workload());
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calibration_is_positive_and_thread_time_advances() {
        let before = thread_cpu_ms();
        let c = calibration_ms();
        assert!(c > 0.0 && c.is_finite());
        if let (Some(a), Some(b)) = (before, thread_cpu_ms()) {
            // 7 passes of CPU-bound work on this thread show up in its CPU time.
            assert!(
                b - a >= 0.5 * c,
                "thread CPU time {} ms for calibration {c} ms",
                b - a
            );
        }
    }
}
