//! Mitsuba's `normalmap` adapter: the nested BSDF seen in a shading frame whose normal is read
//! from an RGB texture, n = normalize(2 rgb − 1) in the local shading frame (so (0.5, 0.5, 1)
//! changes nothing).
//!
//! ```xml
//! <bsdf type="normalmap">
//!     <texture type="bitmap" name="normalmap">
//!         <boolean name="raw" value="true"/> <string name="filename" value="normals.png"/>
//!     </texture>
//!     <bsdf type="roughplastic"/>
//! </bsdf>
//! ```
//! The texture must be read raw (no sRGB decoding), as in Mitsuba 3. The new frame's first
//! tangent is the shading frame's (the direction of ∂p/∂u) made orthogonal to the new normal;
//! Mitsuba 3.9 mixes a world-space ∂p/∂u into its local frame here, which only matters for
//! anisotropic BSDFs.

use glam::{Vec2, Vec3};

use super::bumpmap::{perturbed_eval, perturbed_pdf, perturbed_sample};
use super::{Bsdf, BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct NormalMap {
    pub normals: Texture,
    pub nested: Box<Bsdf>,
}

impl NormalMap {
    pub fn flags(&self) -> BsdfFlags {
        self.nested.flags()
    }

    #[inline]
    fn perturbed(&self, sp: &ShadingPoint) -> ShadingPoint {
        let local = (self.normals.eval_3(sp.uv) * 2.0 - Vec3::ONE).normalize_or_zero();
        if local == Vec3::ZERO {
            return *sp;
        }
        ShadingPoint {
            frame: Frame::from_normal_and_tangent(sp.frame.to_world(local), sp.frame.s),
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
