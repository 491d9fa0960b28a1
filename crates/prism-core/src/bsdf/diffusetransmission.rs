//! pbrt-v4's `diffusetransmission` BSDF: a Lambertian reflector and a Lambertian transmitter in
//! one, f = R/π towards the side of wo and T/π through the surface (Pharr, Jakob & Humphreys
//! 2023, "Physically Based Rendering", 4th ed., pbrt-v4's `DiffuseTransmissionBxDF`). Mitsuba 3
//! has no such model.
//!
//! ```xml
//! <bsdf type="diffusetransmission">
//!     <rgb name="reflectance" value="0.25"/>     <!-- or textures -->
//!     <rgb name="transmittance" value="0.25"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Sampling picks reflection or transmission with probabilities in proportion to max R and
//! max T over the path's wavelengths (pbrt's choice), then a cosine-weighted direction on that
//! side. Two-sided: the same from either side.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::sampling::warp::sample_cosine_hemisphere;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{Texture, TexturePoint, TextureValues};

#[derive(Clone, Debug)]
pub struct DiffuseTransmission {
    pub reflectance: Texture,
    pub transmittance: Texture,
}

impl LeafBsdf for DiffuseTransmission {
    type Lobes<'a> = DiffuseTransmissionLobes;
    const FLAGS: BsdfFlags = BsdfFlags::DIFFUSE
        .union(BsdfFlags::REFLECTION)
        .union(BsdfFlags::TRANSMISSION);

    /// The reflectance.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.reflectance.eval(at, lambda)
    }

    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> DiffuseTransmissionLobes {
        DiffuseTransmissionLobes {
            reflectance: self.reflectance.eval(at, lambda),
            transmittance: self.transmittance.eval(at, lambda),
        }
    }
}

/// The diffuse reflection and transmission at a point.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseTransmissionLobes {
    pub reflectance: SampledSpectrum,
    pub transmittance: SampledSpectrum,
}

impl DiffuseTransmissionLobes {
    /// The probability of sampling reflection: max R / (max R + max T).
    fn reflection_probability(&self) -> Option<f32> {
        let (pr, pt) = (self.reflectance.max_value(), self.transmittance.max_value());
        (pr + pt > 0.0).then(|| pr / (pr + pt))
    }
}

impl Bxdf for DiffuseTransmissionLobes {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let Some(p_reflect) = self.reflection_probability() else {
            return BsdfEval::ZERO;
        };
        if wo.z == 0.0 || wi.z == 0.0 {
            return BsdfEval::ZERO;
        }
        let cos = wi.z.abs() * FRAC_1_PI;
        if wo.z * wi.z > 0.0 {
            BsdfEval {
                value: self.reflectance * cos,
                pdf: p_reflect * cos,
            }
        } else {
            BsdfEval {
                value: self.transmittance * cos,
                pdf: (1.0 - p_reflect) * cos,
            }
        }
    }

    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let p_reflect = self.reflection_probability()?;
        if wo.z == 0.0 {
            return None;
        }
        let mut wi = sample_cosine_hemisphere(u);
        let reflect = u_lobe < p_reflect;
        if (wo.z < 0.0) == reflect {
            wi.z = -wi.z;
        }
        let cos = wi.z.abs() * FRAC_1_PI;
        let (value, pdf, side) = if reflect {
            (self.reflectance, p_reflect * cos, BsdfFlags::REFLECTION)
        } else {
            (
                self.transmittance,
                (1.0 - p_reflect) * cos,
                BsdfFlags::TRANSMISSION,
            )
        };
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample::new(
            wi,
            value * (cos / pdf),
            pdf,
            BsdfFlags::DIFFUSE.union(side),
        ))
    }
}
