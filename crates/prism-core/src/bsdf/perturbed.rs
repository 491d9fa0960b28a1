//! A BSDF seen in a tilted shading frame, as Mitsuba 3.9's `PerturbedBSDF` builds it for bump
//! and normal maps (`perturbed_bsdf.h`):
//! * with `flip_invalid_normals`, a normal that wo sees from behind is mirrored about the
//!   shading normal, (x, y, z) ↦ (−x, −y, z), so that it faces wo (Schüssler et al. 2017,
//!   "Microfacet-based Normal Mapping for Robust Monte Carlo Path Tracing");
//! * the first tangent is the local x axis (the direction of ∂p/∂u) made orthogonal to it;
//! * directions on different sides of the two frames get no light;
//! * with `use_shadowing_function`, values are attenuated by the shadowing term of Conty
//!   Estevez et al. 2019 ("A Microfacet-Based Shadowing Function to Solve the Bump Terminator
//!   Problem", Ray Tracing Gems ch. 12): G = 2 / (1 + √(1 + α² tan²θi)) with
//!   α² = min(tan²θ_n / 8, 1), θ_n the tilt of the normal and θi the light direction's angle.

use glam::{Vec2, Vec3};

use super::{
    Adapter, Bsdf, BsdfEval, BsdfFlags, BsdfModel, BsdfSample, Bxdf, BxdfTree, NodeId,
    ResolveContext, ShadingPoint,
};
use crate::math::Frame;
use crate::polarization::SampledMueller;
use crate::spectrum::SampledSpectrum;

/// The BSDF a bump or normal map nests, and how its frame is tilted.
#[derive(Clone, Debug)]
pub struct Perturbed {
    pub nested: Box<Bsdf>,
    pub flip_invalid_normals: bool,
    pub use_shadowing_function: bool,
}

/// A bump or normal map: the nested BSDF seen in a frame tilted to a normal of the adapter's
/// own at each point. Its [`Adapter`] follows: no lobes of its own, one node over the nested
/// BSDF's.
pub trait Perturbation {
    /// The nested BSDF and how it is tilted.
    fn perturbed(&self) -> &Perturbed;
    /// The new normal at `point` in its local shading frame (not necessarily of unit length).
    fn normal(&self, point: &ShadingPoint) -> Vec3;
}

impl<P: Perturbation> Adapter for P {
    const OWN_FLAGS: BsdfFlags = BsdfFlags::NONE;

    fn nested(&self) -> &[Box<Bsdf>] {
        std::slice::from_ref(&self.perturbed().nested)
    }

    #[inline]
    fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
        resolve_perturbed(self.perturbed(), self.normal(context.point), context, tree)
    }
}

/// Adds the lobes of the nested BSDF seen in the frame tilted to `normal` for the outgoing
/// direction `wo`, and the node that carries directions into that frame.
fn resolve_perturbed<'a>(
    perturbed: &'a Perturbed,
    normal: Vec3,
    context: &ResolveContext,
    tree: &mut BxdfTree<'a>,
) -> NodeId {
    let ResolveContext { point, wo, lambda } = *context;
    let mut n = normal;
    if perturbed.flip_invalid_normals && wo.z * wo.dot(n) <= 0.0 {
        n = Vec3::new(-n.x, -n.y, n.z);
    }
    let n = n.try_normalize().unwrap_or(Vec3::Z);
    let s = (Vec3::X - n * n.x).try_normalize().unwrap_or(Vec3::Y);
    let local = Frame {
        s,
        t: n.cross(s),
        n,
    };
    let tilted = ShadingPoint {
        frame: Frame {
            s: point.frame.to_world(local.s),
            t: point.frame.to_world(local.t),
            n: point.frame.to_world(local.n),
        },
        ..*point
    };
    let tilted = ResolveContext {
        point: &tilted,
        wo: local.to_local(wo),
        lambda,
    };
    let nested = perturbed.nested.resolve(&tilted, tree);
    tree.push(PerturbedLobes {
        local,
        shadowing: perturbed.use_shadowing_function,
        nested,
    })
}

/// The nested lobes in a tilted frame.
#[derive(Clone, Copy, Debug)]
pub struct PerturbedLobes {
    /// The tilted frame in the local coordinates of the original one.
    pub local: Frame,
    pub shadowing: bool,
    pub nested: NodeId,
}

impl PerturbedLobes {
    /// The shadowing term for the light direction `wi` (1 when disabled).
    #[inline]
    fn shadowing(&self, wi: Vec3) -> f32 {
        if !self.shadowing {
            return 1.0;
        }
        let tan2 = |v: Vec3| (1.0 - v.z * v.z).max(0.0) / (v.z * v.z);
        let alpha2 = (0.125 * tan2(self.local.n)).min(1.0);
        let g = 2.0 / (1.0 + (1.0 + alpha2 * tan2(wi)).sqrt());
        if g.is_finite() { g } else { 0.0 }
    }
}

impl Bxdf for PerturbedLobes {
    fn eval(&self, tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let wi_p = self.local.to_local(wi);
        if !(wi.z * wi_p.z > 0.0) {
            return BsdfEval::ZERO;
        }
        let nested = tree.eval(self.nested, self.local.to_local(wo), wi_p);
        BsdfEval {
            value: nested.value * self.shadowing(wi),
            pdf: nested.pdf,
        }
    }

    fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let mut s = tree.sample(self.nested, self.local.to_local(wo), u_lobe, u)?;
        let wi = self.local.to_world(s.wi);
        if !(wi.z * s.wi.z > 0.0) {
            return None;
        }
        s.wi = wi;
        s.weight *= self.shadowing(wi);
        Some(s)
    }

    /// The nested BSDF's, seen in the tilted frame, with the shadowing term that `sample` gives
    /// a sample passing straight through; zero where the tilted frame puts the straight
    /// direction on the other side, as `sample` does. (Mitsuba 3's `bumpmap` and `normalmap`
    /// return zero here, which leaves the pass-through of a bump-mapped `thindielectric` or
    /// `mask` to BSDF samples that MIS weighs against light samples that cannot find it.)
    fn null_transmission(&self, tree: &BxdfTree, wo: Vec3) -> SampledSpectrum {
        let wo_p = self.local.to_local(wo);
        if !(wo.z * wo_p.z > 0.0) {
            return SampledSpectrum::ZERO;
        }
        tree.null_transmission(self.nested, wo_p) * self.shadowing(-wo)
    }

    /// The nested BSDF's matrix for the directions in the tilted frame, passed on as it is:
    /// its reference directions are the implicit Stokes bases of the tilted frame's local
    /// directions, taken for those of the original frame (as Mitsuba 3's `bumpmap` and
    /// `normalmap` pass the nested matrix on, unrotated).
    fn mueller(
        &self,
        tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        let (wo_p, wi_p) = (self.local.to_local(wo), self.local.to_local(wi));
        tree.mueller(self.nested, wo_p, wi_p, lobe)
    }
}
