//! Mitsuba's `area` emitter: a shape that emits radiance from the side its normal points to.
//!
//! ```xml
//! <shape type="rectangle">
//!     <emitter type="area">
//!         <rgb name="radiance" value="17, 12, 4"/>   <!-- default: D65 of luminance 1 -->
//!     </emitter>
//! </shape>
//! ```
//! Light samples come from the shape ([`crate::geometry::Primitive::sample_from`]): spheres by the
//! cone of directions they subtend (uniform in solid angle, so no sample is wasted on the far
//! side; the lecture's "Direct Light Sampling"), other shapes uniformly by area, triangle meshes
//! choosing a triangle by area through an alias table. As in Mitsuba, an emitting shape that
//! names no BSDF gets a black one.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::LightSample;
use crate::geometry::Primitive;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// Index of the emitting shape in the scene.
    pub shape: u32,
    pub radiance: Spectrum,
}

impl AreaLight {
    /// Radiance leaving a point with shading normal `n` in direction `w` (one-sided).
    #[inline]
    pub fn emitted(&self, n: Vec3, w: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        if n.dot(w) > 0.0 {
            self.radiance.sample(lambda)
        } else {
            SampledSpectrum::ZERO
        }
    }

    pub fn sample_incident(
        &self,
        shapes: &[Primitive],
        reference: Vec3,
        time: f32,
        u_choice: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightSample> {
        let shape = &shapes[self.shape as usize];
        let s = shape.sample_from(reference, time, u_choice, u)?;
        let d = s.p - reference;
        let dist = d.length();
        if !(dist > 0.0) || !(s.pdf > 0.0) || !s.pdf.is_finite() {
            return None;
        }
        let wi = d / dist;
        let radiance = self.emitted(s.shading_n, -wi, lambda);
        if radiance.is_black() {
            return None;
        }
        Some(LightSample {
            p: s.p,
            n: s.n,
            wi,
            radiance,
            pdf: s.pdf,
            is_delta: false,
        })
    }

    /// Φ = π · A · L for a one-sided Lambertian emitter, with L the luminance of the radiance.
    pub fn power(&self, shapes: &[Primitive]) -> f32 {
        PI * shapes[self.shape as usize].area() * self.radiance.luminance()
    }
}
