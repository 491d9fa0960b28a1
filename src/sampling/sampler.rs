//! The per-pixel sampler: the random numbers of one pixel sample, dimension by dimension
//! (DESIGN.md §3.5). The numbers depend only on (seed, pixel, sample index, dimension), so an
//! image is the same whatever the thread count or the order of tiles.

use glam::{UVec2, Vec2};

use super::rng::{Pcg32, hash_u64s};

/// Mitsuba's `independent` sampler: every dimension is an independent uniform number.
///
/// ```xml
/// <sampler type="independent">
///     <integer name="sample_count" value="64"/>
/// </sampler>
/// ```
/// Each pixel has its own PCG32 stream (selected by a hash of seed and pixel); sample i starts
/// 2¹⁶ numbers into it, so samples never share numbers (as pbrt-v4's `IndependentSampler`).
#[derive(Clone, Debug)]
pub struct IndependentSampler {
    seed: u64,
    rng: Pcg32,
}

/// Numbers reserved per pixel sample in a pixel's stream.
const DIMENSIONS_PER_SAMPLE: i64 = 1 << 16;

impl IndependentSampler {
    pub fn new(seed: u64) -> Self {
        IndependentSampler {
            seed,
            rng: Pcg32::default(),
        }
    }

    pub fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        let stream = hash_u64s(&[u64::from(pixel.x), u64::from(pixel.y), self.seed]);
        self.rng = Pcg32::new(hash_u64s(&[self.seed]), stream);
        self.rng.advance(i64::from(index) * DIMENSIONS_PER_SAMPLE);
    }

    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        self.rng.next_f32()
    }
}

/// The sampler of a render.
#[derive(Clone, Debug)]
pub enum Sampler {
    Independent(IndependentSampler),
}

impl Sampler {
    /// Prepares the numbers of sample `index` of `pixel` (full-film pixel coordinates).
    pub fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        match self {
            Sampler::Independent(s) => s.start_pixel_sample(pixel, index),
        }
    }

    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        match self {
            Sampler::Independent(s) => s.next_1d(),
        }
    }

    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        let y = self.next_1d();
        Vec2::new(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_reproducible_and_distinct() {
        let mut a = Sampler::Independent(IndependentSampler::new(1));
        let mut b = Sampler::Independent(IndependentSampler::new(1));
        a.start_pixel_sample(UVec2::new(3, 4), 7);
        let first: Vec<f32> = (0..5).map(|_| a.next_1d()).collect();
        // Interleaving other pixels does not change a pixel's numbers.
        b.start_pixel_sample(UVec2::new(0, 0), 0);
        b.next_2d();
        b.start_pixel_sample(UVec2::new(3, 4), 7);
        let again: Vec<f32> = (0..5).map(|_| b.next_1d()).collect();
        assert_eq!(first, again);
        b.start_pixel_sample(UVec2::new(3, 4), 8);
        assert_ne!(first[0], b.next_1d());
        let mut c = Sampler::Independent(IndependentSampler::new(2));
        c.start_pixel_sample(UVec2::new(3, 4), 7);
        assert_ne!(first[0], c.next_1d());
    }
}
