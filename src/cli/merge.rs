//! `gibench merge DIR… --out DIR`: one output set from the `reproduce all` folders of many
//! machines (the shards of a Slurm array or Kubernetes Indexed Job): the work is in
//! [`crate::cli::reproduce::all::merge`].

use std::path::PathBuf;

use clap::Args;
use gibench_harness::Result;

#[derive(Args)]
pub struct MergeArgs {
    /// The folders to pool, each written by `gibench reproduce all` (e.g. one per shard).
    #[arg(required = true, value_name = "DIR")]
    pub dirs: Vec<PathBuf>,
    /// The folder the pooled targets and the combined reproduce-all.json/.md/.html go to.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn exec(args: &MergeArgs) -> Result<()> {
    crate::cli::reproduce::all::merge(&args.dirs, &args.out)
}
