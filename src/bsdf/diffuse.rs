//! Mitsuba's `diffuse` BSDF: the ideal Lambertian reflector, f = ρ/π.
//!
//! ```xml
//! <bsdf type="diffuse">
//!     <rgb name="reflectance" value="0.2, 0.25, 0.7"/>   <!-- or a texture; default 0.5 -->
//! </bsdf>
//! ```
//! Sampled by Nusselt's analogue (cosine-weighted hemisphere, the lecture's "Importance Sampling
//! of the Reflection Integral"), so the sample weight is ρ. One-sided: black from behind.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Diffuse {
    pub reflectance: Texture,
}

impl Diffuse {
    pub fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION)
    }

    #[inline]
    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return SampledSpectrum::ZERO;
        }
        self.reflectance.eval(sp.uv, lambda) * (FRAC_1_PI * wi.z)
    }

    #[inline]
    pub fn pdf(&self, _sp: &ShadingPoint, wo: Vec3, wi: Vec3, _lambda: &SampledWavelengths) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        cosine_hemisphere_pdf(wi)
    }

    #[inline]
    pub fn sample(
        &self,
        sp: &ShadingPoint,
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
        Some(BsdfSample::new(
            wi,
            self.reflectance.eval(sp.uv, lambda),
            pdf,
            self.flags(),
        ))
    }
}
