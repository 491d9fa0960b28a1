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
pub mod interpolation;
pub mod ior;
pub mod rgb;
pub mod sampled;
pub mod spectra;

pub use cie::{LAMBDA_MAX, LAMBDA_MIN};
pub use sampled::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths, WavelengthSampling};
pub use spectra::{PiecewiseLinear, RgbIntent, Spectrum};
