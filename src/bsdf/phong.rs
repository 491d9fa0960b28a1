//! Mitsuba 0.6's `phong` BSDF: the energy-normalised modified Phong model (Phong 1975; Lafortune
//! & Willems 1994, "Using the Modified Phong Reflectance Model for Physically Based Rendering").
//! Mitsuba 3 dropped it; scenes written for Mitsuba 0.6 use it.
//!
//! ```xml
//! <bsdf type="phong">
//!     <float name="exponent" value="30"/>                 <!-- or a texture; default 30 -->
//!     <rgb name="specular_reflectance" value="0.2"/>      <!-- or a texture; default 0.2 -->
//!     <rgb name="diffuse_reflectance" value="0.5"/>       <!-- or a texture; default 0.5 -->
//! </bsdf>
//! ```
//! f cos θi = (ρ_d/π + ρ_s (n + 2)/(2π) cos^n α) cos θi, α the angle between wi and the mirror
//! direction of wo. When max(ρ_d + ρ_s) > 1 both are scaled down to conserve energy, as Mitsuba
//! 0.6 does. The glossy lobe is sampled by p = (n + 1)/(2π) cos^n α around the mirror direction
//! (samples below the horizon are lost), the diffuse lobe by the cosine; a lobe is chosen in
//! proportion to ρ̄_s and ρ̄_d at the point. One-sided.

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3};

use super::fresnel::reflect_z;
use super::{BsdfFlags, BsdfSample, ShadingPoint, Texture, mixture_sample};
use crate::math::Frame;
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Phong {
    pub exponent: Texture,
    pub specular_reflectance: Texture,
    pub diffuse_reflectance: Texture,
    /// Factor applied to both reflectances (1, or less to conserve energy).
    pub scale: f32,
}

impl Phong {
    pub fn flags(&self) -> BsdfFlags {
        BsdfFlags::GLOSSY
            .union(BsdfFlags::DIFFUSE)
            .union(BsdfFlags::REFLECTION)
    }

    /// The reflectances at the point and the probability of sampling the glossy lobe.
    #[inline]
    fn lobes(
        &self,
        sp: &ShadingPoint,
        lambda: &SampledWavelengths,
    ) -> (SampledSpectrum, SampledSpectrum, f32) {
        let specular = self.specular_reflectance.eval(sp.uv, lambda) * self.scale;
        let diffuse = self.diffuse_reflectance.eval(sp.uv, lambda) * self.scale;
        let (s, d) = (specular.average(), diffuse.average());
        let p_glossy = if s + d > 0.0 { s / (s + d) } else { 1.0 };
        (specular, diffuse, p_glossy)
    }

    #[inline]
    fn value(
        wo: Vec3,
        wi: Vec3,
        exponent: f32,
        specular: &SampledSpectrum,
        diffuse: &SampledSpectrum,
    ) -> SampledSpectrum {
        let cos_alpha = reflect_z(wo).dot(wi);
        let glossy = if cos_alpha > 0.0 {
            (exponent + 2.0) / (2.0 * PI) * cos_alpha.powf(exponent)
        } else {
            0.0
        };
        (*specular * glossy + *diffuse * FRAC_1_PI) * wi.z
    }

    #[inline]
    fn mixture_pdf(wo: Vec3, wi: Vec3, exponent: f32, p_glossy: f32) -> f32 {
        let cos_alpha = reflect_z(wo).dot(wi);
        let glossy = if cos_alpha > 0.0 {
            (exponent + 1.0) / (2.0 * PI) * cos_alpha.powf(exponent)
        } else {
            0.0
        };
        p_glossy * glossy + (1.0 - p_glossy) * cosine_hemisphere_pdf(wi)
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
        let (specular, diffuse, _) = self.lobes(sp, lambda);
        Self::value(wo, wi, self.exponent.eval_1(sp.uv), &specular, &diffuse)
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return 0.0;
        }
        let (_, _, p_glossy) = self.lobes(sp, lambda);
        Self::mixture_pdf(wo, wi, self.exponent.eval_1(sp.uv), p_glossy)
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
        let (specular, diffuse, p_glossy) = self.lobes(sp, lambda);
        let exponent = self.exponent.eval_1(sp.uv);
        let (wi, flags) = if u_lobe < p_glossy {
            // cos α = u^(1/(n+1)) around the mirror direction.
            let cos_alpha = u.y.powf(1.0 / (exponent + 1.0));
            let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
            let phi = 2.0 * PI * u.x;
            let local = Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha);
            (
                Frame::from_normal(reflect_z(wo)).to_world(local),
                BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION),
            )
        } else {
            (
                sample_cosine_hemisphere(u),
                BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION),
            )
        };
        if !(wi.z > 0.0) {
            return None;
        }
        mixture_sample(
            wi,
            Self::value(wo, wi, exponent, &specular, &diffuse),
            Self::mixture_pdf(wo, wi, exponent, p_glossy),
            flags,
        )
    }
}
