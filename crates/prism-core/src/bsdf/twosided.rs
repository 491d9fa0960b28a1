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

use super::{
    Adapter, Bsdf, BsdfEval, BsdfFlags, BsdfModel, BsdfSample, Bxdf, BxdfTree, NodeId,
    ResolveContext, ShadingPoint,
};
use crate::math::Frame;
use crate::polarization::SampledMueller;
use crate::spectrum::SampledSpectrum;

#[derive(Clone, Debug)]
pub struct TwoSided {
    /// The BSDF of the front and that of the back.
    pub sides: [Box<Bsdf>; 2],
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
    #[inline]
    fn front(&self) -> &Bsdf {
        &self.sides[0]
    }

    #[inline]
    fn back(&self) -> &Bsdf {
        &self.sides[1]
    }
}

impl Adapter for TwoSided {
    const OWN_FLAGS: BsdfFlags = BsdfFlags::NONE;

    fn nested(&self) -> &[Box<Bsdf>] {
        &self.sides
    }

    /// One side's: the larger count.
    fn nested_node_count(&self) -> usize {
        self.front().node_count().max(self.back().node_count())
    }

    /// That of the side `wo` sees.
    fn diffuse_reflectance(&self, context: &ResolveContext) -> SampledSpectrum {
        let ResolveContext { point, wo, lambda } = *context;
        if wo.z >= 0.0 {
            self.front().diffuse_reflectance(point, wo, lambda)
        } else {
            self.back()
                .diffuse_reflectance(&back_side(point), flip(wo), lambda)
        }
    }

    /// The side that `wo` sees: the front BSDF's lobes as they are, or the back BSDF's with
    /// mirrored directions.
    #[inline]
    fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
        if context.wo.z >= 0.0 {
            return self.front().resolve(context, tree);
        }
        let back = ResolveContext {
            point: &back_side(context.point),
            wo: flip(context.wo),
            lambda: context.lambda,
        };
        let nested = self.back().resolve(&back, tree);
        tree.push(BackSideLobes { nested })
    }
}

/// The back BSDF's lobes seen from the back: every direction mirrored through the surface.
#[derive(Clone, Copy, Debug)]
pub struct BackSideLobes {
    pub nested: NodeId,
}

impl Bxdf for BackSideLobes {
    #[inline]
    fn eval(&self, tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        tree.eval(self.nested, flip(wo), flip(wi))
    }

    #[inline]
    fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let mut s = tree.sample(self.nested, flip(wo), u_lobe, u)?;
        s.wi = flip(s.wi);
        Some(s)
    }

    /// The back BSDF's, seen from the mirrored direction.
    #[inline]
    fn null_transmission(&self, tree: &BxdfTree, wo: Vec3) -> SampledSpectrum {
        tree.null_transmission(self.nested, flip(wo))
    }

    /// The back BSDF's matrix for the mirrored directions, passed on in the implicit bases of
    /// the directions as they are (Mitsuba 3's `twosided`, which mirrors the directions and
    /// keeps the nested BSDF's matrix).
    #[inline]
    fn mueller(
        &self,
        tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        tree.mueller(self.nested, flip(wo), flip(wi), lobe)
    }
}
