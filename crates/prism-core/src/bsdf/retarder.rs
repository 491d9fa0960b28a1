//! Mitsuba 3's `retarder` BSDF: an ideal linear retarder (a wave plate), a sheet that delays the
//! field component along its slow axis behind the one along its fast axis.
//!
//! ```xml
//! <bsdf type="retarder">
//!     <float name="theta" value="45"/>          <!-- the fast axis's angle in degrees -->
//!     <float name="delta" value="90"/>          <!-- the retardance in degrees: 90 is a quarter-wave plate -->
//!     <rgb name="transmittance" value="1"/>     <!-- optional factor -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! A [polarizing sheet](super::polarizing_sheet), a null lobe δ(wi + wo) on both sides;
//! unpolarized light passes whole, so an unpolarized render sees a filter of `transmittance`. In a polarized render its Mueller matrix is the
//! [`linear_retarder`] of retardance δ |cos θ| (Mitsuba's approximation of the change with the
//! angle of incidence), turned by `theta` (by −`theta` seen from the back) from the shading
//! frame's s direction, as Mitsuba's `retarder.cpp` builds it.
//!
//! [`linear_retarder`]: crate::polarization::mueller::linear_retarder

use glam::Vec3;

use super::polarizing_sheet::{PolarizingSheet, in_beam_basis};
use super::{BsdfFlags, LeafBsdf};
use crate::polarization::SampledMueller;
use crate::polarization::mueller::{linear_retarder, rotated_element};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{Texture, TexturePoint, TextureValues};

#[derive(Clone, Debug)]
pub struct Retarder {
    /// The angle of the fast axis, in degrees.
    pub theta: Texture,
    /// The retardance at normal incidence, in degrees.
    pub delta: Texture,
    pub transmittance: Texture,
}

impl LeafBsdf for Retarder {
    type Lobes<'a> = RetarderLobes;
    const FLAGS: BsdfFlags = BsdfFlags::NULL.union(BsdfFlags::POLARIZING);

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> RetarderLobes {
        RetarderLobes {
            theta: self.theta.eval_1(at).to_radians(),
            delta: self.delta.eval_1(at).to_radians(),
            transmittance: self.transmittance.eval(at, lambda),
        }
    }
}

/// The retarder at a point: its angles in radians and its transmittance.
#[derive(Clone, Copy, Debug)]
pub struct RetarderLobes {
    pub theta: f32,
    pub delta: f32,
    pub transmittance: SampledSpectrum,
}

impl PolarizingSheet for RetarderLobes {
    /// The transmittance: a retarder passes unpolarized light whole.
    #[inline]
    fn unpolarized(&self) -> SampledSpectrum {
        self.transmittance
    }

    /// The linear retarder of retardance δ |cos θᵢ| (θᵢ the angle of incidence), its fast axis
    /// turned by `theta` from s (by −`theta` for light crossing from the back).
    fn mueller_along(&self, forward: Vec3) -> SampledMueller {
        let cos_theta = forward.z;
        let retarder = linear_retarder(self.delta * cos_theta.abs());
        let side = if cos_theta >= 0.0 { 1.0 } else { -1.0 };
        let m = rotated_element(side * self.theta, retarder);
        in_beam_basis(m, Vec3::X, forward, self.transmittance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bxdf, BxdfTree};
    use crate::polarization::mueller::stokes_basis;
    use glam::Vec4;

    /// M₀₀ is the transmittance; a quarter-wave plate at 45° to the s direction turns light
    /// polarized along s, crossing at normal incidence from the front, into right circular
    /// light, and crossing from the back (where the plate's angle is mirrored) into left.
    #[test]
    fn a_quarter_wave_plate_makes_circular_light() {
        let transmittance = SampledSpectrum([1.0, 0.9, 0.8, 0.7]);
        let plate = RetarderLobes {
            theta: 45f32.to_radians(),
            delta: 90f32.to_radians(),
            transmittance,
        };
        let front = plate.mueller_along(Vec3::Z);
        assert_eq!(front.m00(), transmittance);
        let tree = BxdfTree::empty();
        assert_eq!(plate.null_transmission(&tree, Vec3::Z), transmittance);
        // Along +z the implicit basis is s itself.
        assert_eq!(stokes_basis(Vec3::Z), Vec3::X);
        let out = front.0[0] * Vec4::new(1.0, 1.0, 0.0, 0.0);
        assert!(
            (out - Vec4::new(1.0, 0.0, 0.0, 1.0)).abs().max_element() < 1e-5,
            "{out}"
        );
        let basis = stokes_basis(-Vec3::Z);
        let along_s = if basis.dot(Vec3::X).abs() > 0.5 {
            Vec4::new(1.0, 1.0, 0.0, 0.0)
        } else {
            Vec4::new(1.0, -1.0, 0.0, 0.0)
        };
        let out = plate.mueller_along(-Vec3::Z).0[0] * along_s;
        assert!((out.w - -1.0).abs() < 1e-5, "{out}");
    }
}
