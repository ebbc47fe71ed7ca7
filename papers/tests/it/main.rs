//! The papers crate's integration tests, one binary of modules.

mod layers;
mod targets;
