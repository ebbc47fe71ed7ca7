//! The `gibench` binary of this build for the root tests: test-support's runner given its path.
#![allow(unused_imports)]
pub use gibench_test_support::reference_image;
pub const GIBENCH: gibench_test_support::Gibench =
    gibench_test_support::Gibench::new(env!("CARGO_BIN_EXE_gibench"));
