//! Mitsuba's `normalmap` adapter: the nested BSDF seen in a shading frame whose normal is read
//! from an RGB texture, n = 2 rgb − 1 in the local shading frame (so (0.5, 0.5, 1) changes
//! nothing).
//!
//! ```xml
//! <bsdf type="normalmap">
//!     <texture type="bitmap" name="normalmap">
//!         <boolean name="raw" value="true"/> <string name="filename" value="normals.png"/>
//!     </texture>
//!     <boolean name="flip_invalid_normals" value="true"/>
//!     <boolean name="use_shadowing_function" value="true"/>
//!     <bsdf type="roughplastic"/>
//! </bsdf>
//! ```
//! The texture must be read raw (no sRGB decoding), as in Mitsuba 3. The tilted frame is built
//! as for `bumpmap` ([`super::bumpmap::Perturbation`]), as Mitsuba 3.9's `perturbed_bsdf.h`.

use glam::{Vec2, Vec3};

use super::bumpmap::Perturbation;
use super::{Bsdf, BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct NormalMap {
    pub normals: Texture,
    pub nested: Box<Bsdf>,
    pub flip_invalid_normals: bool,
    pub use_shadowing_function: bool,
}

impl NormalMap {
    pub fn flags(&self) -> BsdfFlags {
        self.nested.flags()
    }

    #[inline]
    fn perturbation(&self, sp: &ShadingPoint, wo: Vec3) -> Perturbation {
        Perturbation::new(
            sp,
            self.normals.eval_3(sp.uv) * 2.0 - Vec3::ONE,
            wo,
            self.flip_invalid_normals,
            self.use_shadowing_function,
        )
    }

    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.perturbation(sp, wo).eval(&self.nested, wo, wi, lambda)
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        self.perturbation(sp, wo).pdf(&self.nested, wo, wi, lambda)
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        self.perturbation(sp, wo)
            .sample(&self.nested, wo, u_lobe, u, lambda)
    }
}
