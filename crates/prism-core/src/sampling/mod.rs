//! Sampling: random numbers, warps from the unit square, tabulated distributions and the
//! per-pixel sampler.
pub mod distribution;
pub mod rng;
pub mod sampler;
pub mod spherical_rectangle;
pub mod warp;
