//! CPU ray casting and everything built on it: the BVH over the static geometry, the one light
//! model, VPL paths, the reference path tracer and the thread pool they use.
//!
//! Depends on [`crate::scene`] and [`crate::measure`].

pub mod bvh;
pub mod light;
pub mod reference;
pub mod threads;
pub mod vpl;
