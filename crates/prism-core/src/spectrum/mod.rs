//! Spectra: the CIE tables, sampled wavelengths and spectral values along a path, spectral
//! distributions from the scene (constants, tables, upsampled RGB, black bodies), and colour
//! conversions.
//!
//! Light transport is computed at four wavelengths per path; only the film converts the result
//! to CIE XYZ (and from there to sRGB).

pub mod blackbody;
pub mod cie;
pub mod cie_tables;
pub mod conductors;
pub mod ior;
pub mod rgb;
pub mod sampled;
pub mod spectra;

pub use sampled::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths, WavelengthSampling};
pub use spectra::{PiecewiseLinear, RgbIntent, Spectrum};

/// Shortest wavelength transported, in nm (the start of the CIE 1931 tables).
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength transported, in nm (the end of the CIE 1931 tables).
pub const LAMBDA_MAX: f32 = 830.0;
