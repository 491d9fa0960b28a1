//! The film: reconstruction filters and their samplers, per-pixel accumulation of XYZ, and
//! image files (OpenEXR, PNG).

pub mod accumulation;
pub mod filter;
pub mod output;

pub use accumulation::{CropWindow, Film, PixelSums};
pub use filter::{Filter, FilterSampler};
