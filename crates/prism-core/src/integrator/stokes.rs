//! Mitsuba 3's `stokes` integrator: the Stokes vector at the sensor of the estimator it nests,
//! rendered polarized (`path`, [`super::polarized_path`]; `volpath` or `volpathmis`,
//! [`super::polarized_volpath`]), written as twelve extra channels `S0.R`, `S0.G`, `S0.B`, …
//! `S3.B` (each Stokes component's spectral estimate as linear sRGB, as Mitsuba names and
//! converts them), beside the image of its intensity S₀.
//!
//! ```xml
//! <integrator type="stokes">
//!     <integrator type="volpath"/>
//! </integrator>
//! ```
//!
//! The Stokes vector arrives in the implicit basis of the reversed camera ray; as in Mitsuba's
//! `stokes.cpp` it is turned into the basis whose "horizontal" is d × up, d the camera ray and
//! up the sensor's +y axis in world space; S₃ > 0 is right circular light, seen from the
//! sensor.

use glam::Vec3;

use crate::integrator::SampleContext;
use crate::integrator::polarized_path::PolarizedPathIntegrator;
use crate::integrator::polarized_volpath::PolarizedVolPathIntegrator;
use crate::light::LightSelection;
use crate::math::Ray;
use crate::polarization::mueller::{rotate_stokes_basis, stokes_basis};
use crate::spectrum::cie::{XYZ_TO_LINEAR_SRGB, mul3};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct StokesIntegrator {
    /// The polarized integrator it runs.
    pub nested: PolarizedIntegrator,
    /// The sensor's up direction (its +y axis) in world space.
    pub sensor_up: Vec3,
}

impl StokesIntegrator {
    /// The channels, as Mitsuba names them.
    pub fn aov_names(&self) -> Vec<String> {
        (0..4)
            .flat_map(|i| ["R", "G", "B"].map(|c| format!("S{i}.{c}")))
            .collect()
    }

    /// The intensity S₀ along `ray`; the four Stokes components go to `aovs` as linear sRGB.
    pub(super) fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        lambda: &SampledWavelengths,
        aovs: &mut [f32],
    ) -> SampledSpectrum {
        let stokes = match &self.nested {
            PolarizedIntegrator::Path(path) => path.stokes(ctx, ray, lambda),
            PolarizedIntegrator::VolPath(volpath) => volpath.stokes(ctx, ray, lambda),
        };
        let d = ray.d.normalize();
        let rotation = rotate_stokes_basis(-d, stokes_basis(-d), d.cross(self.sensor_up));
        let stokes = stokes.map(|s| rotation * s);
        for (component, channels) in aovs.chunks_exact_mut(3).enumerate() {
            let values = SampledSpectrum::from_fn(|i| stokes[i][component]);
            channels.copy_from_slice(&mul3(&XYZ_TO_LINEAR_SRGB, lambda.to_xyz(&values)));
        }
        SampledSpectrum::from_fn(|i| stokes[i].x)
    }
}

/// The estimators `stokes` runs polarized: `path`, or `volpath` and `volpathmis`.
#[derive(Clone, Debug)]
pub enum PolarizedIntegrator {
    Path(PolarizedPathIntegrator),
    VolPath(PolarizedVolPathIntegrator),
}

impl PolarizedIntegrator {
    /// How one light is chosen for each light sample.
    pub fn light_selection(&self) -> LightSelection {
        match self {
            PolarizedIntegrator::Path(path) => path.light_selection(),
            PolarizedIntegrator::VolPath(volpath) => volpath.light_selection(),
        }
    }

    /// Whether emitters seen directly by the camera are left black.
    pub fn hides_emitters(&self) -> bool {
        match self {
            PolarizedIntegrator::Path(path) => path.path.hide_emitters,
            PolarizedIntegrator::VolPath(volpath) => volpath.volpath.hide_emitters,
        }
    }

    /// Longest path in vertices after the camera; negative for unbounded.
    pub fn max_depth(&self) -> i32 {
        match self {
            PolarizedIntegrator::Path(path) => path.path.max_depth,
            PolarizedIntegrator::VolPath(volpath) => volpath.volpath.max_depth,
        }
    }
}
