//! Random numbers: the PCG32 generator and hashing to derive independent, reproducible streams.
//!
//! Every pixel sample draws from its own stream, seeded by hashing (seed, pixel, sample index),
//! so the image does not depend on thread count or tile order.

/// PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient Statistically Good
/// Algorithms for Random Number Generation", the XSH-RR 64/32 variant).
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    increment: u64,
}

const PCG32_MULTIPLIER: u64 = 0x5851_f42d_4c95_7f2d;
const PCG32_DEFAULT_STATE: u64 = 0x853c_49e6_748f_ea9b;
const PCG32_DEFAULT_STREAM: u64 = 0xda3e_39cb_94b9_5bdb;

impl Default for Pcg32 {
    fn default() -> Self {
        Pcg32 {
            state: PCG32_DEFAULT_STATE,
            increment: PCG32_DEFAULT_STREAM,
        }
    }
}

impl Pcg32 {
    /// A generator on stream `stream` starting from `seed`.
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut rng = Pcg32 {
            state: 0,
            increment: (stream << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    /// A generator seeded from a single value (stream chosen by hashing it).
    pub fn seeded(seed: u64) -> Self {
        Pcg32::new(seed, mix_bits(seed ^ 0x9e37_79b9_7f4a_7c15))
    }

    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(PCG32_MULTIPLIER)
            .wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rotation = (old >> 59) as u32;
        xorshifted.rotate_right(rotation)
    }

    /// A uniform float in [0, 1): 24 random bits, so exactly representable and never 1.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// A uniform double in [0, 1) with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        let high = u64::from(self.next_u32()) << 21;
        let low = u64::from(self.next_u32()) >> 11;
        (high | low) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform integer in [0, bound) without modulo bias (Lemire 2019).
    pub fn next_bounded(&mut self, bound: u32) -> u32 {
        debug_assert!(bound > 0);
        let threshold = bound.wrapping_neg() % bound;
        loop {
            let product = u64::from(self.next_u32()) * u64::from(bound);
            if (product as u32) >= threshold {
                return (product >> 32) as u32;
            }
        }
    }

    /// Moves the generator `delta` steps ahead (or back, for negative values) in O(log delta)
    /// (Brown 1994, "Random Number Generation with Arbitrary Strides").
    pub fn advance(&mut self, delta: i64) {
        let stride = self.stride(delta);
        self.jump(stride);
    }

    /// The affine map that moves this stream `delta` steps: `delta` steps of the LCG
    /// s ↦ a·s + c compose to s ↦ A·s + C, found by repeated squaring (Brown 1994).
    pub fn stride(&self, delta: i64) -> Stride {
        let mut cur_mult = PCG32_MULTIPLIER;
        let mut cur_plus = self.increment;
        let mut acc_mult = 1u64;
        let mut acc_plus = 0u64;
        let mut delta = delta as u64;
        while delta > 0 {
            if delta & 1 == 1 {
                acc_mult = acc_mult.wrapping_mul(cur_mult);
                acc_plus = acc_plus.wrapping_mul(cur_mult).wrapping_add(cur_plus);
            }
            cur_plus = cur_mult.wrapping_add(1).wrapping_mul(cur_plus);
            cur_mult = cur_mult.wrapping_mul(cur_mult);
            delta >>= 1;
        }
        Stride {
            multiplier: acc_mult,
            increment: acc_plus,
        }
    }

    /// Applies a stride of this stream (from [`Self::stride`]) in one multiply-add.
    #[inline]
    pub fn jump(&mut self, stride: Stride) {
        self.state = stride
            .multiplier
            .wrapping_mul(self.state)
            .wrapping_add(stride.increment);
    }
}

/// A jump of a fixed number of steps along one PCG32 stream (see [`Pcg32::stride`]).
#[derive(Clone, Copy, Debug)]
pub struct Stride {
    multiplier: u64,
    increment: u64,
}

/// A 64-bit finaliser with good avalanche (the "mix13" variant of SplitMix64's finaliser,
/// Stafford 2011).
pub fn mix_bits(mut v: u64) -> u64 {
    v ^= v >> 31;
    v = v.wrapping_mul(0x7fb5_d329_728e_a185);
    v ^= v >> 27;
    v = v.wrapping_mul(0x81da_def4_bc2d_d44d);
    v ^= v >> 33;
    v
}

/// Hashes a list of integers into one well-mixed 64-bit value.
pub fn hash_u64s(values: &[u64]) -> u64 {
    let mut h = 0x6a09_e667_f3bc_c909u64;
    for &v in values {
        h = mix_bits(h ^ v.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_lie_in_the_unit_interval_and_average_one_half() {
        let mut rng = Pcg32::seeded(7);
        let n = 100_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let u = rng.next_f32();
            assert!((0.0..1.0).contains(&u));
            sum += f64::from(u);
        }
        // Mean of U(0,1) has standard error 1/sqrt(12 n); allow 5 standard errors.
        let se = (1.0 / (12.0 * n as f64)).sqrt();
        assert!((sum / n as f64 - 0.5).abs() < 5.0 * se);
    }

    #[test]
    fn advance_matches_stepping() {
        let mut a = Pcg32::new(42, 54);
        let mut b = a.clone();
        for _ in 0..1000 {
            a.next_u32();
        }
        b.advance(1000);
        assert_eq!(a.next_u32(), b.next_u32());
        b.advance(-1);
        let mut c = b.clone();
        c.advance(1);
        b.next_u32();
        assert_eq!(b.next_u32(), c.next_u32());
    }

    #[test]
    fn reference_sequence_of_the_pcg32_paper() {
        // pcg32-demo with seed 42, stream 54 prints these first values.
        let mut rng = Pcg32::new(42, 54);
        let expected = [
            0xa15c02b7u32,
            0x7b47f409,
            0xba1d3330,
            0x83d2f293,
            0xbfa4784b,
            0xcbed606e,
        ];
        for e in expected {
            assert_eq!(rng.next_u32(), e);
        }
    }

    #[test]
    fn bounded_integers_stay_below_the_bound() {
        let mut rng = Pcg32::seeded(3);
        for bound in [1u32, 2, 3, 7, 1000, u32::MAX] {
            for _ in 0..1000 {
                assert!(rng.next_bounded(bound) < bound);
            }
        }
    }
}
