//! Mitsuba's `conductor` BSDF: a perfectly smooth metal, a mirror whose reflectance is the
//! Fresnel reflectance of the complex index η + ik at each wavelength.
//!
//! ```xml
//! <bsdf type="conductor">
//!     <string name="material" value="Au"/>       <!-- a preset -->
//!     <!-- or: <spectrum name="eta" value="..."/> <spectrum name="k" value="..."/> (or <rgb>, textures) -->
//!     <rgb name="specular_reflectance" value="1"/>   <!-- optional factor -->
//!     <float name="ext_eta" value="1.33"/>           <!-- Mitsuba 0.6: exterior index -->
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! A single specular lobe: `sample` returns the mirror direction with weight
//! F(cos θ, η(λ), k(λ)) · specular_reflectance; nothing to evaluate. One-sided. Rendered
//! polarized, its Mueller matrix is that of Fresnel reflection
//! ([`crate::polarization::fresnel::specular_reflection`]).

use glam::{Vec2, Vec3};
use wide::f32x4;

use super::fresnel::{fresnel_conductor4, reflect_z};
use super::{BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf};
use crate::polarization::fresnel::{Complex, specular_reflection};
use crate::polarization::{FrameChange, SampledMueller};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::TextureValues;
use crate::texture::{Texture, TexturePoint};

#[derive(Clone, Debug)]
pub struct Conductor {
    pub eta: Texture,
    pub k: Texture,
    pub specular_reflectance: Texture,
    /// The exterior medium's index (Mitsuba 0.6's `extEta`); 1 when the scene gives none.
    pub ext_eta: f32,
}

/// A conductor's complex index of refraction at a point, at each of a path's wavelengths
/// (shared by `conductor` and `roughconductor`).
#[derive(Clone, Copy, Debug)]
pub struct ConductorIor {
    pub eta: SampledSpectrum,
    pub k: SampledSpectrum,
}

impl ConductorIor {
    /// η and k read from textures at `at`, relative to an exterior medium of index `ext_eta`:
    /// the Fresnel equations depend on (η + ik)/η_ext only (Mitsuba 0.6, `conductor.cpp`, which
    /// divides both parts by `extEta`).
    #[inline]
    pub fn at(
        eta: &Texture,
        k: &Texture,
        ext_eta: f32,
        at: TexturePoint,
        lambda: &SampledWavelengths,
    ) -> ConductorIor {
        let inv_ext = 1.0 / ext_eta;
        ConductorIor {
            eta: eta.eval(at, lambda) * inv_ext,
            k: k.eval(at, lambda) * inv_ext,
        }
    }

    /// The Mueller matrix of reflection about the (micro)normal `m` at each wavelength, for
    /// light arriving from `wi` and leaving along `wo` (local), between the implicit Stokes
    /// bases of the two beams (Mitsuba's `conductor` and `roughconductor`).
    pub fn mueller_reflection(&self, m: Vec3, wo: Vec3, wi: Vec3) -> SampledMueller {
        let cos_theta = wi.dot(m);
        let change = FrameChange::from_plane_of_incidence(m, -wi, wo);
        SampledMueller::from_fn(|i| {
            change.apply(specular_reflection(
                cos_theta,
                Complex::new(self.eta[i], self.k[i]),
            ))
        })
    }

    /// The Fresnel reflectance at cos θ for each wavelength.
    #[inline]
    pub fn reflectance(&self, cos_theta: f32) -> SampledSpectrum {
        let reflectance =
            fresnel_conductor4(cos_theta, f32x4::from(self.eta.0), f32x4::from(self.k.0));
        SampledSpectrum(reflectance.to_array())
    }
}

impl LeafBsdf for Conductor {
    type Lobes<'a> = ConductorLobes;
    const FLAGS: BsdfFlags = BsdfFlags::SPECULAR.union(BsdfFlags::REFLECTION);

    #[inline]
    fn lobes(&self, at: TexturePoint, lambda: &SampledWavelengths) -> ConductorLobes {
        ConductorLobes {
            ior: ConductorIor::at(&self.eta, &self.k, self.ext_eta, at, lambda),
            specular_reflectance: self.specular_reflectance.eval(at, lambda),
        }
    }
}

/// The mirror lobe at a point.
#[derive(Clone, Copy, Debug)]
pub struct ConductorLobes {
    pub ior: ConductorIor,
    pub specular_reflectance: SampledSpectrum,
}

impl Bxdf for ConductorLobes {
    fn sample(&self, _tree: &BxdfTree, wo: Vec3, _u_lobe: f32, _u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let weight = self.ior.reflectance(wo.z) * self.specular_reflectance;
        Some(BsdfSample::new(
            reflect_z(wo),
            weight,
            1.0,
            Conductor::FLAGS,
        ))
    }

    fn mueller(
        &self,
        _tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        _lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        Some(self.ior.mueller_reflection(Vec3::Z, wo, wi))
    }
}
