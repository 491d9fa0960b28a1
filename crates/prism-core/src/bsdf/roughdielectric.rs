//! Mitsuba's `roughdielectric` BSDF: a rough interface between two dielectrics (frosted glass),
//! Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eqs. 20–21.
//!
//! ```xml
//! <bsdf type="roughdielectric">
//!     <string name="distribution" value="beckmann"/>   <!-- or ggx -->
//!     <float name="alpha" value="0.1"/>                <!-- or alpha_u, alpha_v; textures too -->
//!     <string name="int_ior" value="bk7"/>             <!-- as for dielectric -->
//!     <string name="ext_ior" value="air"/>
//!     <rgb name="specular_reflectance" value="1"/>     <!-- optional factors -->
//!     <rgb name="specular_transmittance" value="1"/>
//! </bsdf>
//! ```
//! With m the (generalised) half vector, η the relative index in the direction of travel,
//!
//!   reflection:   f cos θi = F D G / (4 |cos θo|),
//!   transmission: f cos θi = |(1 − F) D G (wo·m)(wi·m) / (cos θo (wo·m + η wi·m)²)|,
//!
//! the latter including Mitsuba's (1/η)² for radiance crossing the interface. Sampling draws a
//! visible normal, then reflection or refraction with probabilities F and 1 − F. Both sides
//! are handled (the normal is mirrored to the side of wo).
//!
//! A dispersive index is evaluated at the hero wavelength only; the integrator drops the other
//! wavelengths before using such a BSDF, and refracted samples say so too.

use glam::{Vec2, Vec3};

use super::dielectric::{SpecularFactorTextures, SpecularFactors};
use super::fresnel::{fresnel_dielectric, reflect, refract};
use super::microfacet::{Microfacet, MicrofacetRoughness};
use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::spectrum::ior::RelativeIor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::TexturePoint;

#[derive(Clone, Debug)]
pub struct RoughDielectric {
    pub eta: RelativeIor,
    pub roughness: MicrofacetRoughness,
    pub specular: SpecularFactorTextures,
}

/// No diffuse reflectance: only glossy lobes (Mitsuba 3 evaluates the BSDF towards the normal
/// instead, see docs/mitsuba-compatibility.md).
impl LeafBsdf for RoughDielectric {
    type Lobes<'a> = RoughDielectricLobes;
    const FLAGS: BsdfFlags = BsdfFlags::GLOSSY
        .union(BsdfFlags::REFLECTION)
        .union(BsdfFlags::TRANSMISSION);

    fn is_dispersive(&self) -> bool {
        self.eta.is_dispersive()
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> RoughDielectricLobes {
        RoughDielectricLobes {
            eta_hero: self.eta.at(lambda.lambda(0)),
            dispersive: self.eta.is_dispersive(),
            distribution: self.roughness.at(at),
            specular: self.specular.at(at, lambda),
        }
    }
}

/// The glossy reflection and transmission at a point.
#[derive(Clone, Copy, Debug)]
pub struct RoughDielectricLobes {
    /// η at the hero wavelength, which all lobes use.
    pub eta_hero: f32,
    pub dispersive: bool,
    pub distribution: Microfacet,
    pub specular: SpecularFactors,
}

/// The half vector of a pair of directions and what goes with it.
struct HalfVector {
    m: Vec3,
    reflect: bool,
    /// Relative index in the direction of travel, seen from wo's side.
    eta: f32,
}

impl RoughDielectricLobes {
    /// The half vector for (wo, wi), on the upper side; None for a grazing wo or a degenerate pair.
    #[inline]
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<HalfVector> {
        if wo.z == 0.0 {
            return None;
        }
        let reflect = wo.z * wi.z > 0.0;
        let eta = if wo.z > 0.0 {
            self.eta_hero
        } else {
            1.0 / self.eta_hero
        };
        let m = (wo + wi * if reflect { 1.0 } else { eta }).normalize_or_zero();
        if m == Vec3::ZERO {
            return None;
        }
        Some(HalfVector {
            m: if m.z < 0.0 { -m } else { m },
            reflect,
            eta,
        })
    }

    /// f(wo, wi)·|cos θi| for the half vector of the pair.
    #[inline]
    fn value(&self, wo: Vec3, wi: Vec3, half: &HalfVector) -> SampledSpectrum {
        let HalfVector { m, reflect, eta } = *half;
        let d = self.distribution.d(m);
        let g = self.distribution.g(wo, wi, m);
        if d == 0.0 || g == 0.0 {
            return SampledSpectrum::ZERO;
        }
        let f = fresnel_dielectric(wo.dot(m), self.eta_hero).reflectance;
        if reflect {
            self.specular.reflectance * (f * d * g / (4.0 * wo.z.abs()))
        } else {
            let (om, im) = (wo.dot(m), wi.dot(m));
            let denominator = om + eta * im;
            let value = ((1.0 - f) * d * g * om * im / (wo.z * denominator * denominator)).abs();
            self.specular.transmittance * value
        }
    }

    /// The density of sampling wi, for the half vector of the pair.
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3, half: &HalfVector) -> f32 {
        let HalfVector { m, reflect, eta } = *half;
        let (om, im) = (wo.dot(m), wi.dot(m));
        // The microsurface must agree with the macrosurface about the sides (as G₁ does).
        if !(om * wo.z > 0.0 && im * wi.z > 0.0) {
            return 0.0;
        }
        let jacobian = if reflect {
            1.0 / (4.0 * im)
        } else {
            let denominator = om + eta * im;
            eta * eta * im / (denominator * denominator)
        };
        let wo_up = if wo.z > 0.0 { wo } else { -wo };
        let f = fresnel_dielectric(om, self.eta_hero).reflectance;
        let choice = if reflect { f } else { 1.0 - f };
        (self.distribution.pdf_visible(wo_up, m) * choice * jacobian).abs()
    }
}

impl Bxdf for RoughDielectricLobes {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let Some(half) = self.half_vector(wo, wi) else {
            return BsdfEval::ZERO;
        };
        BsdfEval {
            value: self.value(wo, wi, &half),
            pdf: self.pdf(wo, wi, &half),
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.z.is_finite() {
            return None;
        }
        let wo_up = if wo.z > 0.0 { wo } else { -wo };
        let m = self.distribution.sample_visible(wo_up, u);
        let pdf_m = self.distribution.pdf_visible(wo_up, m);
        if !(pdf_m > 0.0) {
            return None;
        }
        let om = wo.dot(m);
        let fresnel = fresnel_dielectric(om, self.eta_hero);
        let f = fresnel.reflectance;
        let mut sample = if u_lobe < f {
            let wi = reflect(wo, m);
            let pdf = pdf_m * f / (4.0 * wi.dot(m)).abs();
            BsdfSample::new(
                wi,
                self.specular.reflectance,
                pdf,
                BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION),
            )
        } else {
            if f >= 1.0 {
                return None;
            }
            let wi = refract(wo, m, fresnel.cos_theta_t, fresnel.eta_ti);
            let im = wi.dot(m);
            let denominator = om + fresnel.eta_it * im;
            let jacobian = fresnel.eta_it * fresnel.eta_it * im / (denominator * denominator);
            let weight = self.specular.transmittance * (fresnel.eta_ti * fresnel.eta_ti);
            BsdfSample {
                wi,
                weight,
                pdf: (pdf_m * (1.0 - f) * jacobian).abs(),
                flags: BsdfFlags::GLOSSY.union(BsdfFlags::TRANSMISSION),
                eta: fresnel.eta_it,
                terminates_secondary: self.dispersive,
            }
        };
        let g1 = self.distribution.g1(sample.wi, m);
        if !(g1 > 0.0 && sample.pdf > 0.0 && sample.pdf.is_finite()) {
            return None;
        }
        sample.weight *= g1;
        Some(sample)
    }
}
