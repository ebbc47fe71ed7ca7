//! The subcommands of `gibench`, one module each (its clap arguments and its work), and the
//! helpers several of them share.
//!
//! Subcommands: [`run`], [`sweep`], [`list`], [`report`], [`reference`], [`reproduce`],
//! [`plot_quality`], [`compare`], [`merge`], [`export`], [`instructions`], [`export_scene`],
//! [`raycast`]. [`shard`] is the work split of the commands that shard.
//!
//! Shared: [`options`] (option groups several commands flatten in: the reference's, the
//! adapter's), [`params`] (parsing and checking option values, `--param` assignment),
//! [`files`] (checks on output folders, files and stems), [`results_io`] (reading results
//! files and folders of them), [`progress`] (progress bars and where a command reports) and
//! [`page`] (the HTML page a command writes with `--html`).

pub(crate) mod adapter;
pub(crate) mod compare;
pub(crate) mod export;
pub(crate) mod export_scene;
pub(crate) mod files;
pub(crate) mod instructions;
pub(crate) mod list;
pub(crate) mod merge;
pub(crate) mod options;
pub(crate) mod page;
pub(crate) mod params;
pub(crate) mod plot_quality;
pub(crate) mod progress;
pub(crate) mod raycast;
pub(crate) mod reference;
pub(crate) mod report;
pub(crate) mod reproduce;
pub(crate) mod results_io;
pub(crate) mod run;
pub(crate) mod shard;
pub(crate) mod sweep;
