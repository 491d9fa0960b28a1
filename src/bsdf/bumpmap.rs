//! Mitsuba's `bumpmap` adapter: the nested BSDF seen in a shading frame tilted by the gradient
//! of a height texture (Blinn 1978, "Simulation of Wrinkled Surfaces").
//!
//! ```xml
//! <bsdf type="bumpmap">
//!     <texture type="bitmap" name="height">
//!         <boolean name="raw" value="true"/> <string name="filename" value="bumps.png"/>
//!     </texture>
//!     <float name="scale" value="1"/>      <!-- height scale, default 1 -->
//!     <bsdf type="roughplastic"/>
//! </bsdf>
//! ```
//! As Mitsuba 3 (`bumpmap.cpp`): with the height gradient (h_u, h_v) the tangents become
//! ∂p/∂u + n (h_u − n·∂p/∂u) and ∂p/∂v + n (h_v − n·∂p/∂v), the perturbed normal is their
//! cross product (turned to the side of the geometric normal) and the frame's first tangent
//! follows ∂p/∂u. Directions are carried into that frame; a direction on different sides of the
//! two frames gets no light (Mitsuba's check on the light direction).

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct BumpMap {
    pub height: Texture,
    pub scale: f32,
    pub nested: Box<Bsdf>,
}

impl BumpMap {
    pub fn flags(&self) -> BsdfFlags {
        self.nested.flags()
    }

    /// The shading point with the bump-mapped frame.
    #[inline]
    fn perturbed(&self, sp: &ShadingPoint) -> ShadingPoint {
        let gradient = self.height.eval_1_grad(sp.uv) * self.scale;
        let n = sp.frame.n;
        let dp_du = sp.dp_du + n * (gradient.x - n.dot(sp.dp_du));
        let dp_dv = sp.dp_dv + n * (gradient.y - n.dot(sp.dp_dv));
        let mut normal = dp_du.cross(dp_dv).normalize_or_zero();
        if normal == Vec3::ZERO {
            return *sp;
        }
        if normal.dot(sp.ng) < 0.0 {
            normal = -normal;
        }
        ShadingPoint {
            frame: Frame::from_normal_and_tangent(normal, sp.dp_du),
            ..*sp
        }
    }

    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        perturbed_eval(&self.nested, sp, &self.perturbed(sp), wo, wi, lambda)
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        perturbed_pdf(&self.nested, sp, &self.perturbed(sp), wo, wi, lambda)
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        perturbed_sample(&self.nested, sp, &self.perturbed(sp), wo, u_lobe, u, lambda)
    }
}

/// A local direction of `from`'s frame in `to`'s frame.
#[inline]
fn change_frame(from: &ShadingPoint, to: &ShadingPoint, v: Vec3) -> Vec3 {
    to.frame.to_local(from.frame.to_world(v))
}

/// `nested`'s value in the perturbed frame of `perturbed` (shared with `normalmap`).
pub(crate) fn perturbed_eval(
    nested: &Bsdf,
    sp: &ShadingPoint,
    perturbed: &ShadingPoint,
    wo: Vec3,
    wi: Vec3,
    lambda: &SampledWavelengths,
) -> SampledSpectrum {
    let wi_p = change_frame(sp, perturbed, wi);
    if !(wi.z * wi_p.z > 0.0) {
        return SampledSpectrum::ZERO;
    }
    nested.eval(perturbed, change_frame(sp, perturbed, wo), wi_p, lambda)
}

/// `nested`'s density in the perturbed frame.
pub(crate) fn perturbed_pdf(
    nested: &Bsdf,
    sp: &ShadingPoint,
    perturbed: &ShadingPoint,
    wo: Vec3,
    wi: Vec3,
    lambda: &SampledWavelengths,
) -> f32 {
    let wi_p = change_frame(sp, perturbed, wi);
    if !(wi.z * wi_p.z > 0.0) {
        return 0.0;
    }
    nested.pdf(perturbed, change_frame(sp, perturbed, wo), wi_p, lambda)
}

/// A sample of `nested` in the perturbed frame, carried back to the original one.
pub(crate) fn perturbed_sample(
    nested: &Bsdf,
    sp: &ShadingPoint,
    perturbed: &ShadingPoint,
    wo: Vec3,
    u_lobe: f32,
    u: Vec2,
    lambda: &SampledWavelengths,
) -> Option<BsdfSample> {
    let mut s = nested.sample(
        perturbed,
        change_frame(sp, perturbed, wo),
        u_lobe,
        u,
        lambda,
    )?;
    let wi = change_frame(perturbed, sp, s.wi);
    if !(wi.z * s.wi.z > 0.0) {
        return None;
    }
    s.wi = wi;
    Some(s)
}
