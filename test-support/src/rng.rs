//! Random numbers for tests: a fixed linear congruential sequence, the same on every machine
//! and every run (the harness's `SplitMix64` is the other choice).

/// The 32-bit linear congruential generator of the C standard's example (×1103515245 + 12345),
/// its top 24 bits as a float in [0, 1).
#[derive(Clone, Debug)]
pub struct Lcg(u32);

impl Lcg {
    /// The sequence from `state`.
    pub fn new(state: u32) -> Lcg {
        Lcg(state)
    }

    /// The next number in [0, 1).
    pub fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(1_103_515_245).wrapping_add(12345);
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }
}
