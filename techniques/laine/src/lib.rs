//! Laine et al. 2007, "Incremental Instant Radiosity for Real-Time Indirect Illumination".
//!
//! For now only the CPU geometry of the paper's VPL management (§4): [`domain`] keeps the
//! sampling points of the VPLs in the unit disc (spot lights) or on the unit sphere (omni
//! lights) with their Delaunay triangulation, and answers the queries of §4.5–§4.7.

pub mod domain;
