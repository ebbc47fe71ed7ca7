//! The parameters of `direct`: none. The baseline has nothing to tune; the declaration is kept
//! here, as every technique crate keeps its own, so that the registry entry reads alike.

use gibench_harness::kit::technique::ParamSpec;

/// The parameters' declarations: empty (any `-p name=value` is refused by name).
pub(crate) const PARAMS: &[ParamSpec] = &[];
