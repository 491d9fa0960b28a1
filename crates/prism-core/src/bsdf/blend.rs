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
use crate::polarization::SampledMueller;
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
            flags: [self.nested[0].flags(), self.nested[1].flags()],
        })
    }
}

/// Both nested BSDFs' lobes, weighted 1 − w and w, at a point.
#[derive(Clone, Copy, Debug)]
pub struct BlendLobes {
    pub weight: f32,
    pub nested: [NodeId; 2],
    /// The nested BSDFs' flags.
    pub flags: [BsdfFlags; 2],
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

    /// (1 − w) M₀ + w M₁, the nested BSDFs' matrices, each scaled to its BSDF's unpolarized
    /// value for the lobe (Mitsuba 3's `blendbsdf` sums the nested matrices so): for the smooth
    /// lobes the value of `eval`, for a null lobe the null transmission. A nested BSDF without
    /// a polarized model adds a depolarizer of its value; None where neither has one. For
    /// another delta lobe, which `eval` cannot give, only the nested BSDFs that have such a
    /// lobe count, each at the scale of its own matrix (its Fresnel reflectance), a depolarizing
    /// one as a depolarizer of 1: exact where one of them has it.
    fn mueller(
        &self,
        tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        let matrices = self.nested.map(|id| tree.mueller(id, wo, wi, lobe));
        if matrices.iter().all(Option::is_none) {
            return None;
        }
        let shares = [1.0 - self.weight, self.weight];
        let blended = (0..2).map(|k| {
            let id = self.nested[k];
            let m = if lobe.has_null_lobe() {
                let value = tree.null_transmission(id, wo);
                matrices[k].map_or(SampledMueller::depolarizer(value), |m| m.with_m00(value))
            } else if lobe.is_delta() {
                if !self.flags[k].contains(lobe) {
                    SampledMueller::ZERO
                } else {
                    matrices[k].unwrap_or(SampledMueller::depolarizer(SampledSpectrum::ONE))
                }
            } else {
                let value = tree.eval(id, wo, wi).value;
                matrices[k].map_or(SampledMueller::depolarizer(value), |m| m.with_m00(value))
            };
            m.scaled(SampledSpectrum::splat(shares[k]))
        });
        blended.reduce(|a, b| a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::null::NullLobes;
    use crate::bsdf::polarizer::PolarizerLobes;
    use crate::bsdf::polarizing_sheet::PolarizingSheet;
    use crate::bsdf::{Diffuse, ShadingPoint};
    use crate::polarization::mueller::depolarizer;
    use crate::spectrum::{SampledWavelengths, WavelengthSampling};
    use crate::texture::Texture;

    /// A blend of a polarizer (share 1 − w) and the `null` BSDF (share w): light passing
    /// straight through meets (1 − w) P + w I, P the polarizer's matrix, which is what the
    /// two lobes give on average.
    #[test]
    fn a_blended_pass_mixes_the_nested_matrices() {
        let mut tree = BxdfTree::empty();
        let polarizer = PolarizerLobes {
            theta: 0.3,
            transmittance: SampledSpectrum([1.0, 0.9, 0.8, 0.7]),
            polarizing: true,
        };
        let first = tree.push(polarizer);
        let second = tree.push(NullLobes);
        let weight = 0.3;
        let blend = BlendLobes {
            weight,
            nested: [first, second],
            flags: [BsdfFlags::NULL, BsdfFlags::NULL],
        };
        let wo = Vec3::new(0.2, -0.1, 0.9).normalize();
        let m = blend.mueller(&tree, wo, -wo, BsdfFlags::NULL).unwrap();
        let p = polarizer.mueller_along(wo);
        for i in 0..4 {
            let expected = p.0[i] * (1.0 - weight) + glam::Mat4::IDENTITY * weight;
            assert!(
                (m.0[i] - expected)
                    .abs()
                    .to_cols_array()
                    .iter()
                    .all(|&d| d < 1e-6)
            );
        }
        let unpolarized = blend.null_transmission(&tree, wo);
        assert!((m.m00() - unpolarized).0.iter().all(|d| d.abs() < 1e-6));
    }

    /// A blend of a polarizer and a diffuse BSDF, for the smooth lobes light sampling
    /// evaluates: the diffuse BSDF's depolarizer of its value times w (the polarizer has no
    /// smooth lobe); for the null lobe the polarizer's matrix times 1 − w.
    #[test]
    fn the_smooth_lobes_of_a_blend_keep_the_nested_values() {
        let diffuse = Bsdf::Diffuse(Diffuse {
            reflectance: Texture::constant(0.4),
        });
        let lambda = SampledWavelengths::sample(0.5, WavelengthSampling::CieSum);
        let point = ShadingPoint::local(glam::Vec2::ZERO);
        let wo = Vec3::new(0.3, 0.1, 0.8).normalize();
        let mut tree = BxdfTree::empty();
        let polarizer = PolarizerLobes {
            theta: 1.1,
            transmittance: SampledSpectrum::ONE,
            polarizing: true,
        };
        let first = tree.push(polarizer);
        let context = ResolveContext {
            point: &point,
            wo,
            lambda: &lambda,
        };
        let second = diffuse.resolve(&context, &mut tree);
        let weight = 0.25;
        let blend = BlendLobes {
            weight,
            nested: [first, second],
            flags: [BsdfFlags::NULL, diffuse.flags()],
        };
        let wi = Vec3::new(-0.5, 0.2, 0.7).normalize();
        let value = blend.eval(&tree, wo, wi).value;
        let expected = 0.4 * wi.z / std::f32::consts::PI * weight;
        let m = blend.mueller(&tree, wo, wi, BsdfFlags::NONE).unwrap();
        for i in 0..4 {
            assert!((value[i] - expected).abs() < 1e-6);
            let d = m.0[i] - depolarizer(expected);
            assert!(d.abs().to_cols_array().iter().all(|&d| d < 1e-6));
        }
        let pass = blend.mueller(&tree, wo, -wo, BsdfFlags::NULL).unwrap();
        for i in 0..4 {
            let d = pass.0[i] - polarizer.mueller_along(wo).0[i] * (1.0 - weight);
            assert!(d.abs().to_cols_array().iter().all(|&d| d < 1e-6));
        }
    }
}
