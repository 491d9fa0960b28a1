//! The benchmark suite behind `prism bench`: fixed scenes, and for each the BVH build time, its
//! memory, incoherent rays/s, samples/s and the relative MSE reached in a fixed time.

pub mod generated;
