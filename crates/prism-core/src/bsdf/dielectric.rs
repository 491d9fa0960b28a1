//! Mitsuba's `dielectric` BSDF: a smooth interface between two dielectrics (glass, water),
//! reflecting and refracting by the Fresnel equations, from both sides.
//!
//! ```xml
//! <bsdf type="dielectric">
//!     <string name="int_ior" value="bk7"/>     <!-- number or name -->
//!     <string name="ext_ior" value="air"/>
//!     <!-- dispersive: <spectrum name="int_ior" type="sellmeier"> ... </spectrum>, see spectrum::ior -->
//!     <rgb name="specular_reflectance" value="1"/>     <!-- optional factors -->
//!     <rgb name="specular_transmittance" value="1"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Two specular lobes, chosen with the probabilities F and 1 − F, so the weights are 1 (times the
//! optional factors, and (η_i/η_t)² for transmitted radiance, which is compressed into a smaller
//! solid angle: Veach 1997, §5.2). With a dispersive index (our extension; Mitsuba's indices are
//! constants) F differs per wavelength: reflection keeps all wavelengths with weights F(λ)/F̄
//! (F̄ the mean over the path's wavelengths, the choice probability); refraction follows the hero
//! wavelength's direction and asks the integrator to drop the others
//! ([`BsdfSample::terminates_secondary`]), so that each wavelength leaves in its own direction
//! and the image shows true dispersion.

use glam::{Vec2, Vec3};

use super::fresnel::{fresnel_dielectric, reflect_z, refract_z};
use super::{BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::polarization::fresnel::{Complex, specular_reflection, specular_transmission};
use crate::polarization::{FrameChange, SampledMueller};
use crate::spectrum::ior::RelativeIor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::TextureValues;
use crate::texture::{Texture, TexturePoint};

#[derive(Clone, Debug)]
pub struct Dielectric {
    pub interface: SmoothInterface,
}

/// A smooth interface between two dielectrics as `dielectric` and `thindielectric` describe it.
#[derive(Clone, Debug)]
pub struct SmoothInterface {
    /// η = n_interior / n_exterior.
    pub eta: RelativeIor,
    pub specular: SpecularFactorTextures,
}

/// A [`SmoothInterface`] at a point, for a path's wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct SmoothInterfaceAt {
    pub eta: SampledIor,
    pub specular: SpecularFactors,
}

impl SmoothInterface {
    #[inline]
    pub fn at(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SmoothInterfaceAt {
        SmoothInterfaceAt {
            eta: SampledIor::at(&self.eta, lambda),
            specular: self.specular.at(at, lambda),
        }
    }
}

/// An optional factor evaluated at a point: 1 when absent.
#[inline]
pub(crate) fn optional_factor(
    texture: &Option<Texture>,
    at: TexturePoint,
    lambda: &SampledWavelengths,
) -> SampledSpectrum {
    match texture {
        Some(t) => t.eval(at, lambda),
        None => SampledSpectrum::ONE,
    }
}

/// The optional factors of a dielectric's reflection and transmission (Mitsuba's
/// `specular_reflectance` and `specular_transmittance`) at a point: 1 where absent.
#[derive(Clone, Copy, Debug)]
pub struct SpecularFactors {
    pub reflectance: SampledSpectrum,
    pub transmittance: SampledSpectrum,
}

/// The textures of a dielectric's [`SpecularFactors`], each optional.
#[derive(Clone, Debug)]
pub struct SpecularFactorTextures {
    pub reflectance: Option<Texture>,
    pub transmittance: Option<Texture>,
}

impl SpecularFactorTextures {
    #[inline]
    pub fn at(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SpecularFactors {
        SpecularFactors {
            reflectance: optional_factor(&self.reflectance, at, lambda),
            transmittance: optional_factor(&self.transmittance, at, lambda),
        }
    }
}

/// A relative index of refraction at a path's wavelengths: η(λᵢ) for each when it is
/// dispersive, else the one value everywhere.
#[derive(Clone, Copy, Debug)]
pub struct SampledIor {
    pub eta: SampledSpectrum,
    pub dispersive: bool,
}

impl SampledIor {
    #[inline]
    pub fn at(eta: &RelativeIor, lambda: &SampledWavelengths) -> SampledIor {
        let dispersive = eta.is_dispersive();
        SampledIor {
            eta: if dispersive {
                SampledSpectrum::from_fn(|i| eta.at(lambda.lambda(i)))
            } else {
                SampledSpectrum::splat(eta.at(lambda.lambda(0)))
            },
            dispersive,
        }
    }

    /// η at the hero wavelength.
    #[inline]
    pub fn hero(&self) -> f32 {
        self.eta[0]
    }
}

impl LeafBsdf for Dielectric {
    type Lobes<'a> = DielectricLobes;
    const FLAGS: BsdfFlags = BsdfFlags::SPECULAR
        .union(BsdfFlags::REFLECTION)
        .union(BsdfFlags::TRANSMISSION);

    fn is_dispersive(&self) -> bool {
        self.interface.eta.is_dispersive()
    }

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> DielectricLobes {
        DielectricLobes {
            interface: self.interface.at(at, lambda),
        }
    }
}

/// The reflected and refracted lobes at a point.
#[derive(Clone, Copy, Debug)]
pub struct DielectricLobes {
    pub interface: SmoothInterfaceAt,
}

impl Bxdf for DielectricLobes {
    fn sample(&self, _tree: &BxdfTree, wo: Vec3, u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        let cos_o = wo.z;
        if cos_o == 0.0 || !cos_o.is_finite() {
            return None;
        }
        let hero = fresnel_dielectric(cos_o, self.interface.eta.hero());
        let dispersive = self.interface.eta.dispersive;
        let reflectance = if dispersive {
            SampledSpectrum::from_fn(|i| {
                fresnel_dielectric(cos_o, self.interface.eta.eta[i]).reflectance
            })
        } else {
            SampledSpectrum::splat(hero.reflectance)
        };
        let p_reflect = if dispersive {
            reflectance.average()
        } else {
            hero.reflectance
        };
        if u_lobe < p_reflect {
            let weight = reflectance * (1.0 / p_reflect) * self.interface.specular.reflectance;
            return Some(BsdfSample::new(
                reflect_z(wo),
                weight,
                p_reflect,
                BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION),
            ));
        }
        if hero.reflectance >= 1.0 {
            // Total internal reflection at the hero wavelength: it has no refracted light.
            return None;
        }
        let p_transmit = 1.0 - p_reflect;
        let transmittance = (SampledSpectrum::ONE - reflectance) * (1.0 / p_transmit);
        let radiance_scale = hero.eta_ti * hero.eta_ti;
        let weight = transmittance * radiance_scale * self.interface.specular.transmittance;
        Some(BsdfSample {
            wi: refract_z(wo, hero.cos_theta_t, hero.eta_ti),
            weight,
            pdf: p_transmit,
            flags: BsdfFlags::SPECULAR.union(BsdfFlags::TRANSMISSION),
            eta: hero.eta_it,
            terminates_secondary: dispersive,
        })
    }

    /// Fresnel reflection or refraction, whichever takes light from `wi` to `wo` (Mitsuba's
    /// `dielectric`).
    fn mueller(
        &self,
        _tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        _lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        let eta = &self.interface.eta;
        let reflected = wi.z * wo.z > 0.0;
        let change = FrameChange::from_plane_of_incidence(Vec3::Z, -wi, wo);
        Some(SampledMueller::from_fn(|i| {
            let eta = if eta.dispersive {
                eta.eta[i]
            } else {
                eta.hero()
            };
            let m = if reflected {
                specular_reflection(wi.z, Complex::real(eta))
            } else {
                specular_transmission(wi.z, eta)
            };
            change.apply(m)
        }))
    }
}
