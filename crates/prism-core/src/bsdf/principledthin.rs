//! Mitsuba 3's `principledthin` BSDF: Burley's thin-surface variant of the Disney BSDF (Burley
//! 2015, "Extending the Disney BRDF to a BSDF with Integrated Subsurface Scattering", §4 and
//! figure 15), a sheet without thickness that reflects and transmits alike from both sides, as
//! Mitsuba's `principledthin.cpp` implements it.
//!
//! ```xml
//! <bsdf type="principledthin">
//!     <rgb name="base_color" value="0.7, 0.1, 0.1"/>   <!-- every parameter may be a texture -->
//!     <float name="roughness" value="0.15"/>
//!     <float name="spec_tint" value="0.1"/>
//!     <float name="anisotropic" value="0.5"/>
//!     <float name="spec_trans" value="0.8"/>
//!     <float name="diff_trans" value="0.3"/>           <!-- 0 to 2 -->
//!     <float name="eta" value="1.33"/>
//! </bsdf>
//! ```
//! Seen from either side (directions mirrored so that wo is above), with c the base colour,
//! s = `spec_trans` and t = `diff_trans`/2, h the half vector of wo and wi mirrored to wo's side:
//!
//! * specular reflection s F_thin D G / (4 cos θo), GGX with α from `roughness` and
//!   `anisotropic`, F_thin = lerp(F, F_s(C_tint R₀(η)), spec_tint) (F the dielectric Fresnel term,
//!   F_s Schlick's approximation);
//! * specular transmission s c (1 − F) D' G' / (4 cos θo): the same reflection turned to the other
//!   side, its roughness scaled by 0.65η − 0.35 (Burley 2015, figure 15);
//! * diffuse (1 − s)(1 − t) c/π cos θi with `principled`'s retro-reflection, fake subsurface
//!   (`flatness`) and sheen;
//! * diffuse transmission (1 − s) t c/π |cos θi|.
//!
//! Lobes are chosen in proportion to s r_sr/2, s r_st/2, (1 − s)(1 − t) r_dr and (1 − s) t r_dt
//! (the `*_sampling_rate` parameters): the specular ones by visible normals, the diffuse ones by
//! the cosine. The sheet does not bend light: η is 1 along the path.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::burley::{
    diffuse_factor, optional_value, schlick_fresnel, schlick_r0, schlick_weight, sheen_colour,
    specular_alphas, tint,
};
use super::fresnel::{fresnel_dielectric, reflect};
use super::microfacet::{Microfacet, MicrofacetKind};
use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

/// The relative weights with which the lobes are sampled (Mitsuba's `*_sampling_rate`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinSamplingRates {
    pub specular_reflectance: f32,
    pub specular_transmittance: f32,
    pub diffuse_reflectance: f32,
    pub diffuse_transmittance: f32,
}

/// The description: textures, `None` for a lobe the scene leaves out (or sets to the number 0),
/// as Mitsuba's `m_has_*` flags.
#[derive(Clone, Debug)]
pub struct PrincipledThin {
    pub base_color: Texture,
    pub roughness: Texture,
    pub anisotropic: Option<Texture>,
    pub spec_trans: Option<Texture>,
    pub spec_tint: Option<Texture>,
    pub sheen: Option<Texture>,
    pub sheen_tint: Option<Texture>,
    pub flatness: Option<Texture>,
    /// `diff_trans`, from 0 to 2.
    pub diff_trans: Option<Texture>,
    pub eta: Texture,
    pub rates: ThinSamplingRates,
}

impl LeafBsdf for PrincipledThin {
    type Lobes<'a> = PrincipledThinLobes;

    /// Always transmitting, as Mitsuba declares it (so it cannot be nested in `twosided`).
    const FLAGS: BsdfFlags = BsdfFlags::DIFFUSE
        .union(BsdfFlags::GLOSSY)
        .union(BsdfFlags::REFLECTION)
        .union(BsdfFlags::TRANSMISSION);

    /// The base colour, as Mitsuba's `eval_diffuse_reflectance`.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.base_color.eval(at, lambda)
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> PrincipledThinLobes {
        let base_color = self.base_color.eval(at, lambda);
        let roughness = self.roughness.eval_1(at);
        let anisotropic = optional_value(&self.anisotropic, at);
        let eta = self.eta.eval_1(at);
        let (alpha_u, alpha_v) = specular_alphas(roughness, anisotropic);
        let (scaled_u, scaled_v) = specular_alphas((0.65 * eta - 0.35) * roughness, anisotropic);
        let spec_tint = optional_value(&self.spec_tint, at);
        let sheen_tint = optional_value(&self.sheen_tint, at);
        PrincipledThinLobes {
            reflection: Microfacet::new(MicrofacetKind::Ggx, alpha_u, alpha_v),
            transmission: Microfacet::new(MicrofacetKind::Ggx, scaled_u, scaled_v),
            base_color,
            tint: tint(
                &base_color,
                spec_tint.is_some() || sheen_tint.is_some(),
                lambda,
            ),
            eta,
            roughness,
            spec_trans: optional_value(&self.spec_trans, at),
            spec_tint,
            sheen: optional_value(&self.sheen, at),
            sheen_tint,
            flatness: optional_value(&self.flatness, at),
            diff_trans: optional_value(&self.diff_trans, at).map(|t| 0.5 * t),
            rates: self.rates,
        }
    }
}

/// The lobes at a point.
#[derive(Clone, Copy, Debug)]
pub struct PrincipledThinLobes {
    /// GGX of the specular reflection, and of the transmission (roughness scaled by η).
    pub reflection: Microfacet,
    pub transmission: Microfacet,
    pub base_color: SampledSpectrum,
    /// C_tint: the base colour over its luminance.
    pub tint: SampledSpectrum,
    pub eta: f32,
    pub roughness: f32,
    pub spec_trans: Option<f32>,
    pub spec_tint: Option<f32>,
    pub sheen: Option<f32>,
    pub sheen_tint: Option<f32>,
    pub flatness: Option<f32>,
    /// t = `diff_trans`/2, from 0 to 1.
    pub diff_trans: Option<f32>,
    pub rates: ThinSamplingRates,
}

/// The probabilities of choosing each lobe.
struct LobeProbabilities {
    specular_reflection: f32,
    specular_transmission: f32,
    diffuse_reflection: f32,
    diffuse_transmission: f32,
}

/// A pair of directions seen from wo's side (wo above): wi, the half vector of wo and wi
/// mirrored above, and whether it is a normal that reflects wo into wi (or reflects it into
/// wi's mirror image, for a transmission).
struct Pair {
    wo: Vec3,
    wi: Vec3,
    h: Vec3,
    reflect_compatible: bool,
    transmit_compatible: bool,
}

impl PrincipledThinLobes {
    #[inline]
    fn probabilities(&self) -> LobeProbabilities {
        let s = self.spec_trans.unwrap_or(0.0);
        let t = self.diff_trans.unwrap_or(0.0);
        let r = self.rates;
        let (sr, st) = if self.spec_trans.is_some() {
            (
                s * r.specular_reflectance / 2.0,
                s * r.specular_transmittance / 2.0,
            )
        } else {
            (0.0, 0.0)
        };
        let dr = r.diffuse_reflectance * (1.0 - s) * (1.0 - t);
        let dt = if self.diff_trans.is_some() {
            r.diffuse_transmittance * (1.0 - s) * t
        } else {
            0.0
        };
        let total = sr + st + dr + dt;
        let scale = if total > 0.0 { 1.0 / total } else { 0.0 };
        LobeProbabilities {
            specular_reflection: sr * scale,
            specular_transmission: st * scale,
            diffuse_reflection: dr * scale,
            diffuse_transmission: dt * scale,
        }
    }

    /// The pair in the frame where wo is above (the sheet is the same from both sides).
    #[inline]
    fn pair(&self, wo: Vec3, wi: Vec3) -> Option<Pair> {
        if wo.z == 0.0 {
            return None;
        }
        let sign = wo.z.signum();
        let (wo, wi) = (wo * sign, wi * sign);
        let h = (wo + Vec3::new(wi.x, wi.y, wi.z.abs())).normalize_or_zero();
        if h == Vec3::ZERO {
            return None;
        }
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        Some(Pair {
            wo,
            wi,
            h,
            reflect_compatible: wi.z > 0.0 && oh > 0.0 && ih > 0.0,
            transmit_compatible: wi.z < 0.0 && oh > 0.0 && ih < 0.0,
        })
    }

    fn value(&self, pair: &Pair) -> SampledSpectrum {
        let Pair { wo, wi, h, .. } = *pair;
        let s = self.spec_trans.unwrap_or(0.0);
        let t = self.diff_trans.unwrap_or(0.0);
        let (cos_o, cos_i) = (wo.z, wi.z.abs());
        let mut value = SampledSpectrum::ZERO;
        if self.spec_trans.is_some() && s > 0.0 {
            let cos_oh = wo.dot(h);
            let f = fresnel_dielectric(cos_oh, self.eta).reflectance;
            if pair.reflect_compatible {
                let d = self.reflection.d(h) * self.reflection.g(wo, wi, h);
                let fresnel = match self.spec_tint {
                    Some(spec_tint) => {
                        let r0 = schlick_r0(self.eta);
                        SampledSpectrum::from_fn(|i| {
                            let schlick = schlick_fresnel(self.tint[i] * r0, cos_oh, self.eta);
                            f + spec_tint * (schlick - f)
                        })
                    }
                    None => SampledSpectrum::splat(f),
                };
                value += fresnel * (s * d / (4.0 * cos_o));
            }
            if pair.transmit_compatible {
                let d = self.transmission.d(h) * self.transmission.g(wo, wi, h);
                value += self.base_color * (s * (1.0 - f) * d / (4.0 * cos_o));
            }
        }
        if wi.z > 0.0 && s < 1.0 && t < 1.0 {
            let cos_d = h.dot(wi);
            let diffuse = diffuse_factor(self.roughness, self.flatness, cos_o, cos_i, cos_d);
            let weight = (1.0 - s) * (1.0 - t) * cos_i;
            value += self.base_color * (weight * FRAC_1_PI * diffuse);
            if let Some(sheen) = self.sheen
                && sheen > 0.0
            {
                let sheen = sheen * schlick_weight(cos_d.abs()) * weight;
                value += sheen_colour(self.sheen_tint, &self.tint) * sheen;
            }
        }
        if self.diff_trans.is_some() && wi.z < 0.0 && s < 1.0 && t > 0.0 {
            value += self.base_color * ((1.0 - s) * t * FRAC_1_PI * cos_i);
        }
        value
    }

    fn pdf(&self, pair: &Pair) -> f32 {
        let Pair { wo, wi, h, .. } = *pair;
        let p = self.probabilities();
        let mut pdf = 0.0;
        if self.spec_trans.is_some() {
            let jacobian = 1.0 / (4.0 * wo.dot(h)).abs();
            if pair.reflect_compatible {
                pdf += p.specular_reflection * self.reflection.pdf_visible(wo, h) * jacobian;
            }
            if pair.transmit_compatible {
                pdf += p.specular_transmission * self.transmission.pdf_visible(wo, h) * jacobian;
            }
        }
        if wi.z > 0.0 {
            pdf += p.diffuse_reflection * cosine_hemisphere_pdf(wi);
        }
        if self.diff_trans.is_some() && wi.z < 0.0 {
            pdf += p.diffuse_transmission * cosine_hemisphere_pdf(-wi);
        }
        pdf
    }
}

impl Bxdf for PrincipledThinLobes {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let Some(pair) = self.pair(wo, wi) else {
            return BsdfEval::ZERO;
        };
        BsdfEval {
            value: self.value(&pair),
            pdf: self.pdf(&pair),
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.z.is_finite() {
            return None;
        }
        let sign = wo.z.signum();
        let wo_up = wo * sign;
        let p = self.probabilities();
        let (w, flags) = if u_lobe < p.specular_reflection {
            (
                reflect(wo_up, self.reflection.sample_visible(wo_up, u)),
                BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION),
            )
        } else if u_lobe < p.specular_reflection + p.specular_transmission {
            let w = reflect(wo_up, self.transmission.sample_visible(wo_up, u));
            (
                Vec3::new(w.x, w.y, -w.z),
                BsdfFlags::GLOSSY.union(BsdfFlags::TRANSMISSION),
            )
        } else if u_lobe < p.specular_reflection + p.specular_transmission + p.diffuse_reflection {
            (
                sample_cosine_hemisphere(u),
                BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION),
            )
        } else {
            (
                -sample_cosine_hemisphere(u),
                BsdfFlags::DIFFUSE.union(BsdfFlags::TRANSMISSION),
            )
        };
        let wi = w * sign;
        let pair = self.pair(wo, wi)?;
        let valid = match (
            flags.contains(BsdfFlags::GLOSSY),
            flags.contains(BsdfFlags::TRANSMISSION),
        ) {
            (true, false) => pair.reflect_compatible,
            (true, true) => pair.transmit_compatible,
            (false, false) => pair.wi.z > 0.0,
            (false, true) => pair.wi.z < 0.0,
        };
        if !valid {
            return None;
        }
        let pdf = self.pdf(&pair);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(BsdfSample::new(
            wi,
            self.value(&pair) * (1.0 / pdf),
            pdf,
            flags,
        ))
    }
}
