//! The film: reconstruction filters and their samplers, how samples become pixel values, per-pixel accumulation of XYZ, splatting, the
//! error estimated from the samples, a spectral film's channels, and the images written at the end (an EXR, and an 8-bit
//! image tonemapped as the film asks).

pub mod accumulation;
pub mod filter;
pub mod ldr;
pub mod output;
pub mod reconstruction;
pub mod spectral_bands;
pub mod splat;
pub mod stats;

pub use accumulation::{CropWindow, Film, PixelSums, ValueSum};
pub use filter::{
    BoxFilter, Filter, FilterSampler, GaussianFilter, Kernel, LanczosFilter, MitchellFilter,
    TentFilter,
};
pub use ldr::{LdrFormat, LdrOutput, Tonemap, TransferCurve};
pub use output::{
    ComponentFormat, ExrOutput, FilmImages, ImageOutput, PixelFormat, RenderMetadata, write_images,
    write_images_with,
};
pub use reconstruction::{FilterMis, Reconstruction};
pub use spectral_bands::SpectralBand;
pub use splat::{SplatSums, SplatValue, Splatter};
