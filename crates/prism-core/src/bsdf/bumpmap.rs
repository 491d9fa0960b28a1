//! Mitsuba's `bumpmap` adapter: the nested BSDF seen in a shading frame tilted by the gradient
//! of a height texture (Blinn 1978, "Simulation of Wrinkled Surfaces").
//!
//! ```xml
//! <bsdf type="bumpmap">
//!     <texture type="bitmap" name="height">
//!         <boolean name="raw" value="true"/> <string name="filename" value="bumps.png"/>
//!     </texture>
//!     <float name="scale" value="1"/>                        <!-- height scale -->
//!     <boolean name="flip_invalid_normals" value="true"/>
//!     <boolean name="use_shadowing_function" value="true"/>
//!     <bsdf type="roughplastic"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! As Mitsuba 3.9 (`bumpmap.cpp`, `perturbed_bsdf.h`): with the height gradient (h_u, h_v) the
//! tangents become ∂p/∂u + n (h_u − n·∂p/∂u) and ∂p/∂v + n (h_v − n·∂p/∂v); the perturbed normal
//! is their cross product, turned to the side of the geometric normal. The rest is shared with
//! `normalmap` ([`super::perturbed`]).

use glam::Vec3;

use super::ShadingPoint;
use super::perturbed::{Perturbation, Perturbed};
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct BumpMap {
    pub height: Texture,
    pub scale: f32,
    pub perturbed: Perturbed,
}

impl Perturbation for BumpMap {
    fn perturbed(&self) -> &Perturbed {
        &self.perturbed
    }

    /// The bump-mapped normal.
    #[inline]
    fn normal(&self, sp: &ShadingPoint) -> Vec3 {
        let gradient = self.height.eval_1_grad(sp.at()) * self.scale;
        let n = sp.frame.n;
        let dp_du = sp.dp_du + n * (gradient.x - n.dot(sp.dp_du));
        let dp_dv = sp.dp_dv + n * (gradient.y - n.dot(sp.dp_dv));
        let normal = dp_du.cross(dp_dv);
        let normal = if normal.dot(sp.ng) < 0.0 {
            -normal
        } else {
            normal
        };
        sp.frame.to_local(normal)
    }
}
