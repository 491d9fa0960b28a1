//! Mitsuba's `thindielectric` BSDF: a thin pane of glass (a window), whose two parallel
//! interfaces reflect part of the light and let the rest through undeflected.
//!
//! ```xml
//! <bsdf type="thindielectric">
//!     <string name="int_ior" value="bk7"/>     <!-- as for dielectric -->
//!     <string name="ext_ior" value="air"/>
//!     <rgb name="specular_reflectance" value="1"/>     <!-- optional factors -->
//!     <rgb name="specular_transmittance" value="1"/>
//! </bsdf>
//! ```
//! Summing the internal reflections, R' = R + T R T + T R³ T + … = 2R / (1 + R) with R the
//! Fresnel reflectance of one interface (Mitsuba 3, `thindielectric.cpp`); the rest, 1 − R',
//! passes straight through (a null lobe). Both are delta lobes, chosen with probabilities R'
//! and 1 − R' (R' averaged over the path's wavelengths when the index is dispersive; the
//! direction does not depend on it, so all wavelengths are kept).

use glam::{Vec2, Vec3};

use super::dielectric::optional_factor;
use super::fresnel::{fresnel_dielectric, reflect_z};
use super::{BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::spectrum::ior::RelativeIor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct ThinDielectric {
    pub eta: RelativeIor,
    pub specular_reflectance: Option<Texture>,
    pub specular_transmittance: Option<Texture>,
}

impl ThinDielectric {
    pub fn flags(&self) -> BsdfFlags {
        BsdfFlags::SPECULAR
            .union(BsdfFlags::REFLECTION)
            .union(BsdfFlags::NULL)
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
        let cos_o = wo.z.abs();
        if !(cos_o > 0.0) {
            return None;
        }
        let reflectance = |l: f32| {
            let r = fresnel_dielectric(cos_o, self.eta.at(l)).reflectance;
            2.0 * r / (1.0 + r)
        };
        let r = if self.eta.is_dispersive() {
            SampledSpectrum::from_fn(|i| reflectance(lambda.lambda(i)))
        } else {
            SampledSpectrum::splat(reflectance(lambda.lambda(0)))
        };
        let p_reflect = r.average();
        if u_lobe < p_reflect {
            let weight =
                r * (1.0 / p_reflect) * optional_factor(&self.specular_reflectance, sp.uv, lambda);
            Some(BsdfSample::new(
                reflect_z(wo),
                weight,
                p_reflect,
                BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION),
            ))
        } else {
            let p_transmit = 1.0 - p_reflect;
            let weight = (SampledSpectrum::ONE - r)
                * (1.0 / p_transmit)
                * optional_factor(&self.specular_transmittance, sp.uv, lambda);
            Some(BsdfSample::new(-wo, weight, p_transmit, BsdfFlags::NULL))
        }
    }
}
