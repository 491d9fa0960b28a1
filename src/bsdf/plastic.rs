//! Mitsuba's `plastic` BSDF: a diffuse base under a smooth dielectric coating (Weidlich &
//! Wilkie 2007, "Arbitrarily Layered Micro-Facet Surfaces", as Mitsuba 3's `plastic.cpp`).
//!
//! ```xml
//! <bsdf type="plastic">
//!     <rgb name="diffuse_reflectance" value="0.1, 0.27, 0.36"/>  <!-- or a texture; default 0.5 -->
//!     <string name="int_ior" value="polypropylene"/>             <!-- default polypropylene (1.49) -->
//!     <string name="ext_ior" value="air"/>
//!     <rgb name="specular_reflectance" value="1"/>               <!-- optional factor -->
//!     <boolean name="nonlinear" value="false"/>
//! </bsdf>
//! ```
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
use super::{BsdfFlags, BsdfSample, ShadingPoint, Texture, mixture_sample};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

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

    pub fn flags(&self) -> BsdfFlags {
        BsdfFlags::SPECULAR
            .union(BsdfFlags::DIFFUSE)
            .union(BsdfFlags::REFLECTION)
    }

    /// ρ / (1 − F_dr) or, nonlinear, ρ / (1 − ρ F_dr).
    #[inline]
    fn effective_diffuse(&self, sp: &ShadingPoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        let rho = self.diffuse_reflectance.eval(sp.uv, lambda);
        SampledSpectrum::from_fn(|i| {
            let bounce = if self.nonlinear {
                rho[i] * self.fdr_internal
            } else {
                self.fdr_internal
            };
            rho[i] / (1.0 - bounce)
        })
    }

    /// Probability of choosing the mirror lobe at wo (with F = F(cos θo)).
    #[inline]
    fn specular_probability(
        &self,
        sp: &ShadingPoint,
        f_o: f32,
        diffuse: &SampledSpectrum,
        lambda: &SampledWavelengths,
    ) -> f32 {
        let specular = f_o * optional_factor(&self.specular_reflectance, sp.uv, lambda).average();
        let base = (1.0 - f_o) * diffuse.average() * (1.0 - self.fdr_external) * self.inv_eta2;
        if specular + base > 0.0 {
            specular / (specular + base)
        } else {
            1.0
        }
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
        let f_o = fresnel_dielectric(wo.z, self.eta).reflectance;
        let f_i = fresnel_dielectric(wi.z, self.eta).reflectance;
        self.effective_diffuse(sp, lambda)
            * ((1.0 - f_o) * (1.0 - f_i) * self.inv_eta2 * FRAC_1_PI * wi.z)
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta).reflectance;
        let diffuse = self.effective_diffuse(sp, lambda);
        (1.0 - self.specular_probability(sp, f_o, &diffuse, lambda)) * cosine_hemisphere_pdf(wi)
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let f_o = fresnel_dielectric(wo.z, self.eta).reflectance;
        let diffuse = self.effective_diffuse(sp, lambda);
        let p_specular = self.specular_probability(sp, f_o, &diffuse, lambda);
        if u_lobe < p_specular {
            let weight =
                optional_factor(&self.specular_reflectance, sp.uv, lambda) * (f_o / p_specular);
            return Some(BsdfSample::new(
                reflect_z(wo),
                weight,
                p_specular,
                BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION),
            ));
        }
        let wi = sample_cosine_hemisphere(u);
        let f_i = fresnel_dielectric(wi.z, self.eta).reflectance;
        let value = diffuse * ((1.0 - f_o) * (1.0 - f_i) * self.inv_eta2 * FRAC_1_PI * wi.z);
        mixture_sample(
            wi,
            value,
            (1.0 - p_specular) * cosine_hemisphere_pdf(wi),
            BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION),
        )
    }
}
