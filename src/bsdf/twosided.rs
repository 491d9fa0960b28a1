//! Mitsuba's `twosided` adapter nested inside another adapter (`mask`, `blendbsdf`, ...): the
//! first BSDF on the front, the second (or the same) on the back, seen with the directions
//! mirrored through the surface. (A `twosided` at the top of a material becomes the material's
//! front and back, see [`super::Material`].)
//!
//! ```xml
//! <bsdf type="mask">
//!     <bsdf type="twosided"> <bsdf type="diffuse"/> </bsdf>
//! </bsdf>
//! ```

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfFlags, BsdfSample, ShadingPoint};
use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct TwoSided {
    pub front: Box<Bsdf>,
    pub back: Box<Bsdf>,
}

/// The direction mirrored through the tangent plane.
#[inline]
fn flip(v: Vec3) -> Vec3 {
    Vec3::new(v.x, v.y, -v.z)
}

/// The shading point seen from the back: the same world directions have mirrored local ones.
#[inline]
fn back_side(sp: &ShadingPoint) -> ShadingPoint {
    ShadingPoint {
        frame: Frame {
            s: sp.frame.s,
            t: sp.frame.t,
            n: -sp.frame.n,
        },
        ng: -sp.ng,
        ..*sp
    }
}

impl TwoSided {
    pub fn flags(&self) -> BsdfFlags {
        self.front.flags().union(self.back.flags())
    }

    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if wo.z >= 0.0 {
            self.front.eval(sp, wo, wi, lambda)
        } else {
            self.back.eval(&back_side(sp), flip(wo), flip(wi), lambda)
        }
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        if wo.z >= 0.0 {
            self.front.pdf(sp, wo, wi, lambda)
        } else {
            self.back.pdf(&back_side(sp), flip(wo), flip(wi), lambda)
        }
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        if wo.z >= 0.0 {
            self.front.sample(sp, wo, u_lobe, u, lambda)
        } else {
            let mut s = self
                .back
                .sample(&back_side(sp), flip(wo), u_lobe, u, lambda)?;
            s.wi = flip(s.wi);
            Some(s)
        }
    }
}
