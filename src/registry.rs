//! The technique registry: every technique crate's `INFO`, in the order `gibench list` shows them.

use gibench_harness::technique::TechniqueInfo;

/// All registered techniques.
pub fn all() -> Vec<TechniqueInfo> {
    vec![gibench_direct::INFO]
}
