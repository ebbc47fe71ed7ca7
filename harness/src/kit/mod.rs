//! What a technique is built from: the [`technique::Technique`] interface and its contexts, the
//! shared GPU passes ([`passes`]) and the instant-radiosity kit ([`ir`]). Each pass says what it
//! reads and writes.
//!
//! Depends on [`crate::gpu`], [`crate::cpu`] and [`crate::scene`].

pub mod ir;
pub mod passes;
pub mod technique;
pub mod wgsl;
