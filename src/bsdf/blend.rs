//! Mitsuba's `blendbsdf`: a linear blend (1 − w) f₀ + w f₁ of two BSDFs.
//!
//! ```xml
//! <bsdf type="blendbsdf">
//!     <float name="weight" value="0.3"/>    <!-- or a texture, clamped to [0, 1]; required -->
//!     <bsdf type="conductor"/>              <!-- f₀ -->
//!     <bsdf type="roughplastic"/>           <!-- f₁ -->
//! </bsdf>
//! ```
//! Sampling picks f₁ with probability w. A sample of a smooth lobe is returned with the blend's
//! whole density and value at its direction (both BSDFs evaluated), so multiple importance
//! sampling sees the true density; a delta lobe's probability is scaled by the choice.

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Blend {
    pub weight: Texture,
    pub nested: [Box<Bsdf>; 2],
}

impl Blend {
    pub fn flags(&self) -> BsdfFlags {
        self.nested[0].flags().union(self.nested[1].flags())
    }

    #[inline]
    fn weight(&self, sp: &ShadingPoint) -> f32 {
        self.weight.eval_1(sp.uv).clamp(0.0, 1.0)
    }

    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let w = self.weight(sp);
        self.nested[0].eval(sp, wo, wi, lambda) * (1.0 - w)
            + self.nested[1].eval(sp, wo, wi, lambda) * w
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        let w = self.weight(sp);
        (1.0 - w) * self.nested[0].pdf(sp, wo, wi, lambda)
            + w * self.nested[1].pdf(sp, wo, wi, lambda)
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        let w = self.weight(sp);
        let (chosen, probability, u_lobe) = if u_lobe < w {
            (1, w, u_lobe / w)
        } else {
            (0, 1.0 - w, (u_lobe - w) / (1.0 - w))
        };
        let mut s =
            self.nested[chosen].sample(sp, wo, u_lobe.min(1.0 - f32::EPSILON), u, lambda)?;
        if s.flags.is_delta() {
            s.pdf *= probability;
            return Some(s);
        }
        let pdf = self.pdf(sp, wo, s.wi, lambda);
        if !(pdf > 0.0) {
            return None;
        }
        s.weight = self.eval(sp, wo, s.wi, lambda) * (1.0 / pdf);
        s.pdf = pdf;
        Some(s)
    }
}
