//! The interfaces of pbrt-v4's layered BSDFs ([`super::layered`]), in pbrt's own conventions:
//! its `DielectricBxDF` (the coating), `DiffuseBxDF` and `ConductorBxDF` (the bases), each with
//! f(wo, wi) *without* the cosine, sampling restricted to reflection or transmission, and the
//! transport mode that scales radiance refracted into another medium by 1/η'² (Pharr, Jakob
//! & Humphreys 2023, "Physically Based Rendering", 4th ed., §9.3–9.5, §9.7, §14.3.2).
//!
//! Rough interfaces use the Trowbridge–Reitz (GGX) distribution sampled by visible normals with
//! pbrt-v4's height-correlated masking-shadowing G(wo, wi) = 1 / (1 + Λ(wo) + Λ(wi)); below
//! α = 10⁻³ an interface is smooth (pbrt's `EffectivelySmooth`).

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::conductor::ConductorIor;
use super::fresnel::{fresnel_dielectric, reflect, reflect_z, refract};
use super::microfacet::{Microfacet, MicrofacetKind};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};
use crate::spectrum::SampledSpectrum;

/// Which quantity a path carries (pbrt's `TransportMode`): radiance from the camera's side, or
/// importance from the light's. Only radiance refracted into another medium is scaled by 1/η'².
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    Radiance,
    Importance,
}

impl Transport {
    /// The other mode (pbrt's `!mode`), for the walk that starts from the light's side.
    pub fn adjoint(self) -> Transport {
        match self {
            Transport::Radiance => Transport::Importance,
            Transport::Importance => Transport::Radiance,
        }
    }
}

/// Which lobes a sample may come from (pbrt's `BxDFReflTransFlags`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lobes {
    pub reflection: bool,
    pub transmission: bool,
}

impl Lobes {
    pub const ALL: Lobes = Lobes {
        reflection: true,
        transmission: true,
    };
    pub const REFLECTION: Lobes = Lobes {
        reflection: true,
        transmission: false,
    };
    pub const TRANSMISSION: Lobes = Lobes {
        reflection: false,
        transmission: true,
    };
}

/// A direction drawn by an interface: pbrt's `BSDFSample`, f without the cosine.
#[derive(Clone, Copy, Debug)]
pub struct InterfaceSample {
    pub f: SampledSpectrum,
    pub wi: Vec3,
    pub pdf: f32,
    pub specular: bool,
    pub transmission: bool,
}

impl InterfaceSample {
    /// Whether the sample carries anything (pbrt's `!bs || !bs->f || bs->pdf == 0 ||
    /// bs->wi.z == 0` test, negated).
    fn useful(self) -> Option<InterfaceSample> {
        (!self.f.is_black() && self.pdf > 0.0 && self.wi.z != 0.0).then_some(self)
    }
}

/// pbrt's `EffectivelySmooth` bound on α.
const SMOOTH_ALPHA: f32 = 1e-3;

/// A Trowbridge–Reitz distribution with roughness (αu, αv), or `None` where it is smooth.
pub fn trowbridge_reitz(alpha_u: f32, alpha_v: f32) -> Option<Microfacet> {
    (alpha_u.max(alpha_v) >= SMOOTH_ALPHA)
        .then(|| Microfacet::new(MicrofacetKind::Ggx, alpha_u, alpha_v))
}

/// pbrt-v4's height-correlated masking-shadowing term 1 / (1 + Λ(wo) + Λ(wi)).
fn masking(distribution: &Microfacet, wo: Vec3, wi: Vec3) -> f32 {
    1.0 / (1.0 + distribution.lambda(wo) + distribution.lambda(wi))
}

/// The density of normals visible from `w` on either side: G₁(w) D(m) |w·m| / |cos θ|.
fn visible_pdf(distribution: &Microfacet, w: Vec3, m: Vec3) -> f32 {
    let up = if w.z < 0.0 { -w } else { w };
    distribution.pdf_visible(up, m)
}

/// A dielectric interface of relative index η (inside over outside), smooth or rough: pbrt's
/// `DielectricBxDF`. η = 1 lets everything through unchanged.
#[derive(Clone, Copy, Debug)]
pub struct DielectricInterface {
    pub eta: f32,
    pub distribution: Option<Microfacet>,
}

impl DielectricInterface {
    /// Whether its lobes are Dirac deltas.
    pub fn is_specular(&self) -> bool {
        self.eta == 1.0 || self.distribution.is_none()
    }

    /// The generalised half vector of (wo, wi) on the upper side, with the relative index
    /// along the path and whether the pair reflects; `None` where pbrt returns zero
    /// (grazing directions, back-facing microfacets).
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, bool)> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return None;
        }
        let reflect = cos_o * cos_i > 0.0;
        let etap = match (reflect, cos_o > 0.0) {
            (true, _) => 1.0,
            (false, true) => self.eta,
            (false, false) => 1.0 / self.eta,
        };
        let m = (wi * etap + wo).normalize_or_zero();
        if m == Vec3::ZERO {
            return None;
        }
        let m = if m.z < 0.0 { -m } else { m };
        if m.dot(wi) * cos_i < 0.0 || m.dot(wo) * cos_o < 0.0 {
            return None;
        }
        Some((m, etap, reflect))
    }

    /// f(wo, wi), zero for a smooth interface.
    pub fn f(&self, wo: Vec3, wi: Vec3, mode: Transport) -> f32 {
        let Some(distribution) = self.distribution.filter(|_| self.eta != 1.0) else {
            return 0.0;
        };
        let Some((m, etap, reflect)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let f = fresnel_dielectric(wo.dot(m), self.eta).reflectance;
        let (d, g) = (distribution.d(m), masking(&distribution, wo, wi));
        if reflect {
            return d * g * f / (4.0 * wi.z * wo.z).abs();
        }
        let denominator = (wi.dot(m) + wo.dot(m) / etap).powi(2) * wi.z * wo.z;
        let ft = d * (1.0 - f) * g * (wi.dot(m) * wo.dot(m) / denominator).abs();
        match mode {
            Transport::Radiance => ft / (etap * etap),
            Transport::Importance => ft,
        }
    }

    /// The density of sampling `wi` from `wo` with only the lobes `lobes`; zero for a smooth
    /// interface.
    pub fn pdf(&self, wo: Vec3, wi: Vec3, lobes: Lobes) -> f32 {
        let Some(distribution) = self.distribution.filter(|_| self.eta != 1.0) else {
            return 0.0;
        };
        let Some((m, etap, reflect)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let r = fresnel_dielectric(wo.dot(m), self.eta).reflectance;
        let (pr, pt) = choice(r, lobes);
        if pr == 0.0 && pt == 0.0 {
            return 0.0;
        }
        let visible = visible_pdf(&distribution, wo, m);
        if reflect {
            visible / (4.0 * wo.dot(m).abs()) * pr / (pr + pt)
        } else {
            let denominator = (wi.dot(m) + wo.dot(m) / etap).powi(2);
            visible * wi.dot(m).abs() / denominator * pt / (pr + pt)
        }
    }

    /// Draws wi from `wo` among `lobes`: `uc` chooses reflection or transmission, `u` the
    /// microfacet normal.
    pub fn sample(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: Transport,
        lobes: Lobes,
    ) -> Option<InterfaceSample> {
        let scale = |etap: f32| match mode {
            Transport::Radiance => 1.0 / (etap * etap),
            Transport::Importance => 1.0,
        };
        let Some(distribution) = self.distribution.filter(|_| self.eta != 1.0) else {
            let fresnel = fresnel_dielectric(wo.z, self.eta);
            let (pr, pt) = choice(fresnel.reflectance, lobes);
            if pr == 0.0 && pt == 0.0 {
                return None;
            }
            let sample = if uc < pr / (pr + pt) {
                let wi = reflect_z(wo);
                InterfaceSample {
                    f: SampledSpectrum::splat(fresnel.reflectance / wi.z.abs()),
                    wi,
                    pdf: pr / (pr + pt),
                    specular: true,
                    transmission: false,
                }
            } else {
                let wi = refract(wo, Vec3::Z, fresnel.cos_theta_t, fresnel.eta_ti);
                let t = 1.0 - fresnel.reflectance;
                InterfaceSample {
                    f: SampledSpectrum::splat(t / wi.z.abs() * scale(fresnel.eta_it)),
                    wi,
                    pdf: pt / (pr + pt),
                    specular: true,
                    transmission: true,
                }
            };
            return sample.useful();
        };
        if wo.z == 0.0 {
            return None;
        }
        let up = if wo.z < 0.0 { -wo } else { wo };
        let m = distribution.sample_visible(up, u);
        let fresnel = fresnel_dielectric(wo.dot(m), self.eta);
        let r = fresnel.reflectance;
        let (pr, pt) = choice(r, lobes);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        let visible = distribution.pdf_visible(up, m);
        let sample = if uc < pr / (pr + pt) {
            let wi = reflect(wo, m);
            if wo.z * wi.z <= 0.0 {
                return None;
            }
            let f =
                distribution.d(m) * masking(&distribution, wo, wi) * r / (4.0 * wi.z * wo.z).abs();
            InterfaceSample {
                f: SampledSpectrum::splat(f),
                wi,
                pdf: visible / (4.0 * wo.dot(m).abs()) * pr / (pr + pt),
                specular: false,
                transmission: false,
            }
        } else {
            if r >= 1.0 {
                return None;
            }
            let wi = refract(wo, m, fresnel.cos_theta_t, fresnel.eta_ti);
            if wo.z * wi.z >= 0.0 {
                return None;
            }
            let etap = fresnel.eta_it;
            let denominator = (wi.dot(m) + wo.dot(m) / etap).powi(2);
            let pdf = visible * wi.dot(m).abs() / denominator * pt / (pr + pt);
            let ft = distribution.d(m)
                * (1.0 - r)
                * masking(&distribution, wo, wi)
                * (wi.dot(m) * wo.dot(m) / (wi.z * wo.z * denominator)).abs();
            InterfaceSample {
                f: SampledSpectrum::splat(ft * scale(etap)),
                wi,
                pdf,
                specular: false,
                transmission: true,
            }
        };
        sample.useful()
    }
}

/// The probabilities of choosing reflection and transmission: the Fresnel reflectance `r` and
/// 1 − r, each zero where `lobes` leaves it out.
fn choice(r: f32, lobes: Lobes) -> (f32, f32) {
    (
        if lobes.reflection { r } else { 0.0 },
        if lobes.transmission { 1.0 - r } else { 0.0 },
    )
}

/// The opaque base under a coating: Lambertian (pbrt's `DiffuseBxDF`) or a conductor, smooth
/// or rough (pbrt's `ConductorBxDF`). Both reflect on whichever side `wo` lies.
#[derive(Clone, Copy, Debug)]
pub enum Base {
    Diffuse {
        reflectance: SampledSpectrum,
    },
    Conductor {
        ior: ConductorIor,
        distribution: Option<Microfacet>,
    },
}

impl Base {
    /// Whether its lobe is a Dirac delta (a smooth conductor).
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            Base::Conductor {
                distribution: None,
                ..
            }
        )
    }

    /// f(wo, wi).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        if wo.z * wi.z <= 0.0 {
            return SampledSpectrum::ZERO;
        }
        match self {
            Base::Diffuse { reflectance } => *reflectance * FRAC_1_PI,
            Base::Conductor {
                distribution: None, ..
            } => SampledSpectrum::ZERO,
            Base::Conductor {
                ior,
                distribution: Some(distribution),
            } => {
                let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
                let m = (wo + wi).normalize_or_zero();
                if m == Vec3::ZERO {
                    return SampledSpectrum::ZERO;
                }
                let m = if m.z < 0.0 { -m } else { m };
                ior.reflectance(wo.dot(m).abs())
                    * (distribution.d(m) * masking(distribution, wo, wi) / (4.0 * cos_i * cos_o))
            }
        }
    }

    /// The density of sampling `wi` from `wo`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z * wi.z <= 0.0 {
            return 0.0;
        }
        match self {
            Base::Diffuse { .. } => cosine_hemisphere_pdf(Vec3::new(wi.x, wi.y, wi.z.abs())),
            Base::Conductor {
                distribution: None, ..
            } => 0.0,
            Base::Conductor {
                distribution: Some(distribution),
                ..
            } => {
                let m = (wo + wi).normalize_or_zero();
                if m == Vec3::ZERO {
                    return 0.0;
                }
                let m = if m.z < 0.0 { -m } else { m };
                visible_pdf(distribution, wo, m) / (4.0 * wo.dot(m).abs())
            }
        }
    }

    /// Draws a reflected direction from `wo` (the base never transmits).
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<InterfaceSample> {
        let sample = match self {
            Base::Diffuse { reflectance } => {
                let mut wi = sample_cosine_hemisphere(u);
                if wo.z < 0.0 {
                    wi.z = -wi.z;
                }
                InterfaceSample {
                    f: *reflectance * FRAC_1_PI,
                    wi,
                    pdf: cosine_hemisphere_pdf(Vec3::new(wi.x, wi.y, wi.z.abs())),
                    specular: false,
                    transmission: false,
                }
            }
            Base::Conductor {
                ior,
                distribution: None,
            } => {
                let wi = reflect_z(wo);
                InterfaceSample {
                    f: ior.reflectance(wi.z.abs()) * (1.0 / wi.z.abs()),
                    wi,
                    pdf: 1.0,
                    specular: true,
                    transmission: false,
                }
            }
            Base::Conductor {
                ior,
                distribution: Some(distribution),
            } => {
                if wo.z == 0.0 {
                    return None;
                }
                let up = if wo.z < 0.0 { -wo } else { wo };
                let m = distribution.sample_visible(up, u);
                let wi = reflect(wo, m);
                if wo.z * wi.z <= 0.0 {
                    return None;
                }
                let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
                let f = ior.reflectance(wo.dot(m).abs())
                    * (distribution.d(m) * masking(distribution, wo, wi) / (4.0 * cos_i * cos_o));
                InterfaceSample {
                    f,
                    wi,
                    pdf: distribution.pdf_visible(up, m) / (4.0 * wo.dot(m).abs()),
                    specular: false,
                    transmission: false,
                }
            }
        };
        sample.useful()
    }
}
