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
//! works from both sides. In `path` shadow rays treat the surface as opaque (as Mitsuba 3's), so
//! light through the transparent part is found by BSDF sampling alone; the volumetric path
//! tracers cross the null lobe without a bounce and let shadow rays through with its value
//! 1 − α (1 − t_nested), t_nested the nested BSDF's own (Mitsuba 3's `volpath`).

use glam::{Vec2, Vec3};

use super::{
    Adapter, Bsdf, BsdfEval, BsdfFlags, BsdfModel, BsdfSample, Bxdf, BxdfTree, NodeId,
    ResolveContext,
};
use crate::polarization::SampledMueller;
use crate::spectrum::SampledSpectrum;
use crate::texture::Texture;
use crate::texture::TextureValues;

#[derive(Clone, Debug)]
pub struct Mask {
    pub opacity: Texture,
    pub nested: Box<Bsdf>,
}

/// Its diffuse reflectance is the nested BSDF's (the opacity aside, as in Mitsuba).
impl Adapter for Mask {
    const OWN_FLAGS: BsdfFlags = BsdfFlags::NULL;

    fn nested(&self) -> &[Box<Bsdf>] {
        std::slice::from_ref(&self.nested)
    }

    #[inline]
    fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
        let nested = self.nested.resolve(context, tree);
        tree.push(MaskLobes {
            opacity: self.opacity.eval_1(context.point.at()).clamp(0.0, 1.0),
            nested,
        })
    }
}

/// The nested lobes weighted by the opacity α, and the null lobe, at a point.
#[derive(Clone, Copy, Debug)]
pub struct MaskLobes {
    pub opacity: f32,
    pub nested: NodeId,
}

impl Bxdf for MaskLobes {
    #[inline]
    fn eval(&self, tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let nested = tree.eval(self.nested, wo, wi);
        BsdfEval {
            value: nested.value * self.opacity,
            pdf: nested.pdf * self.opacity,
        }
    }

    fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let opacity = self.opacity;
        if u_lobe < opacity {
            // The nested lobes' values and densities both carry the factor α: weights unchanged.
            let mut s = tree.sample(self.nested, wo, u_lobe / opacity, u)?;
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

    /// 1 − α (1 − t_nested): its own null lobe and the nested BSDF's, t_nested (Mitsuba 3's
    /// `mask`).
    fn null_transmission(&self, tree: &BxdfTree, wo: Vec3) -> SampledSpectrum {
        let nested = tree.null_transmission(self.nested, wo);
        SampledSpectrum::ONE - (SampledSpectrum::ONE - nested) * self.opacity
    }

    /// The pass-through keeps the polarization; the nested lobes give theirs.
    fn mueller(
        &self,
        tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        if lobe.contains(BsdfFlags::NULL) && wi == -wo {
            Some(SampledMueller::IDENTITY)
        } else {
            tree.mueller(self.nested, wo, wi, lobe)
        }
    }
}
