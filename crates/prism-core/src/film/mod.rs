//! The film: reconstruction filters and their samplers, per-pixel accumulation of XYZ, the
//! error estimated from the samples, and the images written at the end.

pub mod accumulation;
pub mod filter;
pub mod output;
pub mod stats;

pub use accumulation::{CropWindow, Film, PixelSums, ValueSum};
pub use filter::{Filter, FilterSampler};
pub use output::write_images;
