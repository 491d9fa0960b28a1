//! Mitsuba 3's `pplastic` BSDF: a rough specular reflection added to a diffuse base seen
//! through two smooth refractions (after Baek et al. 2018, "Simultaneous Acquisition of
//! Polarimetric SVBRDF and Normals", as Mitsuba's `pplastic.cpp` evaluates it). Below its
//! unpolarised form; rendered polarized, its Mueller matrix is Mitsuba's polarized one
//! ([`GlossyDiffuseLobes::mueller`]).
//!
//! ```xml
//! <bsdf type="pplastic">
//!     <rgb name="diffuse_reflectance" value="0.05, 0.03, 0.1"/>  <!-- or a texture -->
//!     <float name="alpha" value="0.06"/>               <!-- or alpha_u and alpha_v -->
//!     <string name="distribution" value="beckmann"/>   <!-- or ggx -->
//!     <string name="int_ior" value="polypropylene"/>
//!     <string name="ext_ior" value="air"/>
//!     <rgb name="specular_reflectance" value="1"/>     <!-- optional factor -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! f cos θi = s F(wo·h) D(h) G(wo, wi, h) / (4 cos θo)                     (rough specular)
//!          + (1 − F(cos θo)) ρ (1 − F(cos θi)) cos θi / π                  (diffuse base)
//!
//! with F the dielectric Fresnel reflectance for the relative index η. Unlike `roughplastic`
//! the two parts are simply added: the base sees the coating as smooth, and no light bounces
//! between base and coating, so the model loses energy but never creates it. The specular part
//! is sampled by visible normals, the base by the cosine; the specular part is chosen with
//! probability s̄ / (s̄ + ρ̄) (Mitsuba takes the textures' means over the surface, Prism their
//! averages at the point over the path's wavelengths; only the noise differs). One-sided.

use std::f32::consts::FRAC_1_PI;

use glam::{Mat4, Vec2, Vec3};

use super::dielectric::optional_factor;
use super::fresnel::{fresnel_dielectric, reflect};
use super::glossydiffuse::{GLOSSY_OVER_DIFFUSE, GlossyDiffuseLobes};
use super::microfacet::{Microfacet, MicrofacetRoughness};
use super::{BsdfFlags, LeafBsdf, choice_probability};
use crate::polarization::fresnel::{Complex, specular_reflection, specular_transmission};
use crate::polarization::mueller::depolarizer;
use crate::polarization::{FrameChange, SampledMueller};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct PolarizedPlastic {
    /// The relative index η = int_ior / ext_ior.
    pub eta: f32,
    pub roughness: MicrofacetRoughness,
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Option<Texture>,
}

impl LeafBsdf for PolarizedPlastic {
    type Lobes<'a> = PolarizedPlasticLobes;
    const FLAGS: BsdfFlags = GLOSSY_OVER_DIFFUSE;

    /// The diffuse reflectance of the base.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.diffuse_reflectance.eval(at, lambda)
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> PolarizedPlasticLobes {
        let diffuse = self.diffuse_reflectance.eval(at, lambda);
        let specular = optional_factor(&self.specular_reflectance, at, lambda);
        let (s, d) = (specular.average(), diffuse.average());
        PolarizedPlasticLobes {
            eta: self.eta,
            distribution: self.roughness.at(at),
            diffuse,
            specular,
            p_specular: choice_probability(s, d),
        }
    }
}

/// The specular and diffuse parts at a point.
#[derive(Clone, Copy, Debug)]
pub struct PolarizedPlasticLobes {
    pub eta: f32,
    pub distribution: Microfacet,
    pub diffuse: SampledSpectrum,
    pub specular: SampledSpectrum,
    /// The probability of sampling the specular part.
    pub p_specular: f32,
}

impl GlossyDiffuseLobes for PolarizedPlasticLobes {
    #[inline]
    fn value(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        let h = (wo + wi).normalize();
        let d = self.distribution.d(h);
        let specular = if d > 0.0 {
            let f = fresnel_dielectric(wo.dot(h), self.eta).reflectance;
            self.specular * (f * d * self.distribution.g(wo, wi, h) / (4.0 * wo.z))
        } else {
            SampledSpectrum::ZERO
        };
        let t_o = 1.0 - fresnel_dielectric(wo.z, self.eta).reflectance;
        let t_i = 1.0 - fresnel_dielectric(wi.z, self.eta).reflectance;
        specular + self.diffuse * (t_o * t_i * wi.z * FRAC_1_PI)
    }

    /// Mitsuba's polarized `pplastic`: the specular part Fresnel reflection about the half
    /// vector; the base, light refracted in (T at wi), depolarized by ρ and refracted out (T at
    /// the inner angle of wo, with 1/η), in the frame of the plane of incidence.
    fn mueller(&self, wo: Vec3, wi: Vec3) -> Option<SampledMueller> {
        let h = (wo + wi).normalize();
        let d = self.distribution.d(h);
        let glossy = if d > 0.0 && h.is_finite() {
            let scale = d * self.distribution.g(wo, wi, h) / (4.0 * wo.z);
            let change = FrameChange::from_plane_of_incidence(h, -wi, wo);
            change.apply(specular_reflection(wi.dot(h), Complex::real(self.eta))) * scale
        } else {
            Mat4::ZERO
        };
        let inward = specular_transmission(wi.z.abs(), self.eta);
        let cos_inner = fresnel_dielectric(wo.z, self.eta).cos_theta_t.abs();
        let outward = specular_transmission(cos_inner, 1.0 / self.eta);
        let base = FrameChange::from_plane_of_incidence(Vec3::Z, -wi, wo)
            .apply(outward * depolarizer(1.0) * inward)
            * (wi.z * FRAC_1_PI);
        Some(SampledMueller::from_fn(|i| {
            glossy * self.specular[i] + base * self.diffuse[i]
        }))
    }

    #[inline]
    fn glossy_probability(&self, _wo: Vec3) -> f32 {
        self.p_specular
    }

    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Vec3 {
        reflect(wo, self.distribution.sample_visible(wo, u))
    }

    #[inline]
    fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize();
        let (cos_oh, cos_ih) = (wo.dot(h), wi.dot(h));
        if cos_oh > 0.0 && cos_ih > 0.0 {
            self.distribution.pdf_visible(wo, h) / (4.0 * cos_oh)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod polarized_tests {
    use super::*;
    use crate::bsdf::microfacet::MicrofacetKind;
    use crate::sampling::rng::Pcg32;
    use crate::sampling::warp::sample_cosine_hemisphere;

    /// The polarized model's M₀₀ is the unpolarized value, so that a polarized render's S₀
    /// carries the same energy; and it never turns unpolarized light into more than fully
    /// polarized light.
    #[test]
    fn the_first_element_is_the_unpolarized_value() {
        let lobes = PolarizedPlasticLobes {
            eta: 1.49,
            distribution: Microfacet::new(MicrofacetKind::Ggx, 0.2, 0.2),
            diffuse: SampledSpectrum([0.1, 0.4, 0.7, 0.9]),
            specular: SampledSpectrum([1.0, 0.8, 1.0, 0.6]),
            p_specular: 0.5,
        };
        let mut rng = Pcg32::seeded(5);
        for _ in 0..500 {
            let wo = sample_cosine_hemisphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            let wi = sample_cosine_hemisphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            let value = GlossyDiffuseLobes::value(&lobes, wo, wi);
            let m = GlossyDiffuseLobes::mueller(&lobes, wo, wi).unwrap();
            for i in 0..4 {
                let m00 = m.0[i].x_axis.x;
                assert!(
                    (m00 - value[i]).abs() <= 1e-4 * value[i].max(1e-3),
                    "{m00} {}",
                    value[i]
                );
                let s = m.0[i].x_axis;
                assert!(
                    Vec3::new(s.y, s.z, s.w).length() <= s.x * (1.0 + 1e-4),
                    "{s}"
                );
            }
        }
    }
}
