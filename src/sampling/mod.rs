//! Sampling: random numbers, warps, distributions and the per-pixel sampler.
pub mod rng;
