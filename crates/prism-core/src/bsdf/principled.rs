//! Mitsuba 3's `principled` BSDF: Burley's Disney BSDF (Burley 2012, "Physically Based Shading
//! at Disney"; Burley 2015, "Extending the Disney BRDF to a BSDF with Integrated Subsurface
//! Scattering", without the subsurface and volume parts), with the lobes, Fresnel blend and
//! sampling weights of Mitsuba's `principled.cpp`.
//!
//! ```xml
//! <bsdf type="principled">
//!     <rgb name="base_color" value="0.8, 0.2, 0.1"/>   <!-- every parameter may be a texture -->
//!     <float name="metallic" value="0.7"/>
//!     <float name="specular" value="0.6"/>             <!-- or eta -->
//!     <float name="roughness" value="0.2"/>
//!     <float name="spec_tint" value="0.4"/>
//!     <float name="anisotropic" value="0.5"/>
//!     <float name="sheen" value="0.3"/>
//!     <float name="sheen_tint" value="0.2"/>
//!     <float name="clearcoat" value="0.6"/>
//!     <float name="clearcoat_gloss" value="0.3"/>
//!     <float name="spec_trans" value="0.4"/>
//!     <float name="flatness" value="0.1"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! With c the base colour, w_brdf = (1 − metallic)(1 − spec_trans) and
//! w_bsdf = (1 − metallic) spec_trans, seen from the front (cos θo > 0):
//!
//! * main specular reflection F_p D G / (4 cos θo), GGX with (α_u, α_v) from `roughness` and
//!   `anisotropic`, where F_p = (1 − metallic)(1 − spec_tint) F + metallic F_s(c) +
//!   (1 − metallic) spec_tint F_s(C_tint R₀(η)) blends the dielectric Fresnel F with Schlick's
//!   approximation F_s, and C_tint = c / lum(c);
//! * specular transmission √c w_bsdf (1 − F) D G |wo·h||wi·h| / (cos θo (wo·h + η wi·h)²)
//!   (Walter et al. 2007; radiance is compressed by 1/η², as in Mitsuba);
//! * clearcoat ¼ clearcoat F_s(0.04) D_GTR1 G_GGX(0.25) cos θi (Burley's form, without the
//!   1/(4 cos θo cos θi) of a microfacet BRDF, as Mitsuba);
//! * diffuse w_brdf c/π cos θi [(1 − ½F_o)(1 − ½F_i) + R_r (F_o + F_i + F_o F_i (R_r − 1))],
//!   F_x = (1 − cos θx)⁵ and R_r = 2 roughness cos²θ_d, blended towards the fake subsurface
//!   1.25 (F_ss (1/(cos θo + cos θi) − ½) + ½) by `flatness` (Burley 2015, §5.3);
//! * sheen sheen (1 − metallic) (1 − cos θ_d)⁵ lerp(1, C_tint, sheen_tint) cos θi.
//!
//! From behind only the specular parts act, with w_bsdf F and (1 − F). Lobes are chosen with
//! Mitsuba's probabilities: main reflection r_s (1 − w_bsdf (1 − F)), transmission
//! r_s w_bsdf (1 − F), clearcoat ¼ clearcoat r_c, diffuse w_brdf r_d (F at the sampled normal;
//! from behind F and 1 − F), normalised; r_s, r_c, r_d are the `*_sampling_rate` parameters.
//! The main lobes are sampled by GGX's visible normals, the clearcoat by GTR1's normals, the
//! diffuse and sheen lobes by the cosine.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::burley::{
    Gtr1, clearcoat_alpha, diffuse_factor, optional_value, schlick_fresnel, schlick_r0,
    schlick_weight, sheen_colour, smith_ggx1, specular_alphas, tint,
};
use super::fresnel::{fresnel_dielectric, reflect, refract};
use super::microfacet::{Microfacet, MicrofacetKind};
use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

/// The relative weights with which the lobes are sampled (Mitsuba's `*_sampling_rate`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplingRates {
    pub main_specular: f32,
    pub clearcoat: f32,
    pub diffuse: f32,
}

/// The description: textures, `None` for a lobe the scene leaves out (or sets to the number 0),
/// as Mitsuba's `m_has_*` flags.
#[derive(Clone, Debug)]
pub struct Principled {
    pub base_color: Texture,
    pub roughness: Texture,
    pub anisotropic: Option<Texture>,
    pub metallic: Option<Texture>,
    pub spec_trans: Option<Texture>,
    pub spec_tint: Option<Texture>,
    pub sheen: Option<Texture>,
    pub sheen_tint: Option<Texture>,
    pub flatness: Option<Texture>,
    pub clearcoat: Option<Texture>,
    pub clearcoat_gloss: Texture,
    /// Relative index η (from `eta`, or `specular` s as η = 2/(1 − √(0.08 s)) − 1).
    pub eta: f32,
    pub rates: SamplingRates,
}

impl LeafBsdf for Principled {
    type Lobes<'a> = PrincipledLobes;

    /// The lobes it always has; `flags` adds the transmission where `spec_trans` is given.
    const FLAGS: BsdfFlags = BsdfFlags::DIFFUSE
        .union(BsdfFlags::GLOSSY)
        .union(BsdfFlags::REFLECTION);

    fn flags(&self) -> BsdfFlags {
        if self.spec_trans.is_some() {
            Self::FLAGS.union(BsdfFlags::TRANSMISSION)
        } else {
            Self::FLAGS
        }
    }

    /// The base colour, as Mitsuba's `eval_diffuse_reflectance`.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.base_color.eval(at, lambda)
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> PrincipledLobes {
        let base_color = self.base_color.eval(at, lambda);
        let roughness = self.roughness.eval_1(at);
        let (alpha_u, alpha_v) = specular_alphas(roughness, optional_value(&self.anisotropic, at));
        let spec_tint = optional_value(&self.spec_tint, at);
        let sheen_tint = optional_value(&self.sheen_tint, at);
        let clearcoat = optional_value(&self.clearcoat, at);
        PrincipledLobes {
            distribution: Microfacet::new(MicrofacetKind::Ggx, alpha_u, alpha_v),
            base_color,
            tint: tint(
                &base_color,
                spec_tint.is_some() || sheen_tint.is_some(),
                lambda,
            ),
            eta: self.eta,
            roughness,
            metallic: optional_value(&self.metallic, at),
            spec_trans: optional_value(&self.spec_trans, at),
            spec_tint,
            sheen: optional_value(&self.sheen, at),
            sheen_tint,
            flatness: optional_value(&self.flatness, at),
            clearcoat: clearcoat.map(|c| {
                (
                    c,
                    Gtr1 {
                        alpha: clearcoat_alpha(self.clearcoat_gloss.eval_1(at)),
                    },
                )
            }),
            rates: self.rates,
        }
    }
}

/// The lobes at a point.
#[derive(Clone, Copy, Debug)]
pub struct PrincipledLobes {
    pub distribution: Microfacet,
    pub base_color: SampledSpectrum,
    /// C_tint: the base colour over its luminance.
    pub tint: SampledSpectrum,
    pub eta: f32,
    pub roughness: f32,
    pub metallic: Option<f32>,
    pub spec_trans: Option<f32>,
    pub spec_tint: Option<f32>,
    pub sheen: Option<f32>,
    pub sheen_tint: Option<f32>,
    pub flatness: Option<f32>,
    /// The clearcoat's weight and distribution.
    pub clearcoat: Option<(f32, Gtr1)>,
    pub rates: SamplingRates,
}

/// The geometry of a pair of directions: the side, the half vector (on the upper side) and the
/// dielectric Fresnel reflectance at it.
struct Pair {
    front: bool,
    reflect: bool,
    /// η along the path: η from the front, 1/η from behind.
    eta_path: f32,
    h: Vec3,
    fresnel: f32,
    /// Whether h is a normal that reflects wo into wi (or refracts it), seen from wo's side.
    reflect_compatible: bool,
    refract_compatible: bool,
}

/// The probabilities of choosing each lobe.
struct LobeProbabilities {
    diffuse: f32,
    clearcoat: f32,
    transmission: f32,
    reflection: f32,
}

impl PrincipledLobes {
    /// (w_brdf, w_bsdf).
    #[inline]
    fn weights(&self) -> (f32, f32) {
        let metallic = self.metallic.unwrap_or(0.0);
        let spec_trans = self.spec_trans.unwrap_or(0.0);
        (
            (1.0 - metallic) * (1.0 - spec_trans),
            (1.0 - metallic) * spec_trans,
        )
    }

    #[inline]
    fn pair(&self, wo: Vec3, wi: Vec3) -> Option<Pair> {
        if wo.z == 0.0 {
            return None;
        }
        let front = wo.z > 0.0;
        let reflect = wo.z * wi.z > 0.0;
        let eta_path = if front { self.eta } else { 1.0 / self.eta };
        let h = (wo + wi * if reflect { 1.0 } else { eta_path }).normalize_or_zero();
        if h == Vec3::ZERO {
            return None;
        }
        let h = if h.z < 0.0 { -h } else { h };
        let side = if front { h } else { -h };
        let (oh, ih) = (wo.dot(side), wi.dot(side));
        Some(Pair {
            front,
            reflect,
            eta_path,
            h,
            fresnel: fresnel_dielectric(wo.dot(h), self.eta).reflectance,
            reflect_compatible: reflect && oh > 0.0 && ih > 0.0,
            refract_compatible: !reflect && wi.z != 0.0 && oh > 0.0 && ih < 0.0,
        })
    }

    /// Mitsuba's lobe probabilities for the side and the dielectric reflectance `fresnel` at the
    /// main lobes' normal; their sum does not depend on `fresnel`.
    #[inline]
    fn probabilities(&self, front: bool, fresnel: f32) -> LobeProbabilities {
        let (brdf, bsdf) = self.weights();
        let has_transmission = self.spec_trans.is_some();
        let (reflection, transmission, clearcoat, diffuse) = if front {
            let rate = self.rates.main_specular;
            (
                rate * (1.0 - bsdf * (1.0 - fresnel)),
                if has_transmission {
                    rate * bsdf * (1.0 - fresnel)
                } else {
                    0.0
                },
                self.clearcoat
                    .map_or(0.0, |(c, _)| 0.25 * c * self.rates.clearcoat),
                brdf * self.rates.diffuse,
            )
        } else {
            (
                fresnel,
                if has_transmission { 1.0 - fresnel } else { 0.0 },
                0.0,
                0.0,
            )
        };
        let total = reflection + transmission + clearcoat + diffuse;
        let scale = if total > 0.0 { 1.0 / total } else { 0.0 };
        LobeProbabilities {
            diffuse: diffuse * scale,
            clearcoat: clearcoat * scale,
            transmission: transmission * scale,
            reflection: reflection * scale,
        }
    }

    /// F_p: the front side's blend of the dielectric Fresnel term with Schlick's approximations
    /// for the metal (R₀ = c) and the tinted dielectric (R₀ = C_tint R₀(η)), at cos θ = wo·h.
    #[inline]
    fn front_fresnel(&self, dielectric: f32, cos_oh: f32) -> SampledSpectrum {
        let metallic = self.metallic.unwrap_or(0.0);
        let spec_tint = self.spec_tint.unwrap_or(0.0);
        let mut f = SampledSpectrum::splat((1.0 - metallic) * (1.0 - spec_tint) * dielectric);
        if self.metallic.is_some() {
            f += SampledSpectrum::from_fn(|i| {
                metallic * schlick_fresnel(self.base_color[i], cos_oh, self.eta)
            });
        }
        if let Some(spec_tint) = self.spec_tint {
            let eta_it = if cos_oh >= 0.0 {
                self.eta
            } else {
                1.0 / self.eta
            };
            let r0 = schlick_r0(eta_it);
            f += SampledSpectrum::from_fn(|i| {
                (1.0 - metallic) * spec_tint * schlick_fresnel(self.tint[i] * r0, cos_oh, self.eta)
            });
        }
        f
    }

    fn value(&self, wo: Vec3, wi: Vec3, pair: &Pair) -> SampledSpectrum {
        let (brdf, bsdf) = self.weights();
        let h = pair.h;
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        let d = self.distribution.d(h);
        let g = self.distribution.g(wo, wi, h);
        let f = pair.fresnel;
        let mut value = SampledSpectrum::ZERO;
        if pair.reflect_compatible && f > 0.0 {
            let fresnel = if pair.front {
                self.front_fresnel(f, wo.dot(h))
            } else {
                SampledSpectrum::splat(bsdf * f)
            };
            value += fresnel * (d * g / (4.0 * cos_o));
        }
        if self.spec_trans.is_some() && bsdf > 0.0 && pair.refract_compatible && f < 1.0 {
            let (oh, ih) = (wo.dot(h), wi.dot(h));
            let denominator = oh + pair.eta_path * ih;
            let t = ((1.0 - f) * d * g * oh * ih / (wo.z * denominator * denominator)).abs();
            value += SampledSpectrum::from_fn(|i| self.base_color[i].max(0.0).sqrt()) * (bsdf * t);
        }
        if !(pair.front && pair.reflect) {
            return value;
        }
        if let Some((clearcoat, gtr1)) = self.clearcoat
            && clearcoat > 0.0
            && pair.reflect_compatible
        {
            let fresnel = schlick_fresnel(0.04, wo.dot(h), self.eta);
            let masking = smith_ggx1(wo, h, 0.25) * smith_ggx1(wi, h, 0.25);
            value +=
                SampledSpectrum::splat(0.25 * clearcoat * fresnel * gtr1.d(h) * masking * cos_i);
        }
        if brdf > 0.0 {
            let cos_d = h.dot(wi);
            let diffuse = diffuse_factor(self.roughness, self.flatness, cos_o, cos_i, cos_d);
            value += self.base_color * (brdf * cos_i * FRAC_1_PI * diffuse);
            let metallic = self.metallic.unwrap_or(0.0);
            if let Some(sheen) = self.sheen
                && sheen > 0.0
                && 1.0 - metallic > 0.0
            {
                let weight = sheen * (1.0 - metallic) * schlick_weight(cos_d.abs()) * cos_i;
                value += sheen_colour(self.sheen_tint, &self.tint) * weight;
            }
        }
        value
    }

    fn pdf(&self, wo: Vec3, wi: Vec3, pair: &Pair) -> f32 {
        let p = self.probabilities(pair.front, pair.fresnel);
        let h = pair.h;
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        let jacobian = if pair.reflect {
            1.0 / (4.0 * ih).abs()
        } else {
            let denominator = oh + pair.eta_path * ih;
            (pair.eta_path * pair.eta_path * ih / (denominator * denominator)).abs()
        };
        let wo_up = if pair.front { wo } else { -wo };
        let visible = self.distribution.pdf_visible(wo_up, h);
        let mut pdf = 0.0;
        if pair.reflect_compatible {
            pdf += p.reflection * visible * jacobian;
            if let Some((_, gtr1)) = self.clearcoat {
                pdf += p.clearcoat * gtr1.pdf(h) * jacobian;
            }
        }
        if pair.reflect && pair.front {
            pdf += p.diffuse * cosine_hemisphere_pdf(wi);
        }
        if pair.refract_compatible {
            pdf += p.transmission * visible * jacobian;
        }
        pdf
    }

    #[inline]
    fn has_back(&self) -> bool {
        self.weights().1 > 0.0
    }
}

impl Bxdf for PrincipledLobes {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let Some(pair) = self.pair(wo, wi) else {
            return BsdfEval::ZERO;
        };
        if !pair.front && !self.has_back() {
            return BsdfEval::ZERO;
        }
        BsdfEval {
            value: self.value(wo, wi, &pair),
            pdf: self.pdf(wo, wi, &pair),
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.z.is_finite() {
            return None;
        }
        let front = wo.z > 0.0;
        if !front && !self.has_back() {
            return None;
        }
        let wo_up = if front { wo } else { -wo };
        let m = self.distribution.sample_visible(wo_up, u);
        let fresnel = fresnel_dielectric(wo.dot(m), self.eta);
        let p = self.probabilities(front, fresnel.reflectance);
        let (wi, flags, eta) = if u_lobe < p.diffuse {
            (
                sample_cosine_hemisphere(u),
                BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION),
                1.0,
            )
        } else if u_lobe < p.diffuse + p.clearcoat {
            let (_, gtr1) = self.clearcoat?;
            (
                reflect(wo, gtr1.sample(u)),
                BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION),
                1.0,
            )
        } else if u_lobe < p.diffuse + p.clearcoat + p.transmission {
            if fresnel.reflectance >= 1.0 {
                return None;
            }
            (
                refract(wo, m, fresnel.cos_theta_t, fresnel.eta_ti),
                BsdfFlags::GLOSSY.union(BsdfFlags::TRANSMISSION),
                fresnel.eta_it,
            )
        } else {
            (
                reflect(wo, m),
                BsdfFlags::GLOSSY.union(BsdfFlags::REFLECTION),
                1.0,
            )
        };
        let pair = self.pair(wo, wi)?;
        let transmits = flags.contains(BsdfFlags::TRANSMISSION);
        let valid = if transmits {
            pair.refract_compatible
        } else {
            pair.reflect_compatible || (pair.reflect && flags.contains(BsdfFlags::DIFFUSE))
        };
        if !valid {
            return None;
        }
        let pdf = self.pdf(wo, wi, &pair);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let weight = self.value(wo, wi, &pair) * (1.0 / pdf);
        Some(BsdfSample {
            wi,
            weight,
            pdf,
            flags,
            eta,
            terminates_secondary: false,
        })
    }
}
