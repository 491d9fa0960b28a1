//! Mitsuba's `conductor` BSDF: a perfectly smooth metal, a mirror whose reflectance is the
//! Fresnel reflectance of the complex index η + ik at each wavelength.
//!
//! ```xml
//! <bsdf type="conductor">
//!     <string name="material" value="Au"/>       <!-- a preset; default "none": 100 % mirror -->
//!     <!-- or: <spectrum name="eta" value="..."/> <spectrum name="k" value="..."/> (or <rgb>, textures) -->
//!     <rgb name="specular_reflectance" value="1"/>   <!-- optional factor, default 1 -->
//! </bsdf>
//! ```
//! A single specular lobe: `sample` returns the mirror direction with weight
//! F(cos θ, η(λ), k(λ)) · specular_reflectance; `eval` and `pdf` are zero. One-sided.

use glam::{Vec2, Vec3};
use wide::f32x4;

use super::fresnel::{fresnel_conductor4, reflect_z};
use super::{BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Conductor {
    pub eta: Texture,
    pub k: Texture,
    pub specular_reflectance: Texture,
}

/// The Fresnel reflectance of a conductor at cos θ for each wavelength, η and k read from
/// textures at `uv` (shared by `conductor` and `roughconductor`).
#[inline]
pub(crate) fn conductor_reflectance(
    eta: &Texture,
    k: &Texture,
    uv: Vec2,
    cos_theta: f32,
    lambda: &SampledWavelengths,
) -> SampledSpectrum {
    let (eta, k) = (eta.eval(uv, lambda), k.eval(uv, lambda));
    let reflectance = fresnel_conductor4(cos_theta, f32x4::from(eta.0), f32x4::from(k.0));
    SampledSpectrum(reflectance.to_array())
}

impl Conductor {
    pub fn flags(&self) -> BsdfFlags {
        BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION)
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
        _u_lobe: f32,
        _u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let f = conductor_reflectance(&self.eta, &self.k, sp.uv, wo.z, lambda);
        let weight = f * self.specular_reflectance.eval(sp.uv, lambda);
        Some(BsdfSample::new(reflect_z(wo), weight, 1.0, self.flags()))
    }
}
