//! The technique registry: every technique crate's `TechniqueInfo`, in the order `gibench list`
//! shows them.

use gibench_harness::kit::technique::TechniqueInfo;

static ALL: [TechniqueInfo; 8] = [
    gibench_direct::INFO,
    gibench_keller::FULL,
    gibench_keller::INCREMENTAL,
    gibench_laine::INFO,
    gibench_ism::INFO,
    gibench_ism::INFO_CLASSIC,
    gibench_gaitatzes::INFO,
    gibench_barczak::INFO,
];

/// All registered techniques.
pub fn all() -> &'static [TechniqueInfo] {
    &ALL
}
