//! The harness's integration tests, one binary (`cargo test --release -p gibench-harness --test
//! it`): a module per subject.
//!
//! Kept apart, each in its own binary because it needs its own process: `gpu_wait.rs` (it
//! sizes GPU work by timing it and then times the waits), `profiler.rs` (it counts the CPU time
//! of every worker of rayon's global pool, which any other test's parallel work would add to)
//! and `threads.rs` (it builds rayon's global pool, once per process).

mod accumulate;
mod bindings;
mod direct_light;
mod edges;
mod gbuffer_vs_rays;
mod interleave;
mod ism_kit;
mod layers;
mod reference;
mod roofline;
mod scene;
mod vpl;
mod vpl_maps;
