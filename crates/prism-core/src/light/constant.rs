//! Mitsuba's `constant` emitter: the same radiance arriving from every direction, at infinity.
//!
//! ```xml
//! <emitter type="constant">
//!     <rgb name="radiance" value="0.8, 0.9, 1.0"/>
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! A convex diffuse object of reflectance ρ in it has the radiance ρL everywhere (docs/testing.md,
//! Closed forms).
//! Light samples are uniform on the sphere of directions (as in Mitsuba); rays that leave the
//! scene see L, and the two are combined by multiple importance sampling.

use std::f32::consts::PI;

use glam::Vec2;

use super::{BoundingSphere, DirectionSample, Environment, LightAtInfinity};
use crate::sampling::warp::{sample_uniform_sphere, uniform_sphere_pdf};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

#[derive(Clone, Debug)]
pub struct ConstantLight {
    pub radiance: Spectrum,
    /// The scene's bounding sphere (set when the scene is assembled).
    pub scene: BoundingSphere,
}

impl ConstantLight {
    pub fn new(radiance: Spectrum) -> ConstantLight {
        ConstantLight {
            radiance,
            scene: BoundingSphere::default(),
        }
    }

    /// The radiance along any ray that leaves the scene.
    #[inline]
    pub fn radiance(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.radiance.sample(lambda)
    }

    /// Density of [`Self::sample_incident`]'s directions: 1/(4π) sr⁻¹.
    #[inline]
    pub fn pdf(&self) -> f32 {
        uniform_sphere_pdf()
    }
}

impl LightAtInfinity for ConstantLight {
    const IS_DELTA: bool = false;

    fn sample_direction(&self, u: Vec2, lambda: &SampledWavelengths) -> Option<DirectionSample> {
        let wi = sample_uniform_sphere(u);
        let radiance = self.radiance(lambda);
        Some(DirectionSample {
            wi,
            radiance,
            pdf: self.pdf(),
        })
    }

    fn environment(&self) -> Option<Environment<'_>> {
        Some(Environment::Constant(self))
    }

    /// Φ = π R² ∫ L dω = 4π² R² L: the flux entering the scene's bounding sphere (each
    /// direction crosses a disk of area πR²; pbrt-v4's `UniformInfiniteLight::Phi`).
    fn flux(&self) -> f32 {
        4.0 * PI * PI * self.scene.radius * self.scene.radius * self.radiance.luminance()
    }

    fn scene(&self) -> &BoundingSphere {
        &self.scene
    }

    fn scene_mut(&mut self) -> &mut BoundingSphere {
        &mut self.scene
    }
}
