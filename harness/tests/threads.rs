//! `threads::join_global_pool`. A test binary of its own, not a module of `tests/it/`: it needs
//! its own process, since rayon's global pool is built once per process, and must not have been
//! built by another test first.

use rayon::prelude::*;

/// The calling thread becomes worker 0 of the global pool, parallel sections started from it
/// still run across the pool and give the sequential answer, and a second call changes nothing.
/// Fails if the pool is built without the calling thread (`current_thread_index` is `None`
/// outside the pool).
#[test]
fn the_calling_thread_becomes_a_worker_of_the_global_pool() {
    assert_eq!(rayon::current_thread_index(), None);
    gibench_harness::cpu::threads::join_global_pool();
    assert_eq!(rayon::current_thread_index(), Some(0));
    let sum: u64 = (0..100_000u64).into_par_iter().map(|i| i * i).sum();
    assert_eq!(sum, (0..100_000u64).map(|i| i * i).sum::<u64>());
    gibench_harness::cpu::threads::join_global_pool();
    assert_eq!(rayon::current_thread_index(), Some(0));
}
