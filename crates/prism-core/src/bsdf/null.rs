//! Mitsuba's `null` BSDF: a surface that light passes through unchanged, in direction and in
//! value. It marks the boundary of a medium without scattering (an index-matched boundary):
//! the shape exists only to say where its `interior` medium is.
//!
//! ```xml
//! <bsdf type="null"/>
//! ```
//!
//! Its only lobe is a null delta lobe: wi = −wo with weight 1 and probability 1.

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfModel, BsdfSample, Bxdf, BxdfTree, NodeId, ShadingPoint};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Null;

const FLAGS: BsdfFlags = BsdfFlags::NULL.union(BsdfFlags::TRANSMISSION);

impl BsdfModel for Null {
    fn flags(&self) -> BsdfFlags {
        FLAGS
    }

    fn is_dispersive(&self) -> bool {
        false
    }

    fn node_count(&self) -> usize {
        1
    }

    #[inline]
    fn resolve<'a>(
        &'a self,
        _point: &ShadingPoint,
        _wo: Vec3,
        _lambda: &SampledWavelengths,
        tree: &mut BxdfTree<'a>,
    ) -> NodeId {
        tree.push(NullLobes)
    }
}

/// The null lobe at a point.
#[derive(Clone, Copy, Debug)]
pub struct NullLobes;

impl Bxdf for NullLobes {
    #[inline]
    fn sample(&self, _tree: &BxdfTree, wo: Vec3, _u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        Some(BsdfSample::new(-wo, SampledSpectrum::ONE, 1.0, FLAGS))
    }
}
