//! Mitsuba's `diffuse` BSDF: the ideal Lambertian reflector, f = ρ/π.
//!
//! ```xml
//! <bsdf type="diffuse">
//!     <rgb name="reflectance" value="0.2, 0.25, 0.7"/>   <!-- or a texture -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Sampled by Nusselt's analogue (cosine-weighted hemisphere, the lecture's "Importance Sampling
//! of the Reflection Integral"), so the sample weight is ρ. One-sided: black from behind.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct Diffuse {
    pub reflectance: Texture,
}

impl LeafBsdf for Diffuse {
    type Lobes<'a> = DiffuseLobes;
    const FLAGS: BsdfFlags = BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION);

    /// The reflectance.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.reflectance.eval(at, lambda)
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> DiffuseLobes {
        DiffuseLobes {
            reflectance: self.reflectance.eval(at, lambda),
        }
    }
}

/// The diffuse lobe at a point.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseLobes {
    pub reflectance: SampledSpectrum,
}

impl Bxdf for DiffuseLobes {
    #[inline]
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return BsdfEval::ZERO;
        }
        BsdfEval {
            value: self.reflectance * (FRAC_1_PI * wi.z),
            pdf: cosine_hemisphere_pdf(wi),
        }
    }

    #[inline]
    fn sample(&self, _tree: &BxdfTree, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample::new(wi, self.reflectance, pdf, Diffuse::FLAGS))
    }
}
