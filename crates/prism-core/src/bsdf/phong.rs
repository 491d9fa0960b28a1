//! Mitsuba 0.6's `phong` BSDF: the energy-normalised modified Phong model (Phong 1975; Lafortune
//! & Willems 1994, "Using the Modified Phong Reflectance Model for Physically Based Rendering").
//! Mitsuba 3 dropped it; scenes written for Mitsuba 0.6 use it.
//!
//! ```xml
//! <bsdf type="phong">
//!     <float name="exponent" value="30"/>                 <!-- or a texture -->
//!     <rgb name="specular_reflectance" value="0.2"/>      <!-- or a texture -->
//!     <rgb name="diffuse_reflectance" value="0.5"/>       <!-- or a texture -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! f cos θi = (ρ_d/π + ρ_s (n + 2)/(2π) cos^n α) cos θi, α the angle between wi and the mirror
//! direction of wo. When max(ρ_d + ρ_s) > 1 both are scaled down to conserve energy, as Mitsuba
//! 0.6 does. The glossy lobe is sampled by p = (n + 1)/(2π) cos^n α around the mirror direction
//! (samples below the horizon are lost), the diffuse lobe by the cosine; a lobe is chosen in
//! proportion to ρ̄_s and ρ̄_d at the point. One-sided.

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3};

use super::fresnel::reflect_z;
use super::glossydiffuse::{
    GLOSSY_OVER_DIFFUSE, GlossyDiffuseLobes, ScaledReflectances, ScaledReflectancesAt,
};
use super::{BsdfFlags, LeafBsdf};
use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct Phong {
    pub exponent: Texture,
    pub reflectances: ScaledReflectances,
}

impl LeafBsdf for Phong {
    type Lobes<'a> = PhongLobes;
    const FLAGS: BsdfFlags = GLOSSY_OVER_DIFFUSE;

    /// The diffuse reflectance, scaled as the lobes are.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.reflectances.albedo(at, lambda)
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> PhongLobes {
        PhongLobes {
            exponent: self.exponent.eval_1(at),
            reflectances: self.reflectances.at(at, lambda),
        }
    }
}

/// The glossy and diffuse lobes at a point.
#[derive(Clone, Copy, Debug)]
pub struct PhongLobes {
    pub exponent: f32,
    pub reflectances: ScaledReflectancesAt,
}

impl GlossyDiffuseLobes for PhongLobes {
    #[inline]
    fn value(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        let cos_alpha = reflect_z(wo).dot(wi);
        let glossy = if cos_alpha > 0.0 {
            (self.exponent + 2.0) / (2.0 * PI) * cos_alpha.powf(self.exponent)
        } else {
            0.0
        };
        (self.reflectances.specular * glossy + self.reflectances.diffuse * FRAC_1_PI) * wi.z
    }

    #[inline]
    fn glossy_probability(&self, _wo: Vec3) -> f32 {
        self.reflectances.p_glossy
    }

    /// cos α = u^(1/(n+1)) around the mirror direction.
    #[inline]
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let cos_alpha = u.y.powf(1.0 / (self.exponent + 1.0));
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let phi = 2.0 * PI * u.x;
        let local = Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha);
        Frame::from_normal(reflect_z(wo)).to_world(local)
    }

    #[inline]
    fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let cos_alpha = reflect_z(wo).dot(wi);
        if cos_alpha > 0.0 {
            (self.exponent + 1.0) / (2.0 * PI) * cos_alpha.powf(self.exponent)
        } else {
            0.0
        }
    }
}
