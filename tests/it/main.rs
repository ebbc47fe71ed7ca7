//! The root package's integration tests, one binary (`cargo test --release --test it`): the
//! command line's and the cross-technique tests, a module per subject; `cli_errors/` a module
//! per kind of bad input. A test is one with a name like `conformance::every_registered_...`,
//! so `cargo test --release --test it -- conformance::` runs one subject.
//!
//! Kept apart, each in its own binary because it needs its own process: `tests/compare.rs`
//! (its end-to-end comparison judges real runs' times, which the other tests' work running
//! beside it in the same process would disturb) and `tests/memory.rs` (it measures the
//! process's own resident set), and `tests/fuzz/` (the fuzz targets: its allocator counts every
//! allocation). A new test file belongs here, as a module, unless it needs its
//! own process too (`layout::every_test_file_is_a_module_or_says_why_it_is_apart` checks
//! that none is forgotten).

#[path = "../support/mod.rs"]
mod support;

mod cli_errors;
mod conformance;
mod device_loss;
mod docs_links;
mod export;
mod fleet;
mod gpu_span;
mod html;
mod instructions;
mod keller;
mod layout;
mod output_sets;
mod raycast;
mod readme_examples;
mod report;
mod reproduce;
mod resume;
mod roofline;
mod run;
mod src_layers;
