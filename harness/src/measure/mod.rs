//! What a measurement is made of, below everything that measures: summary statistics, image
//! metrics, the timer calibration, the results file model (one run's record) and the
//! roofline's data (stages' declared costs, the device's bounds).
//!
//! Depends only on [`crate::error`] and [`crate::output`].

pub mod calibrate;
pub mod metrics;
pub mod results;
pub mod roofline;
pub mod stats;
