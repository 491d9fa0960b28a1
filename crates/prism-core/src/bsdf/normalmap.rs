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

use super::perturbed::{Tilt, resolve_perturbed};
use super::{Adapter, Bsdf, BsdfFlags, BxdfTree, NodeId, ResolveContext};
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct NormalMap {
    pub normals: Texture,
    pub nested: Box<Bsdf>,
    pub flip_invalid_normals: bool,
    pub use_shadowing_function: bool,
}

impl Adapter for NormalMap {
    const OWN_FLAGS: BsdfFlags = BsdfFlags::NONE;

    fn nested(&self) -> &[Box<Bsdf>] {
        std::slice::from_ref(&self.nested)
    }

    #[inline]
    fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
        let tilt = Tilt {
            normal: self.normals.eval_3(context.point.at()) * 2.0 - Vec3::ONE,
            flip_invalid_normals: self.flip_invalid_normals,
            use_shadowing_function: self.use_shadowing_function,
        };
        resolve_perturbed(&self.nested, tilt, context, tree)
    }
}
