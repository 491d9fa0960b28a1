//! Sampling: random numbers, warps from the unit square, tabulated distributions, the
//! per-pixel sampler, and the chi-square test of a sampling routine against its density.
pub mod chi2;
pub mod distribution;
pub mod marginal2d;
pub mod rng;
pub mod sampler;
pub mod spherical_rectangle;
pub mod warp;
