//! Mitsuba's `null` BSDF: a surface that light passes straight through, unchanged. It marks an
//! index-matched boundary (the outline of a participating medium) or makes a shape invisible.
//!
//! ```xml
//! <bsdf type="null"/>
//! ```
//! A single null lobe δ(wi + wo) on both sides, with weight 1: `sample` returns −wo with
//! probability 1, nothing can be evaluated. As in Mitsuba 3's `path` integrator, passing through
//! counts as a bounce towards `max_depth`, and shadow rays see the surface as opaque (light
//! beyond it is found by BSDF sampling alone), as for `mask`. As in Mitsuba 3's `volpath` and
//! `volpathmis`, the volumetric path tracers cross it without a bounce and let shadow rays
//! through ([`crate::integrator::volpath`]).

use glam::{Vec2, Vec3};

use super::{BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::polarization::SampledMueller;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::TexturePoint;

/// The `null` BSDF (no parameters).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Null;

impl LeafBsdf for Null {
    type Lobes<'a> = NullLobes;
    const FLAGS: BsdfFlags = BsdfFlags::NULL;

    #[inline]
    fn lobes(&self, _at: TexturePoint, _lambda: &SampledWavelengths) -> NullLobes {
        NullLobes
    }
}

/// The pass-through lobe.
#[derive(Clone, Copy, Debug)]
pub struct NullLobes;

impl Bxdf for NullLobes {
    fn sample(&self, _tree: &BxdfTree, wo: Vec3, _u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        Some(BsdfSample::new(-wo, SampledSpectrum::ONE, 1.0, Null::FLAGS))
    }

    /// All light passes.
    fn null_transmission(&self, _tree: &BxdfTree, _wo: Vec3) -> SampledSpectrum {
        SampledSpectrum::ONE
    }

    /// Polarization passes unchanged too (Mitsuba's `null` is the identity, not a depolarizer).
    fn mueller(
        &self,
        _tree: &BxdfTree,
        _wo: Vec3,
        _wi: Vec3,
        _lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        Some(SampledMueller::IDENTITY)
    }
}
