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

use super::{
    Adapter, Bsdf, BsdfEval, BsdfFlags, BsdfModel, BsdfSample, Bxdf, BxdfTree, NodeId,
    ResolveContext,
};
use crate::spectrum::SampledSpectrum;
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct Blend {
    pub weight: Texture,
    pub nested: [Box<Bsdf>; 2],
}

impl Adapter for Blend {
    const OWN_FLAGS: BsdfFlags = BsdfFlags::NONE;

    fn nested(&self) -> &[Box<Bsdf>] {
        &self.nested
    }

    /// The nested BSDFs' blended by the weight.
    fn diffuse_reflectance(&self, context: &ResolveContext) -> SampledSpectrum {
        let ResolveContext { point, wo, lambda } = *context;
        let weight = self.weight.eval_1(point.at()).clamp(0.0, 1.0);
        (1.0 - weight) * self.nested[0].diffuse_reflectance(point, wo, lambda)
            + weight * self.nested[1].diffuse_reflectance(point, wo, lambda)
    }

    #[inline]
    fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
        let first = self.nested[0].resolve(context, tree);
        let second = self.nested[1].resolve(context, tree);
        tree.push(BlendLobes {
            weight: self.weight.eval_1(context.point.at()).clamp(0.0, 1.0),
            nested: [first, second],
        })
    }
}

/// Both nested BSDFs' lobes, weighted 1 − w and w, at a point.
#[derive(Clone, Copy, Debug)]
pub struct BlendLobes {
    pub weight: f32,
    pub nested: [NodeId; 2],
}

impl Bxdf for BlendLobes {
    fn eval(&self, tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let w = self.weight;
        let first = tree.eval(self.nested[0], wo, wi);
        let second = tree.eval(self.nested[1], wo, wi);
        BsdfEval {
            value: first.value * (1.0 - w) + second.value * w,
            pdf: (1.0 - w) * first.pdf + w * second.pdf,
        }
    }

    fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let w = self.weight;
        let (chosen, probability, u_lobe) = if u_lobe < w {
            (1, w, u_lobe / w)
        } else {
            (0, 1.0 - w, (u_lobe - w) / (1.0 - w))
        };
        let mut s = tree.sample(self.nested[chosen], wo, u_lobe.min(1.0 - f32::EPSILON), u)?;
        if s.flags.is_delta() {
            s.pdf *= probability;
            return Some(s);
        }
        let blend = self.eval(tree, wo, s.wi);
        if !(blend.pdf > 0.0) {
            return None;
        }
        s.weight = blend.value * (1.0 / blend.pdf);
        s.pdf = blend.pdf;
        Some(s)
    }

    /// The nested BSDFs' blended by the weight (Mitsuba 3's `blendbsdf`).
    fn null_transmission(&self, tree: &BxdfTree, wo: Vec3) -> SampledSpectrum {
        let w = self.weight;
        tree.null_transmission(self.nested[0], wo) * (1.0 - w)
            + tree.null_transmission(self.nested[1], wo) * w
    }
}
