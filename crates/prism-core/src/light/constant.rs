//! Mitsuba's `constant` emitter: the same radiance arriving from every direction, at infinity.
//!
//! ```xml
//! <emitter type="constant">
//!     <rgb name="radiance" value="0.8, 0.9, 1.0"/>   <!-- default 1 -->
//! </emitter>
//! ```
//! A convex diffuse object of reflectance ρ in it has the radiance ρL everywhere (DESIGN.md §7).
//! Light samples are uniform on the sphere of directions (as in Mitsuba); rays that leave the
//! scene see L, and the two are combined by multiple importance sampling.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{BoundingSphere, Environment, LightBounds, LightSample, LightSource};
use crate::geometry::Primitive;
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

impl LightSource for ConstantLight {
    fn sample_incident(
        &self,
        _shapes: &[Primitive],
        reference: Vec3,
        _time: f32,
        _u_choice: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightSample> {
        let wi = sample_uniform_sphere(u);
        let radiance = self.radiance(lambda);
        Some(LightSample::from_infinity(
            &self.scene,
            reference,
            wi,
            radiance,
            self.pdf(),
            false,
        ))
    }

    /// Φ = π R² ∫ L dω = 4π² R² L: the flux entering the scene's bounding sphere (each
    /// direction crosses a disk of area πR²; pbrt-v4's `UniformInfiniteLight::Phi`).
    fn power(&self, _shapes: &[Primitive]) -> f32 {
        4.0 * PI * PI * self.scene.radius * self.scene.radius * self.radiance.luminance()
    }

    fn bounds(&self, _shapes: &[Primitive]) -> Option<LightBounds> {
        None
    }

    fn set_scene_bounds(&mut self, bounds: BoundingSphere) {
        self.scene = bounds;
    }

    fn as_environment(&self) -> Option<Environment<'_>> {
        Some(Environment::Constant(self))
    }
}
