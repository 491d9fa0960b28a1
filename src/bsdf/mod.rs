//! Scattering at surfaces: the BSDF interface, the BSDFs, and materials that choose a BSDF for
//! each side of a surface.
//!
//! BSDFs work in the local shading frame (normal = +z). Following pbrt's naming, `wo` points
//! towards where the light goes (the camera side of the path) and `wi` towards where it comes
//! from; both point away from the surface. `eval` returns f(wo, wi)·|cos θi| (the cosine is part
//! of the BSDF's value, as in Mitsuba 3), and `sample` returns that value divided by its pdf.

pub mod diffuse;

use glam::Vec3;

use crate::spectrum::{SampledSpectrum, SampledWavelengths};
pub use diffuse::Diffuse;

/// Which kind of lobe a sample or BSDF has (the lecture's split into diffuse, glossy and mirror
/// parts) and whether it reflects or transmits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    pub const DIFFUSE: BsdfFlags = BsdfFlags(1);
    pub const GLOSSY: BsdfFlags = BsdfFlags(2);
    /// A Dirac delta lobe (mirror or clear glass): cannot be evaluated, only sampled.
    pub const SPECULAR: BsdfFlags = BsdfFlags(4);
    pub const REFLECTION: BsdfFlags = BsdfFlags(8);
    pub const TRANSMISSION: BsdfFlags = BsdfFlags(16);

    pub const fn union(self, other: BsdfFlags) -> BsdfFlags {
        BsdfFlags(self.0 | other.0)
    }

    pub const fn contains(self, other: BsdfFlags) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether some lobe can be evaluated (is not a delta), so light sampling can help.
    pub const fn has_smooth_lobe(self) -> bool {
        self.0 & (BsdfFlags::DIFFUSE.0 | BsdfFlags::GLOSSY.0) != 0
    }
}

/// A direction drawn by a BSDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled direction, in the local frame.
    pub wi: Vec3,
    /// f(wo, wi)·|cos θi| / pdf.
    pub weight: SampledSpectrum,
    /// Density per unit solid angle (for a specular lobe: the probability of choosing it).
    pub pdf: f32,
    /// The lobe that produced the sample.
    pub flags: BsdfFlags,
}

/// A BSDF (one side of a surface).
#[derive(Clone, Debug)]
pub enum Bsdf {
    Diffuse(Diffuse),
}

impl Bsdf {
    pub fn flags(&self) -> BsdfFlags {
        match self {
            Bsdf::Diffuse(_) => BsdfFlags::DIFFUSE.union(BsdfFlags::REFLECTION),
        }
    }

    /// f(wo, wi)·|cos θi|.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Bsdf::Diffuse(b) => b.eval(wo, wi, lambda),
        }
    }

    /// Density with which [`Bsdf::sample`] returns `wi` given `wo`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            Bsdf::Diffuse(b) => b.pdf(wo, wi),
        }
    }

    /// Draws `wi` given `wo`: `u_lobe` chooses a lobe, `u` the direction within it.
    #[inline]
    pub fn sample(
        &self,
        wo: Vec3,
        u_lobe: f32,
        u: glam::Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        match self {
            Bsdf::Diffuse(b) => b.sample(wo, u_lobe, u, lambda),
        }
    }
}

/// What a surface is made of: a BSDF for the front (the side of the shading normal) and, for
/// two-sided materials, one for the back. Mitsuba's BSDFs are one-sided (black from behind)
/// unless wrapped in `twosided`.
#[derive(Clone, Debug)]
pub struct Material {
    pub front: Bsdf,
    pub back: Option<Bsdf>,
}

impl Material {
    /// The BSDF that applies when the outgoing direction has local z-component `cos_theta_o`,
    /// and whether the frame must be flipped to use it (back side of a two-sided material).
    #[inline]
    pub fn side(&self, cos_theta_o: f32) -> Option<(&Bsdf, bool)> {
        if cos_theta_o >= 0.0 {
            Some((&self.front, false))
        } else {
            self.back.as_ref().map(|b| (b, true))
        }
    }
}
