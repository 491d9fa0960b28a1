//! Mitsuba's `mask` BSDF: a partly transparent surface (leaves cut out of quads): with
//! probability 1 − α light passes straight through, otherwise the nested BSDF scatters it.
//!
//! ```xml
//! <bsdf type="mask">
//!     <texture type="bitmap" name="opacity"> <string name="filename" value="leaf.png"/> </texture>
//!     <bsdf type="twosided"> <bsdf type="diffuse"/> </bsdf>
//! </bsdf>
//! ```
//! `opacity` α (a number in [0, 1] or a texture, clamped to [0, 1]; default 0.5). The BSDF is
//! α f_nested plus a null lobe (1 − α) δ(wi + wo), chosen with probability 1 − α; the null pass
//! works from both sides. Shadow rays treat the surface as opaque (as Mitsuba 3's `path`), so
//! light through the transparent part is found by BSDF sampling alone.

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Mask {
    pub opacity: Texture,
    pub nested: Box<Bsdf>,
}

impl Mask {
    pub fn flags(&self) -> BsdfFlags {
        self.nested.flags().union(BsdfFlags::NULL)
    }

    #[inline]
    fn opacity(&self, sp: &ShadingPoint) -> f32 {
        self.opacity.eval_1(sp.uv).clamp(0.0, 1.0)
    }

    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.nested.eval(sp, wo, wi, lambda) * self.opacity(sp)
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        self.nested.pdf(sp, wo, wi, lambda) * self.opacity(sp)
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        let opacity = self.opacity(sp);
        if u_lobe < opacity {
            // The nested lobes' values and densities both carry the factor α: weights unchanged.
            let mut s = self.nested.sample(sp, wo, u_lobe / opacity, u, lambda)?;
            s.pdf *= opacity;
            Some(s)
        } else {
            Some(BsdfSample::new(
                -wo,
                SampledSpectrum::ONE,
                1.0 - opacity,
                BsdfFlags::NULL,
            ))
        }
    }
}
