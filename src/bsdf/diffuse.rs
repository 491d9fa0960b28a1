//! Mitsuba's `diffuse` BSDF: the ideal Lambertian reflector, f = ρ/π.
//!
//! ```xml
//! <bsdf type="diffuse">
//!     <rgb name="reflectance" value="0.2, 0.25, 0.7"/>   <!-- default 0.5 -->
//! </bsdf>
//! ```
//! Sampled by Nusselt's analogue (cosine-weighted hemisphere), so the sample weight is ρ.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfSample};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

#[derive(Clone, Debug)]
pub struct Diffuse {
    pub reflectance: Spectrum,
}

impl Diffuse {
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::ZERO;
        }
        self.reflectance.sample(lambda) * (FRAC_1_PI * wi.z)
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi)
    }

    #[inline]
    pub fn sample(
        &self,
        wo: Vec3,
        _u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.reflectance.sample(lambda),
            pdf,
            flags: BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION),
        })
    }
}
