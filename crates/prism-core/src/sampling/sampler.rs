//! The per-pixel sampler: the random numbers of one pixel sample, dimension by dimension
//! (docs/architecture.md, Conventions).
//!
//! A pixel sample first takes its *primary* dimensions, the parameters of the camera ray that
//! the lecture samples independently ("Distribution Raytracing", "Reference Implementation:
//! primary rays"): wavelength, time, film position (2-D) and lens position (2-D). The numbers for
//! the path's bounces come after. Which dimensions are stratified depends on the sampler:
//!
//! | sampler | primary dimensions | later dimensions |
//! | --- | --- | --- |
//! | `independent` | uniform | uniform |
//! | `stratified` (Mitsuba) | 1-D: N strata, 2-D: √N × √N jittered grid | the same |
//! | `multijitter` (Mitsuba) | 1-D: N strata, 2-D: correlated multi-jittered | the same |
//! | `nrooks` (ours) | every one of the 6 coordinates in N strata (Latin hypercube) | uniform |
//! | `ldsampler` (Mitsuba) | 1-D: scrambled van der Corput, 2-D: scrambled (0, 2)-sequence | the same |
//! | `orthogonal` (Mitsuba) | an orthogonal array of strength t, every dimension a factor | the same |
//!
//! `ldsampler` is Mitsuba 3's low-discrepancy sampler (Kollig and Keller 2002, "Efficient
//! Multidimensional Sampling", after Mitsuba 0.6's sampler of the same name): N, a square of a
//! power of two, points of the (0, 2)-sequence (the van der Corput radical inverse in base 2
//! and the second Sobol' dimension), each coordinate scrambled by an XOR with a random 32-bit
//! number (a random digit scrambling, so each point is uniform), and the order of the points
//! shuffled anew for each dimension. The scrambles are drawn per pixel and per dimension, as in
//! Mitsuba 0.6; Mitsuba 3 shares one per pixel across dimensions, which leaves all of a
//! sample's 1-D numbers with the same low bits (their joint density is not uniform).
//!
//! `orthogonal` is Mitsuba 3's orthogonal array sampler (Jarosz, Enayet, Kensler, Kilpatrick and
//! Christensen 2019, "Orthogonal Array Sampling for Monte Carlo Rendering"): the N = p^t runs of
//! an orthogonal array OA(p^t, ·, p, t) over the prime p, whose every t dimensions together are
//! stratified into the p^t cells of their grid; each dimension is also stratified into N strata
//! (the "multi-jittered" flavour). Strength 2 uses Bose's construction (its run i = (a₀, a₁) in
//! base p gives dimension j the level a₀ + (j − 1) a₁ mod p), other strengths Bush's (the level
//! of dimension j is the polynomial with i's t base-p digits as coefficients, evaluated at j, mod
//! p). The run order is shuffled per pixel, the levels of each dimension per dimension.
//! In every stratified sampler the strata of each dimension are assigned to the N samples of a
//! pixel by an independent pseudo-random permutation (the lecture's `*_stratified_and_shuffle`),
//! computed on the fly by Kensler's hash-based permutation, so no table is stored and any sample
//! index can be drawn alone. Within its stratum a sample is jittered uniformly (or centred, when
//! `jitter` is false). Everything depends only on (seed, pixel, sample index, dimension): the
//! image is the same whatever the thread count or the order of tiles.
//!
//! ```xml
//! <sampler type="nrooks">             <!-- or independent, stratified, multijitter, ldsampler, orthogonal -->
//!     <integer name="sample_count" value="64"/>
//!     <integer name="seed" value="0"/>
//!     <boolean name="jitter" value="true"/>   <!-- stratified, multijitter and orthogonal -->
//!     <integer name="strength" value="2"/>     <!-- orthogonal -->
//! </sampler>
//! ```

use glam::{UVec2, Vec2};

use super::rng::{Pcg32, Stride, hash_u64s};

/// The kinds of per-pixel sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    Independent,
    Stratified { jitter: bool },
    MultiJitter { jitter: bool },
    NRooks,
    LowDiscrepancy,
    Orthogonal { strength: u32, jitter: bool },
}

/// The largest `strength` of the `orthogonal` sampler.
pub const MAX_ORTHOGONAL_STRENGTH: u32 = 4;

impl SamplerKind {
    /// The sampler's plugin name, as scenes, render states and messages write it.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified { .. } => "stratified",
            SamplerKind::MultiJitter { .. } => "multijitter",
            SamplerKind::NRooks => "nrooks",
            SamplerKind::LowDiscrepancy => "ldsampler",
            SamplerKind::Orthogonal { .. } => "orthogonal",
        }
    }

    /// The sample count the sampler really takes for a requested one: `stratified` rounds up to
    /// a square (its 2-D grids are √N × √N) and `multijitter` to a product m·n with m ≥ n close to
    /// √N, as Mitsuba does; the others take any count.
    pub fn sample_count(self, requested: u32) -> u32 {
        let (columns, rows) = self.grid(requested);
        columns * rows
    }

    /// Columns and rows of the 2-D strata for `requested` samples (N × 1 when not gridded).
    fn grid(self, requested: u32) -> (u32, u32) {
        let requested = requested.max(1);
        match self {
            SamplerKind::Stratified { .. } => {
                let side = (f64::from(requested).sqrt().ceil() as u32).max(1);
                (side, side)
            }
            SamplerKind::MultiJitter { .. } => {
                let rows = (f64::from(requested).sqrt() as u32).max(1);
                (requested.div_ceil(rows), rows)
            }
            SamplerKind::LowDiscrepancy => {
                let mut side = 2u32;
                while u64::from(side) * u64::from(side) < u64::from(requested) {
                    side = (side + 1).next_power_of_two();
                }
                (side * side, 1)
            }
            SamplerKind::Orthogonal { strength, .. } => {
                let p = orthogonal_array_base(requested, strength);
                (p.pow(strength), 1)
            }
            SamplerKind::Independent | SamplerKind::NRooks => (requested, 1),
        }
    }
}

/// The smallest prime p ≥ max(2, `strength`) with p^strength ≥ `requested` (Bush's construction
/// needs p ≥ t).
fn orthogonal_array_base(requested: u32, strength: u32) -> u32 {
    let is_prime = |x: u32| {
        (2..)
            .take_while(|d| d * d <= x)
            .all(|d| !x.is_multiple_of(d))
    };
    let mut p = strength.max(2);
    while u64::from(p).pow(strength) < u64::from(requested) || !is_prime(p) {
        p += 1;
    }
    p
}

/// The primary dimensions of a camera ray, each in [0, 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSample {
    pub wavelength: f32,
    pub time: f32,
    /// Position within the reconstruction filter's support.
    pub film: Vec2,
    /// Position on the lens.
    pub lens: Vec2,
}

/// The random numbers of the pixel samples of a render.
#[derive(Clone, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    sample_count: u32,
    columns: u32,
    rows: u32,
    jitter: bool,
    /// The orthogonal array's base p (1 for other samplers).
    levels: u32,
    seed: u64,
    /// Hash of (seed, pixel): selects the pixel's permutations and random stream.
    pixel_seed: u64,
    index: u32,
    dimension: u32,
    rng: Pcg32,
    /// What the render loop's order (a pixel's samples one after another) lets us keep from
    /// one sample to the next, None before the first sample.
    stream: Option<PixelStream>,
}

/// A pixel's random stream, as far as [`Sampler::start_pixel_sample`] has gone along it.
#[derive(Clone, Debug)]
struct PixelStream {
    pixel: UVec2,
    /// The stream's start, for samples that do not follow the last one.
    start: Pcg32,
    /// NUMBERS_PER_SAMPLE steps along the stream: from one sample's start to the next's.
    /// Found when a sample first follows another, so that passes of one sample per pixel do
    /// not pay for it.
    sample_stride: Option<Stride>,
    /// The last sample started (its index in the pixel, not in its block) and the generator at
    /// its start.
    last: (u32, Pcg32),
}

/// Numbers reserved per pixel sample in the pixel's random stream.
const NUMBERS_PER_SAMPLE: i64 = 1 << 16;

impl Sampler {
    /// A sampler of `kind` for `requested` samples per pixel (see [`SamplerKind::sample_count`]).
    pub fn new(kind: SamplerKind, requested: u32, seed: u64) -> Sampler {
        let (columns, rows) = kind.grid(requested);
        let jitter = match kind {
            SamplerKind::Stratified { jitter }
            | SamplerKind::MultiJitter { jitter }
            | SamplerKind::Orthogonal { jitter, .. } => jitter,
            SamplerKind::Independent | SamplerKind::NRooks | SamplerKind::LowDiscrepancy => true,
        };
        let levels = match kind {
            SamplerKind::Orthogonal { strength, .. } => {
                orthogonal_array_base(requested.max(1), strength)
            }
            SamplerKind::Independent
            | SamplerKind::Stratified { .. }
            | SamplerKind::MultiJitter { .. }
            | SamplerKind::NRooks
            | SamplerKind::LowDiscrepancy => 1,
        };
        Sampler {
            kind,
            sample_count: columns * rows,
            columns,
            rows,
            jitter,
            levels,
            seed,
            pixel_seed: 0,
            index: 0,
            dimension: 0,
            rng: Pcg32::default(),
            stream: None,
        }
    }

    /// Samples per pixel.
    pub fn sample_count(&self) -> u32 {
        self.sample_count
    }

    /// Prepares sample `index` of `pixel` (full-film coordinates). Indices beyond the sample
    /// count start new, independently shuffled blocks of N stratified samples, so a render that
    /// goes on past N samples (to reach an error target, say) stays stratified block by block.
    pub fn start_pixel_sample(&mut self, pixel: UVec2, index: u32) {
        let block = index / self.sample_count;
        self.pixel_seed = hash_u64s(&[
            u64::from(pixel.x),
            u64::from(pixel.y),
            self.seed,
            u64::from(block),
        ]);
        self.index = index % self.sample_count;
        self.dimension = 0;
        // The sample's numbers start NUMBERS_PER_SAMPLE · index steps into the pixel's stream:
        // one multiply-add on from the previous sample's start when it is the next one, as in
        // the render loop, else a jump of O(log index) steps from the stream's start.
        match &mut self.stream {
            Some(stream) if stream.pixel == pixel => {
                let (last_index, last_start) = &stream.last;
                let mut rng;
                if last_index.checked_add(1) == Some(index) {
                    let start = &stream.start;
                    let stride = *stream
                        .sample_stride
                        .get_or_insert_with(|| start.stride(NUMBERS_PER_SAMPLE));
                    rng = last_start.clone();
                    rng.jump(stride);
                } else {
                    rng = stream.start.clone();
                    rng.advance(i64::from(index) * NUMBERS_PER_SAMPLE);
                }
                stream.last = (index, rng.clone());
                self.rng = rng;
            }
            _ => {
                let id = hash_u64s(&[u64::from(pixel.x), u64::from(pixel.y), self.seed]);
                let start = Pcg32::new(hash_u64s(&[self.seed]), id);
                let mut rng = start.clone();
                rng.advance(i64::from(index) * NUMBERS_PER_SAMPLE);
                self.stream = Some(PixelStream {
                    pixel,
                    sample_stride: None,
                    start,
                    last: (index, rng.clone()),
                });
                self.rng = rng;
            }
        }
    }

    /// The primary dimensions of the current sample; call once, first, per pixel sample.
    pub fn camera_sample(&mut self) -> CameraSample {
        match self.kind {
            SamplerKind::NRooks => {
                let [wavelength, time, fx, fy, lu, lv] =
                    std::array::from_fn(|d| self.latin_hypercube(d as u32));
                self.dimension = 6;
                CameraSample {
                    wavelength,
                    time,
                    film: Vec2::new(fx, fy),
                    lens: Vec2::new(lu, lv),
                }
            }
            SamplerKind::Independent
            | SamplerKind::Stratified { .. }
            | SamplerKind::MultiJitter { .. }
            | SamplerKind::LowDiscrepancy
            | SamplerKind::Orthogonal { .. } => CameraSample {
                wavelength: self.next_1d(),
                time: self.next_1d(),
                film: self.next_2d(),
                lens: self.next_2d(),
            },
        }
    }

    /// The next number of the path.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        match self.kind {
            SamplerKind::Independent | SamplerKind::NRooks => self.rng.next_f32(),
            SamplerKind::Stratified { .. } | SamplerKind::MultiJitter { .. } => {
                let dimension = self.next_dimension();
                self.latin_hypercube(dimension)
            }
            SamplerKind::LowDiscrepancy => {
                let dimension = self.next_dimension();
                let i = self.stratum(dimension);
                let scramble = self.permutation_seed(dimension, 1);
                unit_from_bits(radical_inverse_2(i, scramble))
            }
            SamplerKind::Orthogonal { strength, .. } => {
                let dimension = self.next_dimension();
                self.orthogonal_array(dimension, strength)
            }
        }
    }

    /// The next pair of numbers of the path.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        match self.kind {
            SamplerKind::Independent | SamplerKind::NRooks => {
                let x = self.rng.next_f32();
                let y = self.rng.next_f32();
                Vec2::new(x, y)
            }
            SamplerKind::Stratified { .. } => {
                let dimension = self.next_dimension();
                let cell = self.stratum(dimension);
                let (jx, jy) = (self.jitter_value(), self.jitter_value());
                Vec2::new(
                    ((cell % self.columns) as f32 + jx) / self.columns as f32,
                    ((cell / self.columns) as f32 + jy) / self.rows as f32,
                )
            }
            SamplerKind::MultiJitter { .. } => {
                let dimension = self.next_dimension();
                self.correlated_multi_jittered(dimension)
            }
            SamplerKind::LowDiscrepancy => {
                let dimension = self.next_dimension();
                let i = self.stratum(dimension);
                let (scramble_x, scramble_y) = (
                    self.permutation_seed(dimension, 1),
                    self.permutation_seed(dimension, 2),
                );
                Vec2::new(
                    unit_from_bits(radical_inverse_2(i, scramble_x)),
                    unit_from_bits(sobol_2(i, scramble_y)),
                )
            }
            SamplerKind::Orthogonal { .. } => {
                let x = self.next_1d();
                let y = self.next_1d();
                Vec2::new(x, y)
            }
        }
    }

    fn next_dimension(&mut self) -> u32 {
        let d = self.dimension;
        self.dimension += 1;
        d
    }

    fn jitter_value(&mut self) -> f32 {
        if self.jitter {
            self.rng.next_f32().min(1.0f32.next_down())
        } else {
            0.5
        }
    }

    /// The seed of the permutation of `dimension` (and of a sub-permutation `part`).
    fn permutation_seed(&self, dimension: u32, part: u32) -> u32 {
        hash_u64s(&[self.pixel_seed, u64::from(dimension), u64::from(part)]) as u32
    }

    /// The current sample's place π_d(i) in dimension `dimension`'s permutation of the pixel's
    /// N samples: its stratum of N in that dimension.
    fn stratum(&self, dimension: u32) -> u32 {
        permute(
            self.index,
            self.sample_count,
            self.permutation_seed(dimension, 0),
        )
    }

    /// Coordinate `dimension` of the current sample in a Latin hypercube over the pixel's N
    /// samples: stratum π_d(i) of N, jittered.
    fn latin_hypercube(&mut self, dimension: u32) -> f32 {
        let stratum = self.stratum(dimension);
        (stratum as f32 + self.jitter_value()) / self.sample_count as f32
    }

    /// Kensler 2013, "Correlated Multi-Jittered Sampling" (Pixar Technical Memo 13-01), §5: the
    /// canonical arrangement that is stratified on the m × n grid and on both axes into N strata,
    /// with the columns' and rows' shuffles correlated; the sample index itself is permuted first.
    fn correlated_multi_jittered(&mut self, dimension: u32) -> Vec2 {
        let (m, n) = (self.columns, self.rows);
        let s = self.stratum(dimension);
        let (x, y) = (s % m, s / m);
        let sx = permute(x, m, self.permutation_seed(dimension, 1));
        let sy = permute(y, n, self.permutation_seed(dimension, 2));
        let (jx, jy) = (self.jitter_value(), self.jitter_value());
        Vec2::new(
            (x as f32 + (sy as f32 + jx) / n as f32) / m as f32,
            (y as f32 + (sx as f32 + jy) / m as f32) / n as f32,
        )
    }
}

impl Sampler {
    /// Dimension `dimension` of the current sample in the pixel's orthogonal array of
    /// `strength` t over p = `levels` levels: the sample is run r = π(i) of the array (the same
    /// shuffle π in every dimension), the dimension's level a(r) is shuffled among the p
    /// levels, and the sub-stratum within the level, b(r) of N/p, is chosen so that the N runs
    /// also fall into N distinct strata of the dimension:
    /// x = (π_a(a) + (π_b(b) + ξ) p / N) / p.
    fn orthogonal_array(&mut self, dimension: u32, strength: u32) -> f32 {
        let p = self.levels;
        let n = self.sample_count;
        let run = permute(self.index, n, self.permutation_seed(u32::MAX, 0));
        let (level, sub_stratum, sub_strata) = if strength == 2 {
            // Bose: the run's digits (a₀, a₁); dimension j's level a₀ + (j − 1) a₁, its
            // sub-stratum the level of its partner dimension, so pairs (j, partner) are
            // correlated multi-jittered.
            let (a0, a1) = (run / p, run % p);
            let combination = |j: u32| (a0 + (j + p - 1) % p * a1) % p;
            match dimension {
                0 => (a0, a1, p),
                1 => (a1, a0, p),
                j => {
                    let partner = if j % 2 == 1 { j - 1 } else { j + 1 };
                    (combination(j), combination(partner), p)
                }
            }
        } else {
            // Bush: the t base-p digits of the run as the coefficients of a polynomial,
            // evaluated at j mod p (Horner's rule, mod p); the sub-stratum the run's other
            // digits, which together with the level determine the run.
            let x = dimension % p;
            let mut digits = [0u32; MAX_ORTHOGONAL_STRENGTH as usize];
            let mut rest = run;
            for digit in digits.iter_mut().take(strength as usize) {
                *digit = rest % p;
                rest /= p;
            }
            let level = digits[..strength as usize]
                .iter()
                .rev()
                .fold(0u32, |acc, &d| (acc * x + d) % p);
            (level, run / p, n / p)
        };
        let stratum = permute(level, p, self.permutation_seed(dimension, 1));
        let sub = permute(sub_stratum, sub_strata, self.permutation_seed(dimension, 2));
        let jitter = self.jitter_value();
        ((stratum as f32 + (sub as f32 + jitter) / sub_strata as f32) / p as f32)
            .min(1.0f32.next_down())
    }
}

/// The radical inverse of `index` in base 2 (its bits reversed), XOR-scrambled, as 32 bits of
/// a fraction.
fn radical_inverse_2(index: u32, scramble: u32) -> u32 {
    index.reverse_bits() ^ scramble
}

/// The second dimension of the Sobol' sequence (direction numbers v_k = 2^31 ⊕ … of the
/// primitive polynomial x + 1), XOR-scrambled, as 32 bits of a fraction.
fn sobol_2(mut index: u32, scramble: u32) -> u32 {
    let mut result = scramble;
    let mut v = 1u32 << 31;
    while index != 0 {
        if index & 1 != 0 {
            result ^= v;
        }
        index >>= 1;
        v ^= v >> 1;
    }
    result
}

/// A 32-bit fraction as a number in [0, 1): its top 24 bits, exactly representable.
fn unit_from_bits(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A pseudo-random permutation of [0, length), evaluated at `index` (Kensler 2013, §3): a
/// reversible hash of the index on the smallest power-of-two domain containing `length`, repeated
/// ("cycle walking") until the result falls below `length`.
pub fn permute(mut index: u32, length: u32, seed: u32) -> u32 {
    debug_assert!(index < length);
    if length <= 1 {
        return 0;
    }
    let mask = u32::MAX >> (length - 1).leading_zeros();
    loop {
        index ^= seed;
        index = index.wrapping_mul(0xe170_893d);
        index ^= seed >> 16;
        index ^= (index & mask) >> 4;
        index ^= seed >> 8;
        index = index.wrapping_mul(0x0929_eb3f);
        index ^= seed >> 23;
        index ^= (index & mask) >> 1;
        index = index.wrapping_mul(1 | (seed >> 27));
        index = index.wrapping_mul(0x6935_fa69);
        index ^= (index & mask) >> 11;
        index = index.wrapping_mul(0x74dc_b303);
        index ^= (index & mask) >> 2;
        index = index.wrapping_mul(0x9e50_1cc3);
        index ^= (index & mask) >> 2;
        index = index.wrapping_mul(0xc860_a3df);
        index &= mask;
        index ^= index >> 5;
        if index < length {
            return (index + seed) % length;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutations_are_bijections() {
        for length in [1u32, 2, 3, 7, 16, 100, 257, 1000] {
            for seed in [0u32, 1, 0xdead_beef, 12345] {
                let mut seen = vec![false; length as usize];
                for i in 0..length {
                    let p = permute(i, length, seed);
                    assert!(!seen[p as usize], "length {length} seed {seed}: {p} twice");
                    seen[p as usize] = true;
                }
            }
        }
    }

    /// Starting a pixel's samples one after another (each a multiply-add on from the last)
    /// gives the numbers of starting each one on its own, for every sampler kind, across
    /// blocks of N and after going back; the same after another pixel's samples.
    #[test]
    fn consecutive_samples_match_samples_started_alone() {
        let kinds = [
            SamplerKind::Independent,
            SamplerKind::NRooks,
            SamplerKind::Stratified { jitter: true },
            SamplerKind::MultiJitter { jitter: true },
        ];
        let numbers = |sampler: &mut Sampler| -> Vec<f32> {
            let c = sampler.camera_sample();
            let mut v = vec![c.wavelength, c.time, c.film.x, c.film.y, c.lens.x, c.lens.y];
            v.extend((0..6).map(|_| sampler.next_1d()));
            v
        };
        for kind in kinds {
            let mut running = Sampler::new(kind, 9, 3);
            let order = (0..20).chain([4, 5, 19, 20]).collect::<Vec<u32>>();
            for (step, &index) in order.iter().enumerate() {
                if step == 10 {
                    running.start_pixel_sample(UVec2::new(6, 1), 2);
                    running.next_1d();
                }
                running.start_pixel_sample(UVec2::new(5, 2), index);
                let mut alone = Sampler::new(kind, 9, 3);
                alone.start_pixel_sample(UVec2::new(5, 2), index);
                assert_eq!(
                    numbers(&mut running),
                    numbers(&mut alone),
                    "{kind:?} {index}"
                );
            }
        }
    }

    #[test]
    fn samples_are_reproducible_and_distinct() {
        let mut a = Sampler::new(SamplerKind::Independent, 16, 1);
        let mut b = Sampler::new(SamplerKind::Independent, 16, 1);
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
        let mut c = Sampler::new(SamplerKind::Independent, 16, 2);
        c.start_pixel_sample(UVec2::new(3, 4), 7);
        assert_ne!(first[0], c.next_1d());
    }

    #[test]
    fn sample_counts_are_rounded_as_mitsuba_does() {
        assert_eq!(
            SamplerKind::Stratified { jitter: true }.sample_count(10),
            16
        );
        assert_eq!(
            SamplerKind::Stratified { jitter: true }.sample_count(64),
            64
        );
        assert_eq!(
            SamplerKind::MultiJitter { jitter: true }.sample_count(10),
            12
        );
        assert_eq!(
            SamplerKind::MultiJitter { jitter: true }.sample_count(64),
            64
        );
        assert_eq!(SamplerKind::NRooks.sample_count(10), 10);
        assert_eq!(SamplerKind::Independent.sample_count(1), 1);
    }

    fn camera_samples(kind: SamplerKind, n: u32, pixel: UVec2) -> Vec<[f32; 6]> {
        let mut sampler = Sampler::new(kind, n, 9);
        (0..sampler.sample_count())
            .map(|i| {
                sampler.start_pixel_sample(pixel, i);
                let c = sampler.camera_sample();
                [c.wavelength, c.time, c.film.x, c.film.y, c.lens.x, c.lens.y]
            })
            .collect()
    }

    /// In each of the six primary dimensions, the N samples of a pixel occupy the N strata
    /// [k/N, (k+1)/N) exactly once each (nrooks and multijitter; the stratified sampler's 2-D
    /// grids are stratified in 2-D only, so only its 1-D dimensions are checked here).
    #[test]
    fn every_primary_dimension_has_one_sample_per_stratum() {
        for (kind, dimensions) in [
            (SamplerKind::NRooks, 6),
            (SamplerKind::MultiJitter { jitter: true }, 6),
            (SamplerKind::MultiJitter { jitter: false }, 6),
            (SamplerKind::Stratified { jitter: true }, 2),
        ] {
            for n in [1u32, 4, 16, 64, 100] {
                for pixel in [UVec2::new(0, 0), UVec2::new(17, 3)] {
                    let samples = camera_samples(kind, n, pixel);
                    let count = samples.len();
                    for d in 0..dimensions {
                        let mut strata = vec![0; count];
                        for s in &samples {
                            assert!((0.0..1.0).contains(&s[d]));
                            strata[(s[d] * count as f32) as usize] += 1;
                        }
                        assert!(
                            strata.iter().all(|&c| c == 1),
                            "{kind:?} n {n} dimension {d}: {strata:?}"
                        );
                    }
                }
            }
        }
    }

    /// The 2-D dimensions of the stratified and multi-jittered samplers put one sample in each cell
    /// of their grid.
    #[test]
    fn two_dimensional_grids_have_one_sample_per_cell() {
        for kind in [
            SamplerKind::Stratified { jitter: true },
            SamplerKind::MultiJitter { jitter: true },
        ] {
            for n in [4u32, 12, 64] {
                let (columns, rows) = kind.grid(n);
                let samples = camera_samples(kind, n, UVec2::new(5, 6));
                for (dx, dy) in [(2, 3), (4, 5)] {
                    let mut cells = vec![0; (columns * rows) as usize];
                    for s in &samples {
                        let cx = (s[dx] * columns as f32) as u32;
                        let cy = (s[dy] * rows as f32) as u32;
                        cells[(cy * columns + cx) as usize] += 1;
                    }
                    assert!(cells.iter().all(|&c| c == 1), "{kind:?} n {n}: {cells:?}");
                }
            }
        }
    }

    /// Sample indices past N form further blocks, each one sample per stratum again.
    #[test]
    fn later_blocks_are_stratified_too() {
        let mut sampler = Sampler::new(SamplerKind::NRooks, 16, 3);
        let block = |sampler: &mut Sampler, b: u32| -> Vec<f32> {
            (0..16)
                .map(|i| {
                    sampler.start_pixel_sample(UVec2::new(2, 2), b * 16 + i);
                    sampler.camera_sample().wavelength
                })
                .collect()
        };
        let (first, second) = (block(&mut sampler, 0), block(&mut sampler, 1));
        for values in [&first, &second] {
            let mut strata: Vec<u32> = values.iter().map(|v| (v * 16.0) as u32).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..16).collect::<Vec<u32>>());
        }
        assert_ne!(first, second, "the second block is shuffled anew");
    }

    /// Different dimensions are shuffled independently: the strata of wavelength and time are not
    /// the same permutation.
    #[test]
    fn dimensions_are_shuffled_independently() {
        let samples = camera_samples(SamplerKind::NRooks, 64, UVec2::new(1, 1));
        let same = samples
            .iter()
            .filter(|s| (s[0] * 64.0) as u32 == (s[1] * 64.0) as u32)
            .count();
        assert!(
            same < 8,
            "{same} samples share their wavelength and time strata"
        );
    }
}
