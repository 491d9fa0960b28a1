//! Mitsuba's `roughconductor` BSDF: a rough metal, the microfacet model of Walter et al. 2007
//! ("Microfacet Models for Refraction through Rough Surfaces", eq. 20) with the conductor
//! Fresnel term.
//!
//! ```xml
//! <bsdf type="roughconductor">
//!     <string name="material" value="Al"/>           <!-- or eta and k; default "none": F = 1 -->
//!     <string name="distribution" value="ggx"/>      <!-- or beckmann (the default) -->
//!     <float name="alpha_u" value="0.05"/>           <!-- or alpha for both; default 0.1 -->
//!     <float name="alpha_v" value="0.3"/>            <!-- (floats or textures) -->
//!     <rgb name="specular_reflectance" value="1"/>   <!-- optional factor -->
//! </bsdf>
//! ```
//! f(wo, wi) cos θi = F(wo·h) D(h) G(wo, wi, h) / (4 cos θo) with h the half vector; sampled by
//! visible normals (Heitz & d'Eon 2014), so the weight is F(wo·m) G₁(wi, m). α_u runs along
//! ∂p/∂u. One-sided.

use glam::{Vec2, Vec3};

use super::conductor::conductor_reflectance;
use super::fresnel::reflect;
use super::microfacet::{Microfacet, MicrofacetKind};
use super::{BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct RoughConductor {
    pub distribution: MicrofacetKind,
    pub alpha_u: Texture,
    pub alpha_v: Texture,
    pub eta: Texture,
    pub k: Texture,
    pub specular_reflectance: Texture,
}

impl RoughConductor {
    pub fn flags(&self) -> BsdfFlags {
        BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION)
    }

    /// The microfacet distribution at the shading point.
    #[inline]
    fn microfacet(&self, sp: &ShadingPoint) -> Microfacet {
        Microfacet::new(
            self.distribution,
            self.alpha_u.eval_1(sp.uv),
            self.alpha_v.eval_1(sp.uv),
        )
    }

    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return SampledSpectrum::ZERO;
        }
        let h = (wo + wi).normalize();
        let distribution = self.microfacet(sp);
        let d = distribution.d(h);
        if d == 0.0 {
            return SampledSpectrum::ZERO;
        }
        let g = distribution.g(wo, wi, h);
        let f = conductor_reflectance(&self.eta, &self.k, sp.uv, wo.dot(h), lambda);
        f * self.specular_reflectance.eval(sp.uv, lambda) * (d * g / (4.0 * wo.z))
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, _lambda: &SampledWavelengths) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        // The visible-normal density, times the Jacobian 1/(4 wo·h) of the reflection map.
        self.microfacet(sp).pdf_visible(wo, h) / (4.0 * wo.dot(h))
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        _u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let distribution = self.microfacet(sp);
        let m = distribution.sample_visible(wo, u);
        let wi = reflect(wo, m);
        let cos_om = wo.dot(m);
        if !(wi.z > 0.0 && cos_om > 0.0) {
            return None;
        }
        let pdf = distribution.pdf_visible(wo, m) / (4.0 * cos_om);
        if !(pdf > 0.0) {
            return None;
        }
        let f = conductor_reflectance(&self.eta, &self.k, sp.uv, cos_om, lambda);
        let weight = f * self.specular_reflectance.eval(sp.uv, lambda) * distribution.g1(wi, m);
        Some(BsdfSample::new(wi, weight, pdf, self.flags()))
    }
}
