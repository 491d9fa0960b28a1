//! Mitsuba 3's `circular` BSDF: an ideal circular polarizer, a sheet that passes only right (or
//! left) circularly polarized light.
//!
//! ```xml
//! <bsdf type="circular">
//!     <boolean name="left_handed" value="false"/>   <!-- true: pass left circular light -->
//!     <rgb name="transmittance" value="1"/>         <!-- optional factor -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md. Like Mitsuba's, it has no
//! angle: a circular polarizer looks the same turned about the beam.
//!
//! A [polarizing sheet](super::polarizing_sheet), a null lobe δ(wi + wo) on both sides. Unpolarized
//! light keeps half its intensity, so an unpolarized render sees a grey filter of
//! ½ · transmittance. In a polarized render its Mueller matrix is the
//! [`right_circular_polarizer`] or [`left_circular_polarizer`], as Mitsuba's `circular.cpp`
//! gives it.
//!
//! [`right_circular_polarizer`]: crate::polarization::mueller::right_circular_polarizer
//! [`left_circular_polarizer`]: crate::polarization::mueller::left_circular_polarizer

use glam::Vec3;

use super::polarizing_sheet::{PolarizingSheet, in_beam_basis};
use super::{BsdfFlags, LeafBsdf};
use crate::polarization::SampledMueller;
use crate::polarization::mueller::{left_circular_polarizer, right_circular_polarizer};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{Texture, TexturePoint, TextureValues};

#[derive(Clone, Debug)]
pub struct Circular {
    pub left_handed: bool,
    pub transmittance: Texture,
}

impl LeafBsdf for Circular {
    type Lobes<'a> = CircularLobes;
    const FLAGS: BsdfFlags = BsdfFlags::NULL.union(BsdfFlags::POLARIZING);

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> CircularLobes {
        CircularLobes {
            left_handed: self.left_handed,
            transmittance: self.transmittance.eval(at, lambda),
        }
    }
}

/// The circular polarizer at a point.
#[derive(Clone, Copy, Debug)]
pub struct CircularLobes {
    pub left_handed: bool,
    pub transmittance: SampledSpectrum,
}

impl PolarizingSheet for CircularLobes {
    /// ½ · transmittance.
    #[inline]
    fn unpolarized(&self) -> SampledSpectrum {
        self.transmittance * 0.5
    }

    /// The right or left circular polarizer, the same about any axis.
    fn mueller_along(&self, forward: Vec3) -> SampledMueller {
        let m = if self.left_handed {
            left_circular_polarizer()
        } else {
            right_circular_polarizer()
        };
        in_beam_basis(m, Vec3::X, forward, self.transmittance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bxdf, BxdfTree};
    use glam::Vec4;

    /// M₀₀ is the unpolarized value ½ · transmittance; each handedness passes its own light,
    /// whatever the direction.
    #[test]
    fn each_handedness_passes_its_own_light() {
        let transmittance = SampledSpectrum([1.0, 0.9, 0.8, 0.7]);
        let right = Vec4::new(1.0, 0.0, 0.0, 1.0);
        let left = Vec4::new(1.0, 0.0, 0.0, -1.0);
        for forward in [Vec3::Z, -Vec3::Z, Vec3::new(0.6, 0.0, 0.8)] {
            for left_handed in [false, true] {
                let lobes = CircularLobes {
                    left_handed,
                    transmittance,
                };
                let m = lobes.mueller_along(forward);
                assert_eq!(m.m00(), transmittance * 0.5);
                let tree = BxdfTree::empty();
                assert_eq!(lobes.null_transmission(&tree, forward), transmittance * 0.5);
                let (own, other) = if left_handed {
                    (left, right)
                } else {
                    (right, left)
                };
                assert!((m.0[0] * own - own).abs().max_element() < 1e-5);
                assert!((m.0[0] * other).abs().max_element() < 1e-5);
            }
        }
    }
}
