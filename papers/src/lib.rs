//! `gibench-papers`: the paper reproductions of gibench as a library, beside the techniques and
//! over the harness's run API. The `gibench` binary's `run`, `sweep`, `reference`, `reproduce`
//! and `merge` subcommands hand their parsed arguments to the `exec` of the module of that name;
//! tests call the same functions without spawning the binary (`papers/tests/it/`).
//!
//! Layers, from the bottom up; a module uses only its own layer and those below it
//! (`papers/tests/it/layers.rs` checks it):
//!
//! 1. **Support**: [`registry`] (the techniques gibench knows), [`options`] (option groups several
//!    commands flatten in), [`params`] (parsing and checking option values, `--param`),
//!    [`files`] (checks on output folders, files and stems), [`page`] (the HTML page of
//!    `--html`), [`progress`] (progress bars, drawing what they are given) and [`shard`] (the
//!    work split of a fleet: Slurm arrays, Kubernetes Indexed Jobs, CI matrices).
//! 2. **Runs**: [`run`], [`sweep`] and [`reference`]: plan (every check before any GPU work),
//!    then run and write one output set; [`equal_time`], the knob search of `run --equal-time`.
//! 3. **Papers**: [`reproduce`], one module per paper (its targets, runs, tables, figures and
//!    the paper's own data, printed beside ours as labelled rows), and `reproduce::all`, the
//!    target registry and planner (manifest, shards, budget) over the papers and runs.
//! 4. **Fleet**: [`merge`], pooling the folders of a fleet's shards into one output set.

pub mod files;
pub mod options;
pub mod page;
pub mod params;
pub mod progress;
pub mod registry;
pub mod shard;

pub mod equal_time;
pub mod reference;
pub mod run;
pub mod sweep;

pub mod reproduce;

pub mod merge;
