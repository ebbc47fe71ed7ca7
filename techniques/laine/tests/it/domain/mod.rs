//! Tests of the sampling-point domains (Laine et al. 2007, §4.5–§4.7): shared point sets and
//! builders here; the checks by subject in the submodules.

mod geometry;
mod maintenance;

use std::f64::consts::PI;

use gibench_harness::cpu::vpl::radical_inverse;
use gibench_harness::rng::SplitMix64 as Rng;
use gibench_laine::domain::{DomainKind, SamplingDomain};
use glam::DVec3;

/// Uniform disc point from the unit square (polar mapping).
pub fn to_disc(u: f64, v: f64) -> DVec3 {
    let r = u.sqrt();
    let phi = 2.0 * PI * v;
    DVec3::new(r * phi.cos(), r * phi.sin(), 0.0)
}

/// Uniform sphere point from the unit square.
pub fn to_sphere(u: f64, v: f64) -> DVec3 {
    let z = 1.0 - 2.0 * u;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * v;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `n` points of `kind`: the Halton sequence (bases 2 and 3), or uniform random ones.
pub fn point_set(kind: DomainKind, n: usize, random: bool) -> Vec<DVec3> {
    let mut rng = Rng::from_state(0x1234_5678 + n as u64);
    (0..n)
        .map(|i| {
            let (u, v) = if random {
                (rng.next_f64(), rng.next_f64())
            } else {
                (
                    radical_inverse(2, i as u64 + 1),
                    radical_inverse(3, i as u64 + 1),
                )
            };
            match kind {
                DomainKind::Disc => to_disc(u, v),
                DomainKind::Sphere => to_sphere(u, v),
            }
        })
        .collect()
}

/// A domain of `kind` holding `pts`, inserted in order under the ids 3, 10, 17, …
pub fn build(kind: DomainKind, pts: &[DVec3]) -> SamplingDomain {
    let mut d = SamplingDomain::new(kind);
    for (i, &p) in pts.iter().enumerate() {
        d.insert(i as u64 * 7 + 3, p).unwrap();
    }
    assert_eq!(d.len(), pts.len());
    d
}
