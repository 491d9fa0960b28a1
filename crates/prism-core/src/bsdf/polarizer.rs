//! Mitsuba 3's `polarizer` BSDF: an ideal linear polarizer, a sheet that light passes straight
//! through, keeping only the component of its electric field along the transmission axis.
//!
//! ```xml
//! <bsdf type="polarizer">
//!     <float name="theta" value="90"/>          <!-- the axis's angle in degrees, or a texture -->
//!     <rgb name="transmittance" value="1"/>     <!-- optional factor -->
//!     <boolean name="polarizing" value="true"/> <!-- false: a neutral filter of ½ -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! A [polarizing sheet](super::polarizing_sheet), a null lobe δ(wi + wo) on both sides. Unpolarized
//! light keeps half its intensity, so an unpolarized render sees a grey filter of ½ · transmittance
//! (as Mitsuba 3's unpolarized variants do). In a polarized render its Mueller matrix is the
//! [`linear_polarizer`] whose absorbing axis is the shading frame's t direction (the surface's v
//! direction) turned by `theta` towards s, projected orthogonally to the beam for light that
//! crosses the sheet obliquely (Korger et al. 2013, "The polarization properties of a tilted
//! polarizer"), and whose transmission axis is orthogonal to it and the beam, as Mitsuba's
//! `polarizer.cpp` builds it.
//!
//! [`linear_polarizer`]: crate::polarization::mueller::linear_polarizer

use glam::Vec3;

use super::polarizing_sheet::{PolarizingSheet, in_beam_basis};
use super::{BsdfFlags, LeafBsdf};
use crate::polarization::SampledMueller;
use crate::polarization::mueller::linear_polarizer;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{Texture, TexturePoint, TextureValues};

#[derive(Clone, Debug)]
pub struct Polarizer {
    /// The angle of the transmission axis, in degrees.
    pub theta: Texture,
    pub transmittance: Texture,
    /// False: an absorber of ½ · transmittance that leaves the polarization alone.
    pub polarizing: bool,
}

impl LeafBsdf for Polarizer {
    type Lobes<'a> = PolarizerLobes;
    const FLAGS: BsdfFlags = BsdfFlags::NULL.union(BsdfFlags::POLARIZING);

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> PolarizerLobes {
        PolarizerLobes {
            theta: self.theta.eval_1(at).to_radians(),
            transmittance: self.transmittance.eval(at, lambda),
            polarizing: self.polarizing,
        }
    }
}

/// The polarizer at a point: its axis's angle in radians and its transmittance.
#[derive(Clone, Copy, Debug)]
pub struct PolarizerLobes {
    pub theta: f32,
    pub transmittance: SampledSpectrum,
    pub polarizing: bool,
}

impl PolarizingSheet for PolarizerLobes {
    /// ½ · transmittance.
    #[inline]
    fn unpolarized(&self) -> SampledSpectrum {
        self.transmittance * 0.5
    }

    /// The linear polarizer whose absorbing axis is t turned by `theta` towards s, projected
    /// orthogonally to `forward`; where it does not polarize, an absorber of ½ · transmittance.
    fn mueller_along(&self, forward: Vec3) -> SampledMueller {
        if !self.polarizing {
            return SampledMueller::absorber(self.unpolarized());
        }
        let (sin, cos) = self.theta.sin_cos();
        let absorbing_axis = Vec3::new(sin, cos, 0.0);
        let effective_absorbing =
            (absorbing_axis - absorbing_axis.dot(forward) * forward).normalize();
        let effective_transmitting = forward.cross(effective_absorbing);
        in_beam_basis(
            linear_polarizer(1.0),
            effective_transmitting,
            forward,
            self.transmittance,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bxdf, BxdfTree};
    use glam::{Vec2, Vec4};

    fn lobes(degrees: f32, polarizing: bool) -> PolarizerLobes {
        PolarizerLobes {
            theta: degrees.to_radians(),
            transmittance: SampledSpectrum([1.0, 0.9, 0.8, 0.7]),
            polarizing,
        }
    }

    /// M₀₀ is the unpolarized render's value, from any direction and either side.
    #[test]
    fn the_first_element_is_the_unpolarized_value() {
        let mut rng = crate::sampling::rng::Pcg32::seeded(3);
        for _ in 0..100 {
            let forward = crate::sampling::warp::sample_uniform_sphere(Vec2::new(
                rng.next_f32(),
                rng.next_f32(),
            ));
            for polarizing in [true, false] {
                let l = lobes(360.0 * rng.next_f32(), polarizing);
                let tree = BxdfTree::empty();
                let weight = l.sample(&tree, forward, 0.5, Vec2::ZERO).unwrap().weight;
                let m00 = l.mueller_along(forward).m00();
                for i in 0..4 {
                    assert!((m00[i] - weight[i]).abs() < 1e-6);
                }
                assert_eq!(l.null_transmission(&tree, forward), weight);
            }
        }
    }

    /// Two sheets at normal incidence, their axes θ apart, pass ½ cos²θ of unpolarized light
    /// (Malus's law), whichever way the light crosses them; a sheet that does not polarize
    /// passes ¼ after another.
    #[test]
    fn two_sheets_follow_malus_law() {
        for forward in [Vec3::Z, -Vec3::Z] {
            for degrees in [0.0f32, 30.0, 45.0, 80.0, 90.0] {
                let first = lobes(10.0, true).mueller_along(forward).0[0];
                let second = lobes(10.0 + degrees, true).mueller_along(forward).0[0];
                let out = second * first * Vec4::X;
                let expected = 0.5 * degrees.to_radians().cos().powi(2);
                assert!((out.x - expected).abs() < 1e-5, "{degrees}°: {out}");
            }
            let neutral = lobes(37.0, false).mueller_along(forward).0[0];
            let out = neutral * lobes(0.0, true).mueller_along(forward).0[0] * Vec4::X;
            assert!((out.x - 0.25).abs() < 1e-6);
        }
    }
}
