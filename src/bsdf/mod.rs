//! Scattering at surfaces: the BSDF interface, Mitsuba's BSDFs, their textures, and materials
//! that choose a BSDF for each side of a surface.
//!
//! BSDFs work in the local shading frame (normal = +z). Following pbrt's naming, `wo` points
//! towards where the light goes (the camera side of the path) and `wi` towards where it comes
//! from; both point away from the surface. `eval` returns f(wo, wi)·|cos θi| (the cosine is part
//! of the BSDF's value, as in Mitsuba 3), and `sample` returns that value divided by its pdf.
//!
//! The lecture's "Importance Sampling of the Reflection Integral" splits a BRDF into diffuse,
//! glossy and mirror parts and adapts the sampling to each: every BSDF here is a sum of lobes
//! with [`BsdfFlags`] saying which kind each is. `sample` first picks a lobe with a probability
//! proportional to an estimate of that lobe's albedo for the given `wo` (the `u_lobe` number),
//! then a direction within it. Smooth lobes (diffuse, glossy) have a density and can be
//! evaluated, so they take part in light sampling and multiple importance sampling; delta lobes
//! (specular mirror and refraction, and the "null" pass-through of `mask` and `thindielectric`)
//! can only be sampled, and their `pdf` is the probability of choosing them. For a sample of a
//! smooth lobe the returned pdf and weight are those of the whole BSDF (all smooth lobes'
//! densities summed), so that MIS sees the density the direction was really drawn with.
//!
//! | plugin | file | lobes |
//! | --- | --- | --- |
//! | `diffuse` | [`diffuse`] | diffuse reflection |
//! | `roughdiffuse` | [`roughdiffuse`] | diffuse reflection (Oren–Nayar) |
//! | `conductor` | [`conductor`] | specular reflection |
//! | `roughconductor` | [`roughconductor`] | glossy reflection |
//! | `dielectric` | [`dielectric`] | specular reflection and transmission |
//! | `roughdielectric` | [`roughdielectric`] | glossy reflection and transmission |
//! | `thindielectric` | [`thindielectric`] | specular reflection, null transmission |
//! | `plastic` | [`plastic`] | specular and diffuse reflection |
//! | `roughplastic` | [`roughplastic`] | glossy and diffuse reflection |
//! | `phong` | [`phong`] | glossy and diffuse reflection |
//! | `twosided` | [`twosided`] | those of the nested BSDFs, on both sides |
//! | `mask` | [`mask`] | the nested BSDF's, and null transmission |
//! | `blendbsdf` | [`blend`] | both nested BSDFs' |
//! | `bumpmap`, `normalmap` | [`bumpmap`], [`normalmap`] | the nested BSDF's, in a perturbed frame |

pub mod blend;
pub mod bumpmap;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod fresnel;
pub mod mask;
pub mod microfacet;
pub mod normalmap;
pub mod phong;
pub mod plastic;
pub mod roughconductor;
pub mod roughdielectric;
pub mod roughdiffuse;
pub mod roughplastic;

pub mod thindielectric;
pub mod twosided;

use glam::{Vec2, Vec3};

pub use crate::texture::Texture;
pub use blend::Blend;
pub use bumpmap::BumpMap;
pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use mask::Mask;
pub use normalmap::NormalMap;
pub use phong::Phong;
pub use plastic::Plastic;
pub use roughconductor::RoughConductor;
pub use roughdielectric::RoughDielectric;
pub use roughdiffuse::RoughDiffuse;
pub use roughplastic::RoughPlastic;
pub use thindielectric::ThinDielectric;
pub use twosided::TwoSided;

use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Which kind of lobe a sample or BSDF has (the lecture's split into diffuse, glossy and mirror
/// parts) and whether it reflects or transmits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    pub const DIFFUSE: BsdfFlags = BsdfFlags(1);
    pub const GLOSSY: BsdfFlags = BsdfFlags(2);
    /// A Dirac delta lobe (mirror or clear glass): cannot be evaluated, only sampled.
    pub const SPECULAR: BsdfFlags = BsdfFlags(4);
    /// Light passing straight through, unchanged in direction (Mitsuba's `Null`: the transparent
    /// part of `mask`, the transmission of `thindielectric`); a delta lobe too.
    pub const NULL: BsdfFlags = BsdfFlags(32);
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

    /// Whether this is (or includes) a delta lobe: specular or null.
    pub const fn is_delta(self) -> bool {
        self.0 & (BsdfFlags::SPECULAR.0 | BsdfFlags::NULL.0) != 0
    }
}

/// A direction drawn by a BSDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled direction, in the local frame.
    pub wi: Vec3,
    /// f(wo, wi)·|cos θi| / pdf.
    pub weight: SampledSpectrum,
    /// Density per unit solid angle (for a delta lobe: the probability of choosing it).
    pub pdf: f32,
    /// The lobe that produced the sample.
    pub flags: BsdfFlags,
    /// Relative index of refraction along the path (η_t/η_i when refracting, 1 otherwise), for
    /// Russian roulette (Mitsuba's `bs.eta`).
    pub eta: f32,
    /// Whether the direction is right for the hero wavelength only (refraction through a
    /// dispersive interface): the path must then drop its other wavelengths.
    pub terminates_secondary: bool,
}

impl BsdfSample {
    /// A sample with η = 1 that does not disperse.
    #[inline]
    pub fn new(wi: Vec3, weight: SampledSpectrum, pdf: f32, flags: BsdfFlags) -> BsdfSample {
        BsdfSample {
            wi,
            weight,
            pdf,
            flags,
            eta: 1.0,
            terminates_secondary: false,
        }
    }
}

/// The surface point a BSDF is evaluated at: texture coordinates for textures, and the local
/// geometry for the BSDFs that perturb the shading frame (bump and normal maps).
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    pub uv: Vec2,
    /// The shading frame that the local directions refer to (world space).
    pub frame: Frame,
    /// The geometric normal, on the side of `frame.n`.
    pub ng: Vec3,
    /// ∂p/∂u and ∂p/∂v (world space, not normalised).
    pub dp_du: Vec3,
    pub dp_dv: Vec3,
}

impl ShadingPoint {
    /// A point whose shading frame is the world frame (for tests and BSDF queries out of scene
    /// context).
    pub fn local(uv: Vec2) -> ShadingPoint {
        ShadingPoint {
            uv,
            frame: Frame {
                s: Vec3::X,
                t: Vec3::Y,
                n: Vec3::Z,
            },
            ng: Vec3::Z,
            dp_du: Vec3::X,
            dp_dv: Vec3::Y,
        }
    }
}

/// A BSDF (one side of a surface, unless it is two-sided by nature, as dielectrics are).
#[derive(Clone, Debug)]
pub enum Bsdf {
    Diffuse(Diffuse),
    RoughDiffuse(RoughDiffuse),
    Conductor(Conductor),
    RoughConductor(RoughConductor),
    Dielectric(Dielectric),
    RoughDielectric(RoughDielectric),
    ThinDielectric(ThinDielectric),
    Plastic(Plastic),
    RoughPlastic(RoughPlastic),
    Phong(Phong),
    TwoSided(TwoSided),
    Mask(Mask),
    Blend(Blend),
    BumpMap(BumpMap),
    NormalMap(NormalMap),
}

/// Calls the same method on whichever BSDF `$self` is.
macro_rules! dispatch {
    ($self:expr, $b:ident => $call:expr) => {
        match $self {
            Bsdf::Diffuse($b) => $call,
            Bsdf::RoughDiffuse($b) => $call,
            Bsdf::Conductor($b) => $call,
            Bsdf::RoughConductor($b) => $call,
            Bsdf::Dielectric($b) => $call,
            Bsdf::RoughDielectric($b) => $call,
            Bsdf::ThinDielectric($b) => $call,
            Bsdf::Plastic($b) => $call,
            Bsdf::RoughPlastic($b) => $call,
            Bsdf::Phong($b) => $call,
            Bsdf::TwoSided($b) => $call,
            Bsdf::Mask($b) => $call,
            Bsdf::Blend($b) => $call,
            Bsdf::BumpMap($b) => $call,
            Bsdf::NormalMap($b) => $call,
        }
    };
}

impl Bsdf {
    /// The union of the lobes' flags.
    pub fn flags(&self) -> BsdfFlags {
        dispatch!(self, b => b.flags())
    }

    /// Whether some index of refraction varies with wavelength, so that refracted directions
    /// depend on it (see [`BsdfSample::terminates_secondary`]).
    pub fn is_dispersive(&self) -> bool {
        match self {
            Bsdf::Dielectric(b) => b.eta.is_dispersive(),
            Bsdf::RoughDielectric(b) => b.eta.is_dispersive(),
            Bsdf::TwoSided(b) => b.front.is_dispersive() || b.back.is_dispersive(),
            Bsdf::Mask(b) => b.nested.is_dispersive(),
            Bsdf::Blend(b) => b.nested[0].is_dispersive() || b.nested[1].is_dispersive(),
            Bsdf::BumpMap(b) => b.nested.is_dispersive(),
            Bsdf::NormalMap(b) => b.nested.is_dispersive(),
            _ => false,
        }
    }

    /// f(wo, wi)·|cos θi| of the smooth lobes.
    #[inline]
    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        dispatch!(self, b => b.eval(sp, wo, wi, lambda))
    }

    /// Density with which [`Bsdf::sample`] returns `wi` given `wo` (smooth lobes only).
    #[inline]
    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        dispatch!(self, b => b.pdf(sp, wo, wi, lambda))
    }

    /// Draws `wi` given `wo`: `u_lobe` chooses a lobe, `u` the direction within it.
    #[inline]
    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        dispatch!(self, b => b.sample(sp, wo, u_lobe, u, lambda))
    }
}

/// For a BSDF that is a mixture of lobes: the sample of one smooth lobe turned into a sample of
/// the whole mixture, whose density at `wi` is `pdf` and whose value there is `value`.
#[inline]
pub(crate) fn mixture_sample(
    wi: Vec3,
    value: SampledSpectrum,
    pdf: f32,
    flags: BsdfFlags,
) -> Option<BsdfSample> {
    if !(pdf > 0.0) || !pdf.is_finite() {
        return None;
    }
    Some(BsdfSample::new(wi, value * (1.0 / pdf), pdf, flags))
}

/// What a surface is made of: a BSDF for the front (the side of the shading normal) and, for
/// top-level `twosided` materials, one for the back. Mitsuba's reflecting BSDFs are one-sided
/// (black from behind) unless wrapped in `twosided`; dielectrics handle both sides themselves.
#[derive(Clone, Debug)]
pub struct Material {
    pub front: Bsdf,
    pub back: Option<Bsdf>,
}

impl Material {
    /// The BSDF that applies when the outgoing direction has local z-component `cos_theta_o`,
    /// and whether the frame must be flipped to use it (back side of a two-sided material).
    /// Without a back BSDF the front one is used from both sides: it decides what its back is.
    #[inline]
    pub fn side(&self, cos_theta_o: f32) -> (&Bsdf, bool) {
        match &self.back {
            Some(back) if cos_theta_o < 0.0 => (back, true),
            _ => (&self.front, false),
        }
    }
}
