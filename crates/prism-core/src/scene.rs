//! A scene as a file describes it: the world (geometry, materials, lights), the camera and its
//! film, the sampler, and the integrator.

use glam::UVec2;

use crate::camera::{Camera, Shutter};
use crate::film::output::ALPHA_CHANNEL;
use crate::film::{CropWindow, ExrOutput, Filter, LdrOutput, Reconstruction, SpectralBand};
use crate::integrator::Integrator;
pub use crate::sampling::sampler::SamplerKind;
use crate::spectrum::{Spectrum, WavelengthSampling};
use crate::world::World;

/// Film settings: size, crop window and reconstruction filter.
#[derive(Clone, Debug)]
pub struct FilmSettings {
    pub size: UVec2,
    pub crop: CropWindow,
    pub filter: Filter,
    /// How samples become pixel values.
    pub reconstruction: Reconstruction,
    /// The density the wavelengths of each camera sample are drawn from.
    pub wavelength_sampling: WavelengthSampling,
    /// The channels of a spectral film (`specfilm`), each an integral of the radiance against
    /// a response; none for other films.
    pub bands: Vec<SpectralBand>,
    /// The sensor's spectral response (Mitsuba's `srf`), by which the radiance arriving is
    /// multiplied at each wavelength before it becomes XYZ; None for a response of 1.
    pub response: Option<Spectrum>,
}

/// Which per-pixel sampler to use and how many samples per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplerSettings {
    pub kind: SamplerKind,
    pub samples_per_pixel: u32,
}

/// Everything needed to render an image.
pub struct Scene {
    pub world: World,
    pub camera: Camera,
    pub film: FilmSettings,
    pub sampler: SamplerSettings,
    /// The estimator and its parameters; it builds its light sampler from the world when a
    /// render starts.
    pub integrator: Integrator,
    /// When camera rays are taken (the sensor's shutter interval and temporal filter).
    pub shutter: Shutter,
    /// Which channels the EXR holds and how it stores them.
    pub exr_output: ExrOutput,
    /// How the 8-bit image beside the EXR is tonemapped and written.
    pub ldr_output: LdrOutput,
    /// Hash of the scene's description and the files it loads, which render states record so
    /// that a resumed render is of the same scene; 0 for scenes built in code.
    pub fingerprint: u64,
}

impl Scene {
    /// A scene from its parts, with an instantaneous shutter, the lecture's wavelength
    /// density, a 32-bit RGB EXR and the default sRGB PNG.
    pub fn new(
        world: World,
        camera: Camera,
        film: FilmSettings,
        sampler: SamplerSettings,
        integrator: Integrator,
    ) -> Scene {
        Scene {
            world,
            camera,
            film,
            sampler,
            integrator,
            shutter: Shutter::instant(),
            exr_output: ExrOutput::default(),
            ldr_output: LdrOutput::default(),
            fingerprint: 0,
        }
    }

    /// The names of the film's extra channels: the integrator's, then the coverage alpha `A`
    /// where the EXR has one, then a spectral film's bands.
    pub fn aov_names(&self) -> Vec<String> {
        let mut names = self.integrator.aov_names();
        if self.exr_output.pixel_format.has_alpha() {
            names.push(ALPHA_CHANNEL.into());
        }
        names.extend(self.film.bands.iter().map(|band| band.name.clone()));
        names
    }

    /// The samples per pixel of one stratified block of the sampler, for a render asked for
    /// `requested` samples per pixel: the sampler's count for that many
    /// ([`crate::sampling::sampler::SamplerKind::sample_count`]), or for half as many when the
    /// film shares samples between pixels, whose control variate takes alternate blocks as
    /// its two independent halves ([`crate::film::reconstruction`]).
    pub fn strata(&self, requested: u32) -> u32 {
        let kind = self.sampler.kind;
        if self.film.reconstruction.shares_samples(self.film.filter) {
            kind.sample_count(requested.div_ceil(2))
        } else {
            kind.sample_count(requested)
        }
    }
}
