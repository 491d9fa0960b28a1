//! Lobes made of a glossy reflection over a diffuse base (`phong`, `ward`, `pplastic`,
//! `roughplastic`): one-sided, valued as the sum of both lobes, and sampled by choosing the
//! glossy lobe with a probability p (which may depend on wo), else the cosine-weighted diffuse
//! one, so that the density of wi is the mixture p p_glossy(wi) + (1 − p) cos θi / π.

use glam::{Vec2, Vec3};

use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, choice_probability, mixture_sample};
use crate::polarization::SampledMueller;
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{Texture, TexturePoint, TextureValues};

/// The flags of every glossy-over-diffuse BSDF: a glossy and a diffuse reflection.
pub const GLOSSY_OVER_DIFFUSE: BsdfFlags = BsdfFlags::GLOSSY
    .union(BsdfFlags::DIFFUSE)
    .union(BsdfFlags::REFLECTION);

/// The reflectances of Mitsuba 0.6's `phong` and `ward`: ρ_s and ρ_d, both multiplied by
/// `scale` (1, or less where ρ_s + ρ_d exceeds 1, to conserve energy: Mitsuba 0.6's
/// `ensureEnergyConservation`).
#[derive(Clone, Debug)]
pub struct ScaledReflectances {
    pub specular: Texture,
    pub diffuse: Texture,
    /// Factor applied to both reflectances.
    pub scale: f32,
}

/// [`ScaledReflectances`] at a point, with the probability of sampling the glossy lobe in
/// proportion to the mean reflectances: p = ρ̄_s / (ρ̄_s + ρ̄_d).
#[derive(Clone, Copy, Debug)]
pub struct ScaledReflectancesAt {
    pub specular: SampledSpectrum,
    pub diffuse: SampledSpectrum,
    pub p_glossy: f32,
}

impl ScaledReflectances {
    /// The scaled diffuse reflectance s ρ_d.
    pub fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.scale * self.diffuse.eval(at, lambda)
    }

    #[inline]
    pub fn at(&self, at: TexturePoint, lambda: &SampledWavelengths) -> ScaledReflectancesAt {
        let specular = self.specular.eval(at, lambda) * self.scale;
        let diffuse = self.diffuse.eval(at, lambda) * self.scale;
        let (s, d) = (specular.average(), diffuse.average());
        ScaledReflectancesAt {
            specular,
            diffuse,
            p_glossy: choice_probability(s, d),
        }
    }
}

/// What tells one glossy-over-diffuse BSDF's lobes from another's; their [`Bxdf`] follows.
pub trait GlossyDiffuseLobes {
    /// f(wo, wi)·cos θi of both lobes, for wo and wi above the surface.
    fn value(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum;
    /// The probability of sampling the glossy lobe at wo.
    fn glossy_probability(&self, wo: Vec3) -> f32;
    /// A direction drawn from the glossy lobe (which may fall below the surface).
    fn sample_glossy(&self, wo: Vec3, u: Vec2) -> Vec3;
    /// The density with which [`Self::sample_glossy`] draws wi.
    fn glossy_pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    /// [`Bxdf::mueller`] of both lobes, for wo and wi above the surface: None, a depolarizer,
    /// unless the BSDF has a polarized model (`pplastic`).
    fn mueller(&self, wo: Vec3, wi: Vec3) -> Option<SampledMueller> {
        let _ = (wo, wi);
        None
    }
}

/// The density of wi when the glossy lobe is chosen with probability `p_glossy`.
#[inline]
fn mixture_pdf(lobes: &impl GlossyDiffuseLobes, wo: Vec3, wi: Vec3, p_glossy: f32) -> f32 {
    p_glossy * lobes.glossy_pdf(wo, wi) + (1.0 - p_glossy) * cosine_hemisphere_pdf(wi)
}

impl<L: GlossyDiffuseLobes> Bxdf for L {
    #[inline]
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        if !(wo.z > 0.0 && wi.z > 0.0) {
            return BsdfEval::ZERO;
        }
        BsdfEval {
            value: self.value(wo, wi),
            pdf: mixture_pdf(self, wo, wi, self.glossy_probability(wo)),
        }
    }

    #[inline]
    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let p_glossy = self.glossy_probability(wo);
        let (wi, flags) = if u_lobe < p_glossy {
            (
                self.sample_glossy(wo, u),
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
            self.value(wo, wi),
            mixture_pdf(self, wo, wi, p_glossy),
            flags,
        )
    }

    #[inline]
    fn mueller(
        &self,
        _tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        _lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        GlossyDiffuseLobes::mueller(self, wo, wi)
    }
}
