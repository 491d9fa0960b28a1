//! Mitsuba's `dielectric` BSDF: a smooth interface between two dielectrics (glass, water),
//! reflecting and refracting by the Fresnel equations, from both sides.
//!
//! ```xml
//! <bsdf type="dielectric">
//!     <string name="int_ior" value="bk7"/>     <!-- number or name; default bk7 (1.5046) -->
//!     <string name="ext_ior" value="air"/>     <!-- default air (1.000277) -->
//!     <!-- dispersive: <spectrum name="int_ior" type="sellmeier"> ... </spectrum>, see spectrum::ior -->
//!     <rgb name="specular_reflectance" value="1"/>     <!-- optional factors -->
//!     <rgb name="specular_transmittance" value="1"/>
//! </bsdf>
//! ```
//! Two specular lobes, chosen with the probabilities F and 1 − F, so the weights are 1 (times the
//! optional factors, and (η_i/η_t)² for transmitted radiance, which is compressed into a smaller
//! solid angle: Veach 1997, §5.2). With a dispersive index (our extension; Mitsuba's indices are
//! constants) F differs per wavelength: reflection keeps all wavelengths with weights F(λ)/F̄
//! (F̄ the mean over the path's wavelengths, the choice probability); refraction follows the hero
//! wavelength's direction and asks the integrator to drop the others
//! ([`BsdfSample::terminates_secondary`]), so that each wavelength leaves in its own direction
//! and the image shows true dispersion.

use glam::{Vec2, Vec3};

use super::fresnel::{fresnel_dielectric, reflect_z, refract_z};
use super::{BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::spectrum::ior::RelativeIor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Dielectric {
    /// η = n_interior / n_exterior.
    pub eta: RelativeIor,
    pub specular_reflectance: Option<Texture>,
    pub specular_transmittance: Option<Texture>,
}

/// An optional factor evaluated at a point: 1 when absent.
#[inline]
pub(crate) fn optional_factor(
    texture: &Option<Texture>,
    uv: Vec2,
    lambda: &SampledWavelengths,
) -> SampledSpectrum {
    match texture {
        Some(t) => t.eval(uv, lambda),
        None => SampledSpectrum::ONE,
    }
}

impl Dielectric {
    pub fn flags(&self) -> BsdfFlags {
        BsdfFlags::SPECULAR
            .union(BsdfFlags::REFLECTION)
            .union(BsdfFlags::TRANSMISSION)
    }

    pub fn eval(
        &self,
        _sp: &ShadingPoint,
        _wo: Vec3,
        _wi: Vec3,
        _lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        SampledSpectrum::ZERO
    }

    pub fn pdf(&self, _sp: &ShadingPoint, _wo: Vec3, _wi: Vec3, _l: &SampledWavelengths) -> f32 {
        0.0
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        _u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 || !cos_o.is_finite() {
            return None;
        }
        let hero = fresnel_dielectric(cos_o, self.eta.at(lambda.lambda(0)));
        let dispersive = self.eta.is_dispersive();
        let reflectance = if dispersive {
            SampledSpectrum::from_fn(|i| {
                fresnel_dielectric(cos_o, self.eta.at(lambda.lambda(i))).reflectance
            })
        } else {
            SampledSpectrum::splat(hero.reflectance)
        };
        let p_reflect = if dispersive {
            reflectance.average()
        } else {
            hero.reflectance
        };
        if u_lobe < p_reflect {
            let weight = reflectance
                * (1.0 / p_reflect)
                * optional_factor(&self.specular_reflectance, sp.uv, lambda);
            return Some(BsdfSample::new(
                reflect_z(wo),
                weight,
                p_reflect,
                BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION),
            ));
        }
        if hero.reflectance >= 1.0 {
            // Total internal reflection at the hero wavelength: it has no refracted light.
            return None;
        }
        let p_transmit = 1.0 - p_reflect;
        let transmittance = (SampledSpectrum::ONE - reflectance) * (1.0 / p_transmit);
        let radiance_scale = hero.eta_ti * hero.eta_ti;
        let weight = transmittance
            * radiance_scale
            * optional_factor(&self.specular_transmittance, sp.uv, lambda);
        Some(BsdfSample {
            wi: refract_z(wo, hero.cos_theta_t, hero.eta_ti),
            weight,
            pdf: p_transmit,
            flags: BsdfFlags::SPECULAR.union(BsdfFlags::TRANSMISSION),
            eta: hero.eta_it,
            terminates_secondary: dispersive,
        })
    }
}
