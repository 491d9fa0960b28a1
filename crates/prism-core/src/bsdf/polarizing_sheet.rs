//! The lobes shared by Mitsuba 3's ideal polarizing elements (`polarizer`, `retarder`,
//! `circular`): a sheet that light passes straight through, a null lobe δ(wi + wo) on both
//! sides, which changes only the light's polarization and intensity. Each element gives its
//! Mueller matrix ([`PolarizingSheet`]); the [`Bxdf`] follows from it.

use glam::{Mat4, Vec2, Vec3};

use super::circular::CircularLobes;
use super::polarizer::PolarizerLobes;
use super::retarder::RetarderLobes;
use super::{BsdfFlags, BsdfSample, Bxdf, BxdfTree};
use crate::polarization::mueller::stokes_basis;
use crate::polarization::{FrameChange, SampledMueller};
use crate::spectrum::SampledSpectrum;

/// A polarizing element at a point: what it passes of unpolarized light and its Mueller matrix.
pub trait PolarizingSheet {
    /// What passes of unpolarized light, M₀₀ of [`Self::mueller_along`]: the weight of the
    /// null lobe, and what an unpolarized render sees.
    fn unpolarized(&self) -> SampledSpectrum;

    /// The Mueller matrix for light passing along `forward` (local, the direction of travel),
    /// from and to the implicit Stokes bases of `forward`.
    fn mueller_along(&self, forward: Vec3) -> SampledMueller;
}

/// An element's Mueller matrix `element` for light along `forward`, written in the Stokes basis
/// whose reference direction is `reference`, turned to the implicit Stokes basis of `forward` on
/// both sides ([`FrameChange::collinear`], R M Rᵀ) and scaled by `transmittance`.
pub fn in_beam_basis(
    element: Mat4,
    reference: Vec3,
    forward: Vec3,
    transmittance: SampledSpectrum,
) -> SampledMueller {
    let change = FrameChange::collinear(forward, reference, stokes_basis(forward));
    SampledMueller::splat(change.apply(element)).scaled(transmittance)
}

/// Writes the [`Bxdf`] of each polarizing element's lobes from its [`PolarizingSheet`]: light
/// passes straight through, the sample is −wo with weight [`PolarizingSheet::unpolarized`] and
/// probability 1, which is also the null transmission, and its Mueller matrix is the element's
/// along `wo`, the direction the light travels. (A macro rather than a blanket implementation
/// over [`PolarizingSheet`], which would overlap glossydiffuse's over its lobes.)
macro_rules! polarizing_sheets {
    ($($lobes:ty),+ $(,)?) => {$(
        impl Bxdf for $lobes {
            fn sample(
                &self,
                _tree: &BxdfTree,
                wo: Vec3,
                _u_lobe: f32,
                _u: Vec2,
            ) -> Option<BsdfSample> {
                Some(BsdfSample::new(
                    -wo,
                    self.unpolarized(),
                    1.0,
                    BsdfFlags::NULL,
                ))
            }

            fn null_transmission(&self, _tree: &BxdfTree, _wo: Vec3) -> SampledSpectrum {
                self.unpolarized()
            }

            fn mueller(
                &self,
                _tree: &BxdfTree,
                wo: Vec3,
                _wi: Vec3,
                _lobe: BsdfFlags,
            ) -> Option<SampledMueller> {
                Some(self.mueller_along(wo))
            }
        }
    )+};
}

polarizing_sheets!(PolarizerLobes, RetarderLobes, CircularLobes);
