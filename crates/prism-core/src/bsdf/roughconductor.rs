//! Mitsuba's `roughconductor` BSDF: a rough metal, the microfacet model of Walter et al. 2007
//! ("Microfacet Models for Refraction through Rough Surfaces", eq. 20) with the conductor
//! Fresnel term.
//!
//! ```xml
//! <bsdf type="roughconductor">
//!     <string name="material" value="Al"/>           <!-- or eta and k -->
//!     <string name="distribution" value="ggx"/>      <!-- or beckmann -->
//!     <float name="alpha_u" value="0.05"/>           <!-- or alpha for both -->
//!     <float name="alpha_v" value="0.3"/>            <!-- (floats or textures) -->
//!     <rgb name="specular_reflectance" value="1"/>   <!-- optional factor -->
//!     <float name="ext_eta" value="1.33"/>           <!-- Mitsuba 0.6: exterior index -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! f(wo, wi) cos θi = F(wo·h) D(h) G(wo, wi, h) / (4 cos θo) with h the half vector; sampled by
//! visible normals (Heitz & d'Eon 2014), so the weight is F(wo·m) G₁(wi, m). α_u runs along
//! ∂p/∂u. One-sided.

use glam::{Vec2, Vec3};

use super::conductor::ConductorIor;
use super::fresnel::reflect;
use super::microfacet::{Microfacet, MicrofacetRoughness};
use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::polarization::SampledMueller;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct RoughConductor {
    pub roughness: MicrofacetRoughness,
    pub eta: Texture,
    pub k: Texture,
    pub specular_reflectance: Texture,
    /// The exterior medium's index (Mitsuba 0.6's `extEta`); 1 when the scene gives none.
    pub ext_eta: f32,
}

/// No diffuse reflectance: only a glossy lobe (Mitsuba 3 evaluates the BSDF towards the normal
/// instead, see docs/mitsuba-compatibility.md).
impl LeafBsdf for RoughConductor {
    type Lobes<'a> = RoughConductorLobes;
    const FLAGS: BsdfFlags = BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION);

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> RoughConductorLobes {
        RoughConductorLobes {
            distribution: self.roughness.at(at),
            ior: ConductorIor::at(&self.eta, &self.k, self.ext_eta, at, lambda),
            specular_reflectance: self.specular_reflectance.eval(at, lambda),
        }
    }
}

/// The glossy lobe at a point.
#[derive(Clone, Copy, Debug)]
pub struct RoughConductorLobes {
    pub distribution: Microfacet,
    pub ior: ConductorIor,
    pub specular_reflectance: SampledSpectrum,
}

impl Bxdf for RoughConductorLobes {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return BsdfEval::ZERO;
        }
        let h = (wo + wi).normalize();
        // The visible-normal density, times the Jacobian 1/(4 wo·h) of the reflection map.
        let pdf = self.distribution.pdf_visible(wo, h) / (4.0 * wo.dot(h));
        let d = self.distribution.d(h);
        if d == 0.0 {
            return BsdfEval {
                value: SampledSpectrum::ZERO,
                pdf,
            };
        }
        let g = self.distribution.g(wo, wi, h);
        let f = self.ior.reflectance(wo.dot(h));
        BsdfEval {
            value: f * self.specular_reflectance * (d * g / (4.0 * wo.z)),
            pdf,
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let m = self.distribution.sample_visible(wo, u);
        let wi = reflect(wo, m);
        let cos_om = wo.dot(m);
        if !(wi.z > 0.0 && cos_om > 0.0) {
            return None;
        }
        let pdf = self.distribution.pdf_visible(wo, m) / (4.0 * cos_om);
        if !(pdf > 0.0) {
            return None;
        }
        let f = self.ior.reflectance(cos_om);
        let weight = f * self.specular_reflectance * self.distribution.g1(wi, m);
        Some(BsdfSample::new(wi, weight, pdf, RoughConductor::FLAGS))
    }

    /// Fresnel reflection about the half vector (Mitsuba's `roughconductor`).
    fn mueller(
        &self,
        _tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        _lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        let h = (wo + wi).normalize();
        h.is_finite()
            .then(|| self.ior.mueller_reflection(h, wo, wi))
    }
}
