//! One run: the frame loop ([`runner`]), the quality pass against the reference ([`quality`])
//! and a session of runs writing one output set ([`session`]); the kernels that measure the
//! device's bounds for the roofline ([`bounds`]).
//!
//! Depends on [`crate::kit`] and everything below it.

pub mod bounds;
pub mod commit;
pub mod config;
pub mod quality;
pub mod runner;
pub mod session;
