//! Mitsuba 0.6's `roughdiffuse` BSDF: Oren & Nayar 1994, "Generalization of Lambert's
//! Reflectance Model", with its interreflection term (or, with `use_fast_approx`, the
//! qualitative model of the paper's eq. 30). Mitsuba 3 has no such plugin; scenes written for
//! Mitsuba 0.6 use it.
//!
//! ```xml
//! <bsdf type="roughdiffuse">
//!     <rgb name="reflectance" value="0.5"/>         <!-- or a texture -->
//!     <float name="alpha" value="0.2"/>             <!-- or a texture -->
//!     <boolean name="use_fast_approx" value="false"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! α is a Beckmann-style RMS slope; as in Mitsuba the Oren–Nayar slope deviation is σ = α/√2.
//! α = 0 is Lambert's law. Sampled like `diffuse` (cosine-weighted); labelled a diffuse lobe
//! (Mitsuba 0.6 calls it glossy, which only matters to its own integrators). One-sided.

use std::f32::consts::{FRAC_1_PI, FRAC_1_SQRT_2};

use glam::{Vec2, Vec3};

use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf, mixture_sample};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use crate::texture::TexturePoint;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct RoughDiffuse {
    pub reflectance: Texture,
    pub alpha: Texture,
    pub use_fast_approx: bool,
}

impl LeafBsdf for RoughDiffuse {
    type Lobes<'a> = RoughDiffuseLobes;
    const FLAGS: BsdfFlags = BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION);

    /// The reflectance (Oren–Nayar's ρ).
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.reflectance.eval(at, lambda)
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> RoughDiffuseLobes {
        RoughDiffuseLobes {
            reflectance: self.reflectance.eval(at, lambda),
            sigma: self.alpha.eval_1(at) * FRAC_1_SQRT_2,
            use_fast_approx: self.use_fast_approx,
        }
    }
}

/// The Oren–Nayar lobe at a point.
#[derive(Clone, Copy, Debug)]
pub struct RoughDiffuseLobes {
    pub reflectance: SampledSpectrum,
    /// The slope deviation σ = α/√2.
    pub sigma: f32,
    pub use_fast_approx: bool,
}

impl RoughDiffuseLobes {
    /// f(wo, wi) cos θi for directions above the surface.
    #[inline]
    fn value(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        let sigma = self.sigma;
        let sigma2 = sigma * sigma;
        let rho = self.reflectance;
        let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
        let sin_i = (1.0 - wi.z * wi.z).max(0.0).sqrt();
        // cos(φo − φi).
        let cos_phi_diff = if sin_o > 1e-4 && sin_i > 1e-4 {
            (wo.x * wi.x + wo.y * wi.y) / (sin_o * sin_i)
        } else {
            0.0
        };
        // α = max(θo, θi), β = min(θo, θi).
        let (sin_alpha, sin_beta, tan_beta) = if wo.z > wi.z {
            (sin_i, sin_o, sin_o / wo.z)
        } else {
            (sin_o, sin_i, sin_i / wi.z)
        };
        let value = if self.use_fast_approx {
            let a = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
            let b = 0.45 * sigma2 / (sigma2 + 0.09);
            rho * (a + b * cos_phi_diff.max(0.0) * sin_alpha * tan_beta)
        } else {
            // Oren & Nayar 1994, eqs. 27–29 (with C₃'s (4αβ/π²)² and the interreflection term
            // 0.17 ρ² σ²/(σ² + 0.13) (1 − cos(φo − φi)(2β/π)²)).
            let (theta_o, theta_i) = (wo.z.clamp(-1.0, 1.0).acos(), wi.z.clamp(-1.0, 1.0).acos());
            let (alpha, beta) = (theta_o.max(theta_i), theta_o.min(theta_i));
            let t = sigma2 / (sigma2 + 0.09);
            let t2 = 4.0 * FRAC_1_PI * FRAC_1_PI * alpha * beta;
            let t3 = 2.0 * beta * FRAC_1_PI;
            let c1 = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
            let mut c2 = 0.45 * t;
            let c3 = 0.125 * t * t2 * t2;
            let c4 = 0.17 * sigma2 / (sigma2 + 0.13);
            if cos_phi_diff > 0.0 {
                c2 *= sin_alpha;
            } else {
                c2 *= sin_alpha - t3 * t3 * t3;
            }
            let tan_half = (sin_alpha + sin_beta)
                / ((1.0 - sin_alpha * sin_alpha).max(0.0).sqrt()
                    + (1.0 - sin_beta * sin_beta).max(0.0).sqrt());
            let single = rho
                * (c1 + cos_phi_diff * c2 * tan_beta + (1.0 - cos_phi_diff.abs()) * c3 * tan_half);
            let double = rho * rho * (c4 * (1.0 - cos_phi_diff * t3 * t3));
            single + double
        };
        value * (FRAC_1_PI * wi.z)
    }
}

impl Bxdf for RoughDiffuseLobes {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return BsdfEval::ZERO;
        }
        BsdfEval {
            value: self.value(wo, wi),
            pdf: cosine_hemisphere_pdf(wi),
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        let value = if wi.z <= 0.0 {
            SampledSpectrum::ZERO
        } else {
            self.value(wo, wi)
        };
        mixture_sample(wi, value, cosine_hemisphere_pdf(wi), RoughDiffuse::FLAGS)
    }
}
