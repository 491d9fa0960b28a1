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

use super::{BsdfEval, BsdfFlags, BsdfModel, BsdfSample, Bxdf, BxdfTree, NodeId, ShadingPoint};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct Diffuse {
    pub reflectance: Texture,
}

const FLAGS: BsdfFlags = BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION);

impl BsdfModel for Diffuse {
    fn flags(&self) -> BsdfFlags {
        FLAGS
    }

    fn is_dispersive(&self) -> bool {
        false
    }

    fn node_count(&self) -> usize {
        1
    }

    /// The reflectance.
    fn diffuse_reflectance(
        &self,
        point: &ShadingPoint,
        _wo: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.reflectance.eval(point.at(), lambda)
    }

    #[inline]
    fn resolve<'a>(
        &'a self,
        point: &ShadingPoint,
        _wo: Vec3,
        lambda: &SampledWavelengths,
        tree: &mut BxdfTree<'a>,
    ) -> NodeId {
        tree.push(DiffuseLobes {
            reflectance: self.reflectance.eval(point.at(), lambda),
        })
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
        Some(BsdfSample::new(wi, self.reflectance, pdf, FLAGS))
    }
}
