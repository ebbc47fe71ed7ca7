//! Shadow-map updates by priority (Barczak 2006 §4.5.3).
//!
//! Reads: each light's flux (its brightest channel is its brightness), the lights whose maps a
//! motion affected ([`crate::database::Update::shadow_maps`]), and how many maps a frame may
//! re-render (the thesis: 100–150 of 300).
//! Writes: the lights whose maps to re-render this frame.
//!
//! A map a motion touches goes out of date (if it already was, it stays so since the first
//! time). Every frame each out-of-date map's age (frames out of date, counting this one) grows
//! by one and the `budget` maps of highest priority, brightness × age, are re-rendered (ties:
//! the lower light index) and become current. Bright lights are updated at once, and no map
//! starves: a map's priority grows without bound while it waits.

use glam::Vec3;

/// See the module docs.
#[derive(Clone, Debug)]
pub struct ShadowMapSchedule {
    brightness: Vec<f32>,
    /// Frames out of date; 0: current.
    age: Vec<u32>,
}

impl ShadowMapSchedule {
    /// A schedule for lights of `flux`, every map current.
    pub fn new(flux: impl IntoIterator<Item = Vec3>) -> ShadowMapSchedule {
        let brightness: Vec<f32> = flux.into_iter().map(|f| f.max_element().max(0.0)).collect();
        let age = vec![0; brightness.len()];
        ShadowMapSchedule { brightness, age }
    }

    /// Marks the maps of `lights` out of date.
    pub fn mark(&mut self, lights: &[u32]) {
        for &l in lights {
            let a = &mut self.age[l as usize];
            *a = (*a).max(1);
        }
    }

    /// Maps out of date now.
    pub fn stale(&self) -> usize {
        self.age.iter().filter(|a| **a > 0).count()
    }

    /// This frame's maps to re-render: at most `budget`, by priority; the rest age a frame.
    pub fn next_frame(&mut self, budget: usize) -> Vec<u32> {
        let mut stale: Vec<u32> = (0..self.age.len() as u32)
            .filter(|&l| self.age[l as usize] > 0)
            .collect();
        let priority = |l: u32| self.brightness[l as usize] as f64 * self.age[l as usize] as f64;
        stale.sort_by(|&a, &b| priority(b).total_cmp(&priority(a)).then(a.cmp(&b)));
        stale.truncate(budget);
        for (l, a) in self.age.iter_mut().enumerate() {
            if stale.contains(&(l as u32)) {
                *a = 0;
            } else if *a > 0 {
                *a += 1;
            }
        }
        stale.sort_unstable();
        stale
    }
}
