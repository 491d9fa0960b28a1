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
//! as for `bumpmap` ([`super::perturbed`]), as Mitsuba 3.9's `perturbed_bsdf.h`.

use glam::Vec3;

use super::ShadingPoint;
use super::perturbed::{Perturbation, Perturbed};
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct NormalMap {
    pub normals: Texture,
    pub perturbed: Perturbed,
}

impl Perturbation for NormalMap {
    fn perturbed(&self) -> &Perturbed {
        &self.perturbed
    }

    /// The texture's RGB in [0, 1]³ mapped to [−1, 1]³.
    #[inline]
    fn normal(&self, point: &ShadingPoint) -> Vec3 {
        self.normals.eval_3(point.at()) * 2.0 - Vec3::ONE
    }
}
