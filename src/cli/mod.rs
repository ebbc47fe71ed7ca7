//! The subcommands of `gibench` that are not paper work, one module each (its clap arguments and
//! its work): [`list`], [`report`], [`plot_quality`], [`compare`], [`export`], [`instructions`],
//! [`export_scene`], [`raycast`], [`adapter`]. [`results_io`] (reading results files and folders
//! of them) is theirs to share.
//!
//! `run`, `sweep`, `reference`, `reproduce` and `merge` are the `gibench-papers` library's
//! (`papers/`): `main.rs` hands their arguments to it, as cargo's `commands/` hand theirs to
//! `cargo::ops`. Their argument structs live there too, because a paper target is such a command
//! line, parsed and checked by the library and recorded in the manifest.

pub(crate) mod adapter;
pub(crate) mod compare;
pub(crate) mod export;
pub(crate) mod export_scene;
pub(crate) mod instructions;
pub(crate) mod list;
pub(crate) mod plot_quality;
pub(crate) mod raycast;
pub(crate) mod report;
pub(crate) mod results_io;
