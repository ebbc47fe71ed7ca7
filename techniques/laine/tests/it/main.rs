//! `laine`'s integration tests, one binary (`cargo test --release -p gibench-laine --test it`):
//! the sampling-point domains and the VPL manager.

mod domain;
mod manager;
