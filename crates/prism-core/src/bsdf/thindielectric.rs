//! Mitsuba's `thindielectric` BSDF: a thin pane of glass (a window), whose two parallel
//! interfaces reflect part of the light and let the rest through undeflected.
//!
//! ```xml
//! <bsdf type="thindielectric">
//!     <string name="int_ior" value="bk7"/>     <!-- as for dielectric -->
//!     <string name="ext_ior" value="air"/>
//!     <rgb name="specular_reflectance" value="1"/>     <!-- optional factors -->
//!     <rgb name="specular_transmittance" value="1"/>
//! </bsdf>
//! ```
//! Summing the internal reflections, R' = R + T R T + T R³ T + … = 2R / (1 + R) with R the
//! Fresnel reflectance of one interface (Mitsuba 3, `thindielectric.cpp`); the rest, 1 − R',
//! passes straight through (a null lobe). Both are delta lobes, chosen with probabilities R'
//! and 1 − R' (R' averaged over the path's wavelengths when the index is dispersive; the
//! direction does not depend on it, so all wavelengths are kept). As in Mitsuba 3, `path`
//! counts the pass as a bounce and its shadow rays see the pane as opaque, while the volumetric
//! path tracers cross it without a bounce and let shadow rays through with the null lobe's
//! value, (1 − R') times `specular_transmittance`.

use glam::{Vec2, Vec3};

use super::dielectric::{SmoothInterface, SmoothInterfaceAt};
use super::fresnel::{fresnel_dielectric, reflect_z};
use super::{BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::TexturePoint;

#[derive(Clone, Debug)]
pub struct ThinDielectric {
    pub interface: SmoothInterface,
}

/// Not dispersive: the pane does not bend light, so a dispersive index changes only how much
/// each wavelength reflects, never its direction.
impl LeafBsdf for ThinDielectric {
    type Lobes<'a> = ThinDielectricLobes;
    const FLAGS: BsdfFlags = BsdfFlags::SPECULAR
        .union(BsdfFlags::REFLECTION)
        .union(BsdfFlags::NULL);

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> ThinDielectricLobes {
        ThinDielectricLobes {
            interface: self.interface.at(at, lambda),
        }
    }
}

/// The reflected and passing lobes at a point.
#[derive(Clone, Copy, Debug)]
pub struct ThinDielectricLobes {
    pub interface: SmoothInterfaceAt,
}

impl ThinDielectricLobes {
    /// R' = 2R / (1 + R) for each wavelength, seen at |cos θ| = `cos_o`.
    #[inline]
    fn reflectance(&self, cos_o: f32) -> SampledSpectrum {
        let reflectance = |eta: f32| {
            let r = fresnel_dielectric(cos_o, eta).reflectance;
            2.0 * r / (1.0 + r)
        };
        if self.interface.eta.dispersive {
            SampledSpectrum::from_fn(|i| reflectance(self.interface.eta.eta[i]))
        } else {
            SampledSpectrum::splat(reflectance(self.interface.eta.hero()))
        }
    }
}

impl Bxdf for ThinDielectricLobes {
    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        let cos_o = wo.z.abs();
        if !(cos_o > 0.0) {
            return None;
        }
        let r = self.reflectance(cos_o);
        let p_reflect = r.average();
        if u_lobe < p_reflect {
            let weight = r * (1.0 / p_reflect) * self.interface.specular.reflectance;
            Some(BsdfSample::new(
                reflect_z(wo),
                weight,
                p_reflect,
                BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION),
            ))
        } else {
            let p_transmit = 1.0 - p_reflect;
            let weight = (SampledSpectrum::ONE - r)
                * (1.0 / p_transmit)
                * self.interface.specular.transmittance;
            Some(BsdfSample::new(-wo, weight, p_transmit, BsdfFlags::NULL))
        }
    }

    /// (1 − R') times `specular_transmittance`.
    fn null_transmission(&self, _tree: &BxdfTree, wo: Vec3) -> SampledSpectrum {
        let cos_o = wo.z.abs();
        if !(cos_o > 0.0) {
            return SampledSpectrum::ZERO;
        }
        (SampledSpectrum::ONE - self.reflectance(cos_o)) * self.interface.specular.transmittance
    }
}
