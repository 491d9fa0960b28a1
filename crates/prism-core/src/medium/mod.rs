//! Participating media: Mitsuba 3's `homogeneous` and `heterogeneous` media (and pbrt-v4's grid
//! media, a density times absorption and scattering spectra) with their phase
//! functions ([`phase`]) and the volumes that give a heterogeneous medium's coefficients
//! ([`volume`], grids looked up as [`lattice`] describes), and the three operations a
//! volumetric path tracer needs from them.
//!
//! A medium has an extinction coefficient σ_t (per unit length, `scale` times the given
//! `sigma_t`) and a single-scattering albedo α, so σ_s = α σ_t and σ_a = σ_t − σ_s. Along a
//! ray, light is attenuated by the transmittance T(t) = exp(−∫₀ᵗ σ_t) and gains in-scattered
//! light σ_s ∫ p L at every point (the radiative transfer equation; pbrt-v4 §14.1).
//!
//! A microflake phase function (`sggx`) makes both coefficients depend on the direction of
//! travel d as well, through the flakes' projected area σ(d) ([`PhaseFunction::projected_area`]),
//! so [`Medium::coefficients`] and the majorants take d.
//!
//! # Tracking with one majorant for the four wavelengths
//! A path carries four wavelengths, and σ_t may differ between them (a chromatic medium). The
//! free-flight distances are drawn with a single majorant m ≥ σ_t(x, λᵢ) for all four (its
//! largest value over them: for a homogeneous medium maxᵢ σ_t(λᵢ), for a heterogeneous one the
//! grid's maximum, for a density grid times a spectrum the density's maximum times maxᵢ σ_t(λᵢ)
//! per unit density), as tentative collisions with density m·exp(−m t) (delta tracking, Woodcock
//! et al. 1965). At a tentative collision, each wavelength i has a real part σ_t(λᵢ) and a null
//! part σ_n(λᵢ) = m − σ_t(λᵢ); one event is chosen for all four (spectral tracking, Kutz et al.
//! 2017, "Spectral and Decomposition Tracking for Rendering Heterogeneous Volumes", §4) with the
//! history-aware probabilities P_real = Σᵢ βᵢ σ_t(λᵢ) / (m Σᵢ βᵢ), P_null = 1 − P_real (βᵢ the
//! path throughput), and each wavelength is weighted by its own coefficient over the event's
//! probability density: σ_s(λᵢ) / (m P_real) for a real collision (which scatters, the
//! absorbed part left in the weight as Mitsuba does), σ_n(λᵢ) / (m P_null) for a null one.
//! That is unbiased for every wavelength at once, because the distance density m·exp(−m t) and
//! the probability of passing a segment, exp(−m t), are the same for all four and cancel
//! against the majorant's own attenuation.
//!
//! Why not hero-wavelength tracking (Mitsuba 3's `volpath` samples distances with the hero's
//! σ_t and weights the others by exp(−(σ_t(λᵢ) − σ_t(λ₀)) t))? Those weights are unbounded
//! and grow exponentially with distance when a companion wavelength is less extinct than the
//! hero, so chromatic media get fireflies. Here every weight is bounded (by N = 4 times the
//! ratio of coefficients) and the majorant is one number per path segment, which a
//! lane-parallel integrator can share across lanes. The price is extra null collisions where
//! the four extinctions differ. (`volpathmis` takes the other route and bounds the hero's
//! weights by multiple importance sampling over the four wavelengths' densities, with each
//! wavelength's own majorant, [`Medium::majorants`]; see `integrator::volpathmis`.)
//!
//! # Transmittance of shadow rays
//! A homogeneous medium's transmittance is the closed form exp(−σ_t d); a heterogeneous one's
//! is estimated by ratio tracking (Novák et al. 2014, "Residual Ratio Tracking", §3): tentative
//! collisions with the majorant, each multiplying the estimate by 1 − σ_t(x, λᵢ)/m, whose
//! expectation is exp(−∫σ_t) for every wavelength.

pub mod lattice;
pub mod phase;
pub mod volume;

use glam::Vec3;

pub use phase::{
    BlendPhase, HenyeyGreenstein, Isotropic, PhaseFunction, PhaseModel, PhaseSample, Rayleigh,
    Sggx, TabulatedPhase,
};
pub use volume::{ConstantInBox, GridFilter, GridVolume, GridWrap, SpectralGridVolume, Volume};

use crate::dispatch::plugin_class;
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

/// A medium as the scene describes it.
#[derive(Clone, Debug)]
pub struct Medium {
    pub kind: MediumKind,
    pub phase: PhaseFunction,
    /// Whether light sampling (next-event estimation) is used at scattering points in this
    /// medium (Mitsuba's `sample_emitters`); without it, only phase-function samples find
    /// emitters.
    pub sample_emitters: bool,
}

plugin_class! {
    /// What every kind of medium answers: its coefficients at a point, a bound on them, and
    /// where along a ray it may be non-empty.
    pub trait MediumModel {
        /// The coefficients at `p` for the wavelengths `lambda`.
        fn coefficients(&self, p: Vec3, lambda: &SampledWavelengths) -> MediumCoefficients;

        /// Whether σ_t is the same everywhere (σ_s may vary with the albedo, as in
        /// [`HomogeneousExtinction`]).
        fn is_homogeneous(&self) -> bool;

        /// A majorant m ≥ σ_t(x, λᵢ) for every point and each of the wavelengths `lambda`.
        fn majorant(&self, lambda: &SampledWavelengths) -> f32;

        /// The parameter interval of `ray` (unit direction) in which the medium may be
        /// non-empty, within [0, t_max].
        fn ray_extent(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)>;
    }

    /// How a medium's coefficients vary.
    #[derive(Clone, Debug)]
    pub enum MediumKind {
        Homogeneous(Homogeneous),
        HomogeneousAbsorbingScattering(HomogeneousAbsorbingScattering),
        HomogeneousExtinction(HomogeneousExtinction),
        Heterogeneous(Heterogeneous),
        HeterogeneousAbsorbingScattering(HeterogeneousAbsorbingScattering),
    }
}

/// A medium whose coefficients are the same everywhere: it answers [`MediumModel`] from them,
/// with its largest σ_t over the wavelengths as the majorant (a tight one, so delta tracking
/// meets no null collision) and the whole ray as its extent.
pub trait HomogeneousModel {
    /// The coefficients, at every point, for the wavelengths `lambda`.
    fn uniform_coefficients(&self, lambda: &SampledWavelengths) -> MediumCoefficients;
}

impl<M: HomogeneousModel> MediumModel for M {
    #[inline]
    fn coefficients(&self, _p: Vec3, lambda: &SampledWavelengths) -> MediumCoefficients {
        self.uniform_coefficients(lambda)
    }

    fn is_homogeneous(&self) -> bool {
        true
    }

    #[inline]
    fn majorant(&self, lambda: &SampledWavelengths) -> f32 {
        self.uniform_coefficients(lambda).sigma_t.max_value()
    }

    fn ray_extent(&self, _ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        Some((0.0, t_max))
    }
}

/// The same σ_t = scale·sigma_t and albedo everywhere.
#[derive(Clone, Debug)]
pub struct Homogeneous {
    pub sigma_t: Spectrum,
    pub albedo: Spectrum,
    pub scale: f32,
}

impl HomogeneousModel for Homogeneous {
    #[inline]
    fn uniform_coefficients(&self, lambda: &SampledWavelengths) -> MediumCoefficients {
        let sigma_t = self.sigma_t.sample(lambda) * self.scale;
        MediumCoefficients {
            sigma_s: sigma_t * self.albedo.sample(lambda),
            sigma_t,
        }
    }
}

/// The same σ_a = scale·sigma_a and σ_s = scale·sigma_s everywhere (Mitsuba 0.6's form), so
/// σ_t = σ_a + σ_s.
#[derive(Clone, Debug)]
pub struct HomogeneousAbsorbingScattering {
    pub sigma_a: Spectrum,
    pub sigma_s: Spectrum,
    pub scale: f32,
}

impl HomogeneousModel for HomogeneousAbsorbingScattering {
    #[inline]
    fn uniform_coefficients(&self, lambda: &SampledWavelengths) -> MediumCoefficients {
        let sigma_s = self.sigma_s.sample(lambda) * self.scale;
        MediumCoefficients {
            sigma_t: self.sigma_a.sample(lambda) * self.scale + sigma_s,
            sigma_s,
        }
    }
}

/// The same σ_t = scale·sigma_t everywhere with an albedo that varies, α(x) from a volume
/// (Mitsuba 3's `homogeneous` medium given a `gridvolume` albedo): the extinction, and so the
/// free flights, majorant and transmittance, are a homogeneous medium's; only the scattering
/// σ_s(x) = α(x) σ_t varies.
#[derive(Clone, Debug)]
pub struct HomogeneousExtinction {
    pub sigma_t: Spectrum,
    pub albedo: Volume,
    pub scale: f32,
}

impl MediumModel for HomogeneousExtinction {
    #[inline]
    fn coefficients(&self, p: Vec3, lambda: &SampledWavelengths) -> MediumCoefficients {
        let sigma_t = self.sigma_t.sample(lambda) * self.scale;
        MediumCoefficients {
            sigma_s: sigma_t * self.albedo.eval(p, lambda),
            sigma_t,
        }
    }

    fn is_homogeneous(&self) -> bool {
        true
    }

    #[inline]
    fn majorant(&self, lambda: &SampledWavelengths) -> f32 {
        (self.sigma_t.sample(lambda) * self.scale).max_value()
    }

    fn ray_extent(&self, _ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        Some((0.0, t_max))
    }
}

/// σ_t(x) = scale·sigma_t(x) and albedo(x) from volumes; outside the box of a grid `sigma_t`
/// the medium is empty.
#[derive(Clone, Debug)]
pub struct Heterogeneous {
    pub sigma_t: Volume,
    pub albedo: Volume,
    pub scale: f32,
}

impl MediumModel for Heterogeneous {
    #[inline]
    fn coefficients(&self, p: Vec3, lambda: &SampledWavelengths) -> MediumCoefficients {
        let sigma_t = self.sigma_t.eval(p, lambda) * self.scale;
        MediumCoefficients {
            sigma_s: sigma_t * self.albedo.eval(p, lambda),
            sigma_t,
        }
    }

    fn is_homogeneous(&self) -> bool {
        false
    }

    #[inline]
    fn majorant(&self, _lambda: &SampledWavelengths) -> f32 {
        self.sigma_t.max_value() * self.scale
    }

    fn ray_extent(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        self.sigma_t.ray_extent(ray, t_max)
    }
}

/// A density d(x) from a volume times absorption and scattering spectra (pbrt-v4's grid media,
/// `GridMedium` in `src/pbrt/media.h`): σ_a(x, λ) = scale·d(x)·sigma_a(λ) and
/// σ_s(x, λ) = scale·d(x)·sigma_s(λ), so σ_t(x, λ) = scale·d(x)·(sigma_a(λ) + sigma_s(λ)) and
/// the albedo sigma_s/(sigma_a + sigma_s) is the same everywhere. Outside the box of a grid
/// `density` the medium is empty.
///
/// The extinction is the density times a spectrum, so the bound on it for the wavelengths λᵢ is
/// scale·max d·(sigma_a(λᵢ) + sigma_s(λᵢ)), and the one majorant of the trackers is its
/// largest value over the four, as for a chromatic homogeneous medium; the wavelengths whose
/// extinction is smaller meet null collisions in proportion. `volpathmis` takes that majorant
/// for all four too ([`Medium::majorants`]), as the ratio tracking of its shadow rays does.
#[derive(Clone, Debug)]
pub struct HeterogeneousAbsorbingScattering {
    pub density: Volume,
    pub sigma_a: Spectrum,
    pub sigma_s: Spectrum,
    pub scale: f32,
}

impl HeterogeneousAbsorbingScattering {
    /// scale·sigma_s(λᵢ) and scale·(sigma_a(λᵢ) + sigma_s(λᵢ)): the coefficients at density 1.
    #[inline]
    fn per_unit_density(&self, lambda: &SampledWavelengths) -> MediumCoefficients {
        let sigma_s = self.sigma_s.sample(lambda) * self.scale;
        MediumCoefficients {
            sigma_t: self.sigma_a.sample(lambda) * self.scale + sigma_s,
            sigma_s,
        }
    }
}

impl MediumModel for HeterogeneousAbsorbingScattering {
    #[inline]
    fn coefficients(&self, p: Vec3, lambda: &SampledWavelengths) -> MediumCoefficients {
        let unit = self.per_unit_density(lambda);
        let density = self.density.eval(p, lambda);
        MediumCoefficients {
            sigma_t: unit.sigma_t * density,
            sigma_s: unit.sigma_s * density,
        }
    }

    fn is_homogeneous(&self) -> bool {
        false
    }

    #[inline]
    fn majorant(&self, lambda: &SampledWavelengths) -> f32 {
        self.density.max_value() * self.per_unit_density(lambda).sigma_t.max_value()
    }

    fn ray_extent(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        self.density.ray_extent(ray, t_max)
    }
}

/// The media on the two sides of a surface (Mitsuba's `interior` and `exterior`): indices into
/// the world's media, `None` for vacuum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MediumInterface {
    pub interior: Option<u32>,
    pub exterior: Option<u32>,
}

impl MediumInterface {
    /// Whether crossing the surface changes the medium (it names one on either side).
    #[inline]
    pub fn is_transition(&self) -> bool {
        self.interior.is_some() || self.exterior.is_some()
    }

    /// The medium a ray leaving the surface in direction `d` enters, given the surface's
    /// geometric normal `n` (which points to the exterior).
    #[inline]
    pub fn target(&self, n: Vec3, d: Vec3) -> Option<u32> {
        if d.dot(n) > 0.0 {
            self.exterior
        } else {
            self.interior
        }
    }
}

/// A medium's coefficients at a point for a path's wavelengths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MediumCoefficients {
    pub sigma_t: SampledSpectrum,
    pub sigma_s: SampledSpectrum,
}

/// Which event a tentative collision turned out to be, and the factor it multiplies the
/// path throughput by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Collision {
    /// A real collision: the path scatters here.
    Real(SampledSpectrum),
    /// A null collision: the path flies on in the same direction.
    Null(SampledSpectrum),
}

impl Medium {
    /// The medium's coefficients at `p` for the wavelengths `lambda`, for light travelling
    /// along `d` (unit): the medium's own, times the phase function's projected area along
    /// `d` (1 unless the phase function is a microflake one, `sggx`).
    #[inline]
    pub fn coefficients(
        &self,
        p: Vec3,
        d: Vec3,
        lambda: &SampledWavelengths,
    ) -> MediumCoefficients {
        let c = self.kind.coefficients(p, lambda);
        let area = self.phase.projected_area(d);
        MediumCoefficients {
            sigma_t: c.sigma_t * area,
            sigma_s: c.sigma_s * area,
        }
    }

    /// Whether σ_t is the same everywhere (the albedo may still vary).
    #[inline]
    pub fn is_homogeneous(&self) -> bool {
        self.kind.is_homogeneous()
    }

    /// A majorant m ≥ σ_t(x, d, λᵢ) for every point along direction `d` (unit) and each of the
    /// wavelengths `lambda`: a homogeneous medium's largest σ_t(d, λᵢ) (tight), a heterogeneous
    /// one's bound times the largest projected area of its phase function.
    #[inline]
    pub fn majorant(&self, d: Vec3, lambda: &SampledWavelengths) -> f32 {
        if self.is_homogeneous() {
            self.coefficients(Vec3::ZERO, d, lambda).sigma_t.max_value()
        } else {
            self.kind.majorant(lambda) * self.phase.max_projected_area()
        }
    }

    /// Each wavelength's own majorant m(λᵢ) ≥ σ_t(x, d, λᵢ) for every point along direction
    /// `d` (unit): σ_t(d, λᵢ) itself for a homogeneous medium (which then has no null
    /// collisions), the bound of [`Self::majorant`] for all four in a heterogeneous one.
    #[inline]
    pub fn majorants(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        if self.is_homogeneous() {
            self.coefficients(Vec3::ZERO, d, lambda).sigma_t
        } else {
            SampledSpectrum::splat(self.majorant(d, lambda))
        }
    }

    /// The parameter interval of `ray` (unit direction) in which the medium may be non-empty,
    /// within [0, t_max].
    #[inline]
    pub fn ray_extent(&self, ray: &Ray, t_max: f32) -> Option<(f32, f32)> {
        self.kind.ray_extent(ray, t_max)
    }

    /// Transmittance along `ray` (unit direction) from t = 0 to `t_max`: exact for a
    /// homogeneous medium, estimated without bias by ratio tracking for a heterogeneous one,
    /// drawing uniform numbers from `u`.
    pub fn transmittance(
        &self,
        ray: &Ray,
        t_max: f32,
        lambda: &SampledWavelengths,
        mut u: impl FnMut() -> f32,
    ) -> SampledSpectrum {
        if self.is_homogeneous() {
            let sigma_t = self.coefficients(ray.o, ray.d, lambda).sigma_t;
            return SampledSpectrum::from_fn(|i| (-sigma_t[i] * t_max).exp());
        }
        let Some((t0, t1)) = self.ray_extent(ray, t_max) else {
            return SampledSpectrum::ONE;
        };
        let majorant = self.majorant(ray.d, lambda);
        let mut transmittance = SampledSpectrum::ONE;
        let mut t = t0;
        while let Some(next) = sample_free_flight(t, t1, majorant, u()) {
            t = next;
            let sigma_t = self.coefficients(ray.at(t), ray.d, lambda).sigma_t;
            transmittance *= SampledSpectrum::from_fn(|i| (1.0 - sigma_t[i] / majorant).max(0.0));
            if transmittance.is_black() {
                break;
            }
        }
        transmittance
    }
}

/// A tentative collision after `t_start` with the majorant `majorant`: t = t_start − ln(1 − u)/m,
/// density m·exp(−m (t − t_start)); `None` (probability exp(−m (t_end − t_start))) when it lies
/// at or beyond `t_end`.
#[inline]
pub fn sample_free_flight(t_start: f32, t_end: f32, majorant: f32, u: f32) -> Option<f32> {
    if !(majorant > 0.0) {
        return None;
    }
    let t = t_start - (1.0 - u).ln() / majorant;
    (t < t_end).then_some(t)
}

/// Spectral tracking's choice at a tentative collision (see the module's documentation): with
/// path throughput `throughput`, coefficients `c` and majorant `majorant`, a real collision
/// with probability P_real = Σ β σ_t / (m Σ β) and weight σ_s / (m P_real), else a null one
/// with weight σ_n / (m (1 − P_real)).
#[inline]
pub fn choose_collision(
    throughput: SampledSpectrum,
    c: &MediumCoefficients,
    majorant: f32,
    u: f32,
) -> Collision {
    let beta: f32 = throughput.0.iter().map(|b| b.abs()).sum();
    let real: f32 = (0..throughput.0.len())
        .map(|i| throughput[i].abs() * c.sigma_t[i])
        .sum();
    let p_real = if beta > 0.0 {
        (real / (beta * majorant)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    if u < p_real {
        Collision::Real(c.sigma_s * (1.0 / (majorant * p_real)))
    } else {
        let sigma_n = SampledSpectrum::from_fn(|i| (majorant - c.sigma_t[i]).max(0.0));
        Collision::Null(sigma_n * (1.0 / (majorant * (1.0 - p_real))))
    }
}
