//! Mitsuba's `plastic` BSDF: a diffuse base under a smooth dielectric coating (Weidlich &
//! Wilkie 2007, "Arbitrarily Layered Micro-Facet Surfaces", as Mitsuba 3's `plastic.cpp`).
//!
//! ```xml
//! <bsdf type="plastic">
//!     <rgb name="diffuse_reflectance" value="0.1, 0.27, 0.36"/>  <!-- or a texture -->
//!     <string name="int_ior" value="polypropylene"/>
//!     <string name="ext_ior" value="air"/>
//!     <rgb name="specular_reflectance" value="1"/>               <!-- optional factor -->
//!     <boolean name="nonlinear" value="false"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Two lobes: the coating's mirror reflection F(cos θo) (a delta), and the base seen through it,
//!
//!   f cos θi = ρ (1 − F(cos θo)) (1 − F(cos θi)) cos θi / (π η² (1 − F_dr)),
//!
//! where F_dr is the diffuse Fresnel reflectance of the coating's underside, which accounts for
//! light bouncing between base and coating; with `nonlinear` the bounces are modulated by the
//! base colour, 1 − ρ F_dr instead of 1 − F_dr, which darkens and saturates colours. A lobe is
//! chosen in proportion to its albedo at wo: F(cos θo)·s̄ for the mirror, and (1 − F(cos θo))
//! ρ̄_eff (1 − F_dr,ext)/η² for the base (s̄ and ρ̄ averaged over the path's wavelengths).
//! One-sided.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::dielectric::optional_factor;
use super::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance, reflect_z};
use super::{
    BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf, choice_probability, mixture_sample,
};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct Plastic {
    eta: f32,
    diffuse_reflectance: Texture,
    specular_reflectance: Option<Texture>,
    nonlinear: bool,
    inv_eta2: f32,
    /// Diffuse Fresnel reflectance of the coating seen from inside and from outside.
    fdr_internal: f32,
    fdr_external: f32,
}

impl Plastic {
    pub fn new(
        eta: f32,
        diffuse_reflectance: Texture,
        specular_reflectance: Option<Texture>,
        nonlinear: bool,
    ) -> Plastic {
        Plastic {
            eta,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            inv_eta2: 1.0 / (eta * eta),
            fdr_internal: fresnel_diffuse_reflectance(1.0 / eta),
            fdr_external: fresnel_diffuse_reflectance(eta),
        }
    }
}

/// The effective diffuse reflectance of a base of reflectance ρ under a coating that reflects
/// the fraction R of the light from below back down: ρ / (1 − R) or, with `nonlinear`,
/// ρ / (1 − ρ R), which darkens and saturates colours (shared with `roughplastic`).
#[inline]
pub(crate) fn effective_diffuse(
    rho: SampledSpectrum,
    internal_reflectance: f32,
    nonlinear: bool,
) -> SampledSpectrum {
    SampledSpectrum::from_fn(|i| {
        let bounce = if nonlinear {
            rho[i] * internal_reflectance
        } else {
            internal_reflectance
        };
        rho[i] / (1.0 - bounce)
    })
}

impl LeafBsdf for Plastic {
    type Lobes<'a> = PlasticLobes<'a>;
    const FLAGS: BsdfFlags = BsdfFlags::SPECULAR
        .union(BsdfFlags::DIFFUSE)
        .union(BsdfFlags::REFLECTION);

    /// The diffuse reflectance under the coating.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.diffuse_reflectance.eval(at, lambda)
    }

    #[inline]
    fn lobes<'a>(&'a self, at: TexturePoint, lambda: &SampledWavelengths) -> PlasticLobes<'a> {
        let rho = self.diffuse_reflectance.eval(at, lambda);
        PlasticLobes {
            plastic: self,
            diffuse: effective_diffuse(rho, self.fdr_internal, self.nonlinear),
            specular_reflectance: optional_factor(&self.specular_reflectance, at, lambda),
        }
    }
}

/// The coating's mirror and the base under it, at a point.
#[derive(Clone, Copy, Debug)]
pub struct PlasticLobes<'a> {
    plastic: &'a Plastic,
    /// The effective diffuse reflectance of the base.
    diffuse: SampledSpectrum,
    specular_reflectance: SampledSpectrum,
}

impl PlasticLobes<'_> {
    /// Probability of choosing the mirror lobe at wo (with F = F(cos θo)).
    #[inline]
    fn specular_probability(&self, f_o: f32) -> f32 {
        let p = self.plastic;
        let specular = f_o * self.specular_reflectance.average();
        let base = (1.0 - f_o) * self.diffuse.average() * (1.0 - p.fdr_external) * p.inv_eta2;
        choice_probability(specular, base)
    }

    /// The base's f cos θi given F(cos θo) and the sampled direction.
    #[inline]
    fn base_value(&self, f_o: f32, wi: Vec3) -> SampledSpectrum {
        let p = self.plastic;
        let f_i = fresnel_dielectric(wi.z, p.eta).reflectance;
        self.diffuse * ((1.0 - f_o) * (1.0 - f_i) * p.inv_eta2 * FRAC_1_PI * wi.z)
    }
}

impl Bxdf for PlasticLobes<'_> {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return BsdfEval::ZERO;
        }
        let f_o = fresnel_dielectric(wo.z, self.plastic.eta).reflectance;
        BsdfEval {
            value: self.base_value(f_o, wi),
            pdf: (1.0 - self.specular_probability(f_o)) * cosine_hemisphere_pdf(wi),
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let f_o = fresnel_dielectric(wo.z, self.plastic.eta).reflectance;
        let p_specular = self.specular_probability(f_o);
        if u_lobe < p_specular {
            let weight = self.specular_reflectance * (f_o / p_specular);
            return Some(BsdfSample::new(
                reflect_z(wo),
                weight,
                p_specular,
                BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION),
            ));
        }
        let wi = sample_cosine_hemisphere(u);
        mixture_sample(
            wi,
            self.base_value(f_o, wi),
            (1.0 - p_specular) * cosine_hemisphere_pdf(wi),
            BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION),
        )
    }
}
