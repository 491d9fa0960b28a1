//! Mitsuba 3's `sunsky` emitter: the Hosek–Wilkie sky dome and sun at infinity, spectral.
//!
//! ```xml
//! <emitter type="sunsky">
//!     <vector name="sun_direction" x="0.3" y="0.2" z="0.8"/>  <!-- or a place and time -->
//!     <float name="turbidity" value="3"/>   <!-- 1 … 10 -->
//!     <float name="albedo" value="0.3"/>    <!-- ground albedo, a spectrum in [0, 1] -->
//!     <float name="sun_scale" value="1"/>   <!-- 0 turns the sun off -->
//!     <float name="sky_scale" value="1"/>   <!-- 0 turns the sky off -->
//!     <float name="sun_aperture" value="0.5358"/>  <!-- the disc's full angle, degrees -->
//!     <boolean name="complex_sun" value="false"/>  <!-- limb darkening -->
//!     <transform name="to_world"> … </transform>   <!-- the frame is +z up -->
//! </emitter>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! The emitter's frame is +z up (+x north for the place-and-time form, whose sun position is
//! [`sun_position`]); `to_world` places it. Radiance is in W m⁻² sr⁻¹ nm⁻¹, the models of
//! [`model`] evaluated at the path's wavelengths. Below the horizon (z < 0) there is no light,
//! and when the sun is below the horizon the whole emitter is dark, as in Mitsuba.
//!
//! # Sampling
//! Prism's own scheme (Mitsuba fits truncated Gaussian mixtures; any density that covers the
//! radiance is unbiased): with probability w_sky = Φ_sky/(Φ_sky + Φ_sun), the ratio of the
//! sky's and the sun's luminous flux, a direction from a piecewise-constant density over
//! (φ/2π, cos θ) ∈ [0, 1)² of the upper hemisphere, each cell weighted by the sky's luminance
//! at its centre (dω = 2π du d(cos θ), so p_ω = p(u, v)/(2π)); otherwise a uniform direction
//! in the sun's cone. The density of a direction is the mixture of both.

pub mod data;
pub mod model;
pub mod sun_position;

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{BoundingSphere, DirectionSample, Environment, LightAtInfinity};
use crate::math::{Frame, Transform};
use crate::sampling::distribution::PiecewiseConstant2D;
use crate::spectrum::cie::cie_y;
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN, SampledSpectrum, SampledWavelengths};
use data::{BANDS, SunskyTables};
use model::{SUN_HALF_APERTURE, SkyModel, SunModel, band_wavelength, bands_around};

/// The sky-sampling table's resolution in φ and in cos θ.
const SAMPLING_PHI: usize = 128;
const SAMPLING_COS: usize = 64;

/// What a `sunsky` emitter is made of, as a scene gives it.
#[derive(Clone, Debug)]
pub struct SunskySettings {
    /// The sun's direction in the emitter's frame (+z up); need not be unit.
    pub sun: Vec3,
    /// Turbidity, in [1, 10].
    pub turbidity: f32,
    /// The ground albedo at each band's wavelength (320, 360, …, 720 nm), in [0, 1].
    pub albedo: [f32; BANDS],
    pub sun_scale: f32,
    pub sky_scale: f32,
    /// The sun disc's half-aperture in radians, in (0, π/2).
    pub sun_half_aperture: f32,
    /// The solar radiance function with limb darkening instead of a uniform disc.
    pub complex_sun: bool,
    /// Emitter-to-world transform.
    pub to_world: Transform,
}

#[derive(Clone, Debug)]
pub struct Sunsky {
    to_world: Transform,
    /// The sun's unit direction in the emitter's frame.
    sun: Vec3,
    sun_frame: Frame,
    sky: SkyModel,
    sun_model: SunModel,
    sky_scale: f32,
    sun_scale: f32,
    complex_sun: bool,
    /// The disc's half-aperture h: sin h, and 1 − cos h = 2 sin²(h/2), computed without
    /// cancellation (h is a few milliradians).
    sin_aperture: f32,
    one_minus_cos_aperture: f32,
    /// (1 − cos h₀)/(1 − cos h): keeps the sun's irradiance for any aperture.
    area_ratio: f32,
    /// Density of sky directions over (φ/2π, cos θ).
    distribution: PiecewiseConstant2D,
    /// Probability of sampling the sky rather than the sun.
    sky_weight: f32,
    /// ∫ Y(L) dω of the sky and of the sun (luminance, with the scales).
    sky_luminous: f64,
    sun_luminous: f64,
    /// The scene's bounding sphere (set when the scene is assembled).
    pub scene: BoundingSphere,
}

/// Per band c, the weight of its value in the luminance Y = ∫ L ȳ dλ / ∫ ȳ dλ of the
/// piecewise-linear spectrum through the bands (1 nm trapezoid rule over 360–830 nm, as
/// [`crate::spectrum::Spectrum::luminance`]; zero beyond 720 nm).
fn band_luminance_weights() -> [f64; BANDS] {
    let mut weights = [0.0; BANDS];
    let mut total = 0.0;
    let n = (LAMBDA_MAX - LAMBDA_MIN) as usize;
    for i in 0..=n {
        let lambda = LAMBDA_MIN + i as f32;
        let y = f64::from(cie_y(lambda)) * if i == 0 || i == n { 0.5 } else { 1.0 };
        total += y;
        if let Some((low, high, w)) = bands_around(lambda) {
            weights[low] += y * f64::from(1.0 - w);
            weights[high] += y * f64::from(w);
        }
    }
    weights.map(|w| w / total)
}

/// The angle between two unit vectors, accurate for small and large angles (2 asin of half
/// the chord).
fn unit_angle(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) >= 0.0 {
        2.0 * (0.5 * (a - b).length()).min(1.0).asin()
    } else {
        PI - 2.0 * (0.5 * (a + b).length()).min(1.0).asin()
    }
}

/// The direction of (u, v) = (φ/2π, cos θ) in the emitter's frame.
fn uv_to_direction(uv: Vec2) -> Vec3 {
    let cos_theta = uv.y;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (2.0 * PI * uv.x).sin_cos();
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// (φ/2π, cos θ) of a unit direction of the upper hemisphere, inside [0, 1)².
fn direction_to_uv(d: Vec3) -> Vec2 {
    let u = d.y.atan2(d.x) / (2.0 * PI);
    let u = if u < 0.0 { u + 1.0 } else { u };
    Vec2::new(
        if u < 1.0 { u } else { 0.0 },
        d.z.clamp(0.0, 1.0f32.next_down()),
    )
}

impl Sunsky {
    /// The emitter of `settings` (checked by the scene reader: values in range, sun direction
    /// non-zero and finite), with the embedded tables.
    pub fn new(settings: &SunskySettings) -> Sunsky {
        Sunsky::with_tables(settings, SunskyTables::embedded())
    }

    pub fn with_tables(settings: &SunskySettings, tables: &SunskyTables) -> Sunsky {
        let sun = settings.sun.normalize();
        // Mitsuba interpolates the tables at the elevation η = π/2 − θ_sun.
        let eta = f64::from(sun.z.clamp(-1.0, 1.0)).asin();
        let albedo = settings.albedo.map(f64::from);
        let turbidity = f64::from(settings.turbidity);
        let sky = SkyModel::new(tables, turbidity, &albedo, eta.max(0.0));
        let sun_model = SunModel::new(tables, turbidity, eta.max(0.0));
        let half = f64::from(settings.sun_half_aperture);
        let one_minus_cos = 2.0 * (0.5 * half).sin().powi(2);
        let one_minus_cos_real = 2.0 * (0.5 * SUN_HALF_APERTURE).sin().powi(2);
        let mut light = Sunsky {
            to_world: settings.to_world,
            sun,
            sun_frame: Frame::from_normal(sun),
            sky,
            sun_model,
            sky_scale: settings.sky_scale,
            sun_scale: settings.sun_scale,
            complex_sun: settings.complex_sun,
            sin_aperture: half.sin() as f32,
            one_minus_cos_aperture: one_minus_cos as f32,
            area_ratio: (one_minus_cos_real / one_minus_cos) as f32,
            distribution: PiecewiseConstant2D::new(&[1.0], 1, 1),
            sky_weight: 1.0,
            sky_luminous: 0.0,
            sun_luminous: 0.0,
            scene: BoundingSphere::default(),
        };
        light.build_sampling();
        light
    }

    /// The sky-sampling table, the luminous integrals of sky and sun and the choice between
    /// them.
    fn build_sampling(&mut self) {
        if self.sun.z < 0.0 {
            return;
        }
        let weights_y = band_luminance_weights();
        let luminance = |d: Vec3| -> f64 {
            let gamma = unit_angle(self.sun, d);
            let cos_gamma = self.sun.dot(d).clamp(-1.0, 1.0);
            (0..BANDS)
                .map(|c| weights_y[c] * f64::from(self.sky.band(c, d.z, gamma, cos_gamma)))
                .sum::<f64>()
                .max(0.0)
        };
        let mut cells: Vec<f64> = Vec::with_capacity(SAMPLING_PHI * SAMPLING_COS);
        for j in 0..SAMPLING_COS {
            for i in 0..SAMPLING_PHI {
                let uv = Vec2::new(
                    (i as f32 + 0.5) / SAMPLING_PHI as f32,
                    (j as f32 + 0.5) / SAMPLING_COS as f32,
                );
                cells.push(luminance(uv_to_direction(uv)));
            }
        }
        // A table of other data than Mitsuba's may overflow: such cells weigh nothing.
        let limit = f64::from(f32::MAX) / cells.len() as f64;
        for y in &mut cells {
            if !(*y <= limit) {
                *y = 0.0;
            }
        }
        let mean = cells.iter().sum::<f64>() / cells.len() as f64;
        // Every cell keeps a little density, so that no direction the sky lights is missed.
        let floor = 1e-3 * mean;
        let weights: Vec<f32> = cells.iter().map(|&y| y.max(floor) as f32).collect();
        self.distribution = PiecewiseConstant2D::new(&weights, SAMPLING_PHI, SAMPLING_COS);
        self.sky_luminous = f64::from(self.sky_scale) * 2.0 * std::f64::consts::PI * mean;
        let sun_y: f64 = (0..BANDS)
            .map(|c| weights_y[c] * f64::from(self.sun_model.disc_radiance[c]))
            .sum();
        let solid_angle = 2.0 * std::f64::consts::PI * f64::from(self.one_minus_cos_aperture);
        self.sun_luminous =
            f64::from(self.sun_scale) * sun_y * f64::from(self.area_ratio) * solid_angle;
        if !(self.sun_luminous.is_finite() && self.sun_luminous >= 0.0) {
            self.sun_luminous = 0.0;
        }
        let total = self.sky_luminous + self.sun_luminous;
        self.sky_weight = if total > 0.0 {
            (self.sky_luminous / total) as f32
        } else {
            1.0
        };
    }

    /// Whether the unit direction `d` (emitter frame) falls on the sun's disc: the chord to the
    /// sun's centre is at most 2 sin(h/2), i.e. |d − s|² ≤ 2(1 − cos h).
    #[inline]
    fn on_sun(&self, d: Vec3) -> bool {
        (d - self.sun).length_squared() <= 2.0 * self.one_minus_cos_aperture
    }

    /// The radiance arriving from the unit direction `d` of the emitter's frame.
    pub fn local_radiance(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        if !(d.z >= 0.0 && self.sun.z >= 0.0) {
            return SampledSpectrum::ZERO;
        }
        let cos_theta = d.z;
        let gamma = unit_angle(self.sun, d);
        let cos_gamma = self.sun.dot(d).clamp(-1.0, 1.0);
        let on_sun = self.sun_scale > 0.0 && self.on_sun(d);
        let (cos_psi, elevation) = if on_sun && self.complex_sun {
            let ratio = gamma.sin() / self.sin_aperture;
            (
                (1.0 - ratio * ratio).max(0.0).sqrt(),
                0.5 * PI - cos_theta.min(1.0).acos(),
            )
        } else {
            (0.0, 0.0)
        };
        SampledSpectrum::from_fn(|i| {
            let Some((low, high, w)) = bands_around(lambda.lambda(i)) else {
                return 0.0;
            };
            let lerp = |f: &dyn Fn(usize) -> f32| (1.0 - w) * f(low) + w * f(high);
            let mut value = 0.0;
            if self.sky_scale > 0.0 {
                value = self.sky_scale * lerp(&|c| self.sky.band(c, cos_theta, gamma, cos_gamma));
            }
            if on_sun {
                let sun = if self.complex_sun {
                    lerp(&|c| self.sun_model.radiance_function(c, elevation))
                        * self.sun_model.limb_darkening(low, high, w, cos_psi)
                } else {
                    lerp(&|c| self.sun_model.disc_radiance[c])
                };
                value += self.sun_scale * sun * self.area_ratio;
            }
            value
        })
    }

    /// The radiance seen by a ray leaving the scene in the unit direction `d` (world).
    pub fn radiance(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        let local = self.to_world.inverse_vector(d).normalize_or_zero();
        self.local_radiance(local, lambda)
    }

    /// Density per unit solid angle of [`Self::sample_incident`]'s direction `d` (world, unit).
    pub fn pdf(&self, d: Vec3) -> f32 {
        let local = self.to_world.inverse_vector(d).normalize_or_zero();
        self.local_pdf(local)
    }

    fn local_pdf(&self, d: Vec3) -> f32 {
        if !(d.z >= 0.0 && self.sun.z >= 0.0) || self.sky_luminous + self.sun_luminous <= 0.0 {
            return 0.0;
        }
        let sky = self.distribution.pdf(direction_to_uv(d)) / (2.0 * PI);
        let sun = if self.on_sun(d) {
            1.0 / (2.0 * PI * self.one_minus_cos_aperture)
        } else {
            0.0
        };
        self.sky_weight * sky + (1.0 - self.sky_weight) * sun
    }

    /// The sun's unit direction in the emitter's frame.
    pub fn sun_direction(&self) -> Vec3 {
        self.sun
    }

    /// The probability of sampling the sky rather than the sun.
    pub fn sky_weight(&self) -> f32 {
        self.sky_weight
    }

    /// The band wavelengths (nm) at which a scene's albedo is evaluated.
    pub fn band_wavelengths() -> [f32; BANDS] {
        std::array::from_fn(band_wavelength)
    }
}

impl LightAtInfinity for Sunsky {
    const IS_DELTA: bool = false;

    /// A direction towards the sky or the sun (see the module's documentation).
    fn sample_direction(&self, u: Vec2, lambda: &SampledWavelengths) -> Option<DirectionSample> {
        if !(self.sky_luminous + self.sun_luminous > 0.0) {
            return None;
        }
        let local = if u.x < self.sky_weight {
            let ux = (u.x / self.sky_weight).min(1.0f32.next_down());
            uv_to_direction(self.distribution.sample(Vec2::new(ux, u.y)))
        } else {
            let ux = ((u.x - self.sky_weight) / (1.0 - self.sky_weight)).min(1.0);
            // Uniform in the cone: 1 − cos θ uniform in [0, 1 − cos h].
            let one_minus_cos = ux * self.one_minus_cos_aperture;
            let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
            let (sin_phi, cos_phi) = (2.0 * PI * u.y).sin_cos();
            self.sun_frame.to_world(Vec3::new(
                sin_theta * cos_phi,
                sin_theta * sin_phi,
                1.0 - one_minus_cos,
            ))
        };
        let wi = self.to_world.vector(local).normalize();
        // The density and radiance of the direction as rounded, exactly what MIS evaluates
        // when BSDF sampling finds it.
        let local = self.to_world.inverse_vector(wi).normalize_or_zero();
        let pdf = self.local_pdf(local);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let radiance = self.local_radiance(local, lambda);
        Some(DirectionSample { wi, radiance, pdf })
    }

    fn environment(&self) -> Option<Environment<'_>> {
        Some(Environment::Sunsky(self))
    }

    /// Φ = π R² ∫ Y(L) dω, the luminous flux entering the scene's bounding sphere (as for
    /// [`super::EnvironmentMap::power`]): the sky's integral from the sampling table's cells
    /// and the sun's radiance times its solid angle.
    fn flux(&self) -> f32 {
        let integral = self.sky_luminous + self.sun_luminous;
        (std::f64::consts::PI * f64::from(self.scene.radius).powi(2) * integral) as f32
    }

    fn scene(&self) -> &BoundingSphere {
        &self.scene
    }

    fn scene_mut(&mut self) -> &mut BoundingSphere {
        &mut self.scene
    }
}
