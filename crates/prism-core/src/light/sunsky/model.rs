//! The Hosek–Wilkie sky and sun, as Mitsuba 3's spectral `sunsky` evaluates them.
//!
//! * Sky: Hosek & Wilkie 2012, "An Analytic Model for Full Spectral Sky-Dome Radiance"
//!   (ACM TOG 31(4)), eq. 9: for a view at zenith angle θ and angle γ from the sun,
//!   L = (1 + A e^{B/(cos θ + 0.01)}) · (C + D e^{Eγ} + F cos²γ + G χ(I, γ) + H √cos θ) · L_M,
//!   with χ(I, γ) = (1 + cos²γ) / (1 + I² − 2 I cos γ)^{3/2}. The nine coefficients and the mean
//!   radiance L_M of each of the 11 bands (320–720 nm every 40 nm) are interpolated linearly in
//!   turbidity (1 … 10) and ground albedo (0, 1), then along a quintic Bézier curve in
//!   x = (2η/π)^{1/3} of the sun's elevation η over 6 control points (§5 of the paper).
//! * Sun: Hosek & Wilkie 2013, "Adding a Solar-Radiance Function to the Hosek-Wilkie Skylight
//!   Model" (IEEE CG&A 33(3)). By default (Mitsuba's `complex_sun = false`) a uniform disc whose
//!   radiance is the tabulated solar irradiance at the sun's elevation divided by the disc's
//!   solid angle; with `complex_sun`, the paper's piecewise-cubic radiance in the view's
//!   elevation (45 segments in (2e/π)^{1/3}) times its limb-darkening polynomial in cos ψ, the
//!   cosine of the angle from the disc's rim. Either way the radiance is rescaled by
//!   (1 − cos h₀)/(1 − cos h) when the disc's half-aperture h differs from the real sun's h₀,
//!   so the sun's irradiance stays the same.
//!
//! Between bands, the radiance is interpolated linearly; outside 320–720 nm it is zero (as in
//! Mitsuba).

use std::f64::consts::PI;

use super::data::{
    ALBEDOS, BAND_STEP, BANDS, FIRST_BAND, IRRADIANCE_ELEVATIONS, SKY_CONTROL_POINTS, SKY_PARAMS,
    SUN_CONTROL_POINTS, SUN_LD_PARAMS, SUN_SEGMENTS, SunskyTables, TURBIDITIES,
};

/// The real sun's half-aperture h₀: half of 0.5358°, in radians (Mitsuba's
/// `SUN_HALF_APERTURE`).
pub const SUN_HALF_APERTURE: f64 = PI * (0.5 * 0.5358) / 180.0;

/// The wavelength of band `c`, in nm.
pub fn band_wavelength(c: usize) -> f32 {
    FIRST_BAND + BAND_STEP * c as f32
}

/// The two bands around `lambda` and the weight of the upper one; `None` outside 320–720 nm.
#[inline]
pub fn bands_around(lambda: f32) -> Option<(usize, usize, f32)> {
    let t = (lambda - FIRST_BAND) / BAND_STEP;
    if !(t >= 0.0 && t <= (BANDS - 1) as f32) {
        return None;
    }
    let low = (t as usize).min(BANDS - 1);
    let high = (low + 1).min(BANDS - 1);
    Some((low, high, t - low as f32))
}

/// Linear interpolation between the turbidity levels around `turbidity` ∈ [1, 10]: the lower
/// level's index and the weight of the next one (which exists whenever the weight is not 0).
fn turbidity_levels(turbidity: f64) -> (usize, f64) {
    let t = (turbidity - 1.0).clamp(0.0, (TURBIDITIES - 1) as f64);
    let low = (t as usize).min(TURBIDITIES - 2);
    (low, t - low as f64)
}

/// The sky of one sun position, turbidity and albedo: per band, the nine coefficients A … I
/// and the mean radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyModel {
    pub params: [[f32; SKY_PARAMS]; BANDS],
    pub radiance: [f32; BANDS],
}

/// The sun of one turbidity and sun elevation, per band.
#[derive(Clone, Debug, PartialEq)]
pub struct SunModel {
    /// The uniform disc's radiance for the real sun's aperture (irradiance / solid angle).
    pub disc_radiance: [f32; BANDS],
    /// The solar radiance polynomials of the turbidity: (segment, band, power).
    pub polynomials: Vec<[[f32; SUN_CONTROL_POINTS]; BANDS]>,
    /// Limb darkening (band, power).
    pub limb_darkening: [[f32; SUN_LD_PARAMS]; BANDS],
}

/// The quintic Bézier weights of the 6 control points at the sun elevation `eta` (radians):
/// C(5, k) x^k (1 − x)^{5−k} with x = (2η/π)^{1/3}, x kept below 1 as Mitsuba keeps it.
fn bezier_weights(eta: f64) -> [f64; SKY_CONTROL_POINTS] {
    let x = (2.0 * eta / PI)
        .max(0.0)
        .cbrt()
        .min(1.0 - f64::from(f32::EPSILON) / 2.0);
    const BINOMIAL: [f64; SKY_CONTROL_POINTS] = [1.0, 5.0, 10.0, 10.0, 5.0, 1.0];
    std::array::from_fn(|k| {
        BINOMIAL[k] * x.powi(k as i32) * (1.0 - x).powi((SKY_CONTROL_POINTS - 1 - k) as i32)
    })
}

impl SkyModel {
    /// The sky for `turbidity` ∈ [1, 10], the ground albedo of each band (in [0, 1]) and the
    /// sun's elevation `eta` (radians, ≥ 0).
    pub fn new(tables: &SunskyTables, turbidity: f64, albedo: &[f64; BANDS], eta: f64) -> SkyModel {
        let (t0, tw) = turbidity_levels(turbidity);
        let bezier = bezier_weights(eta);
        // (turbidity, albedo, control point, band, parameter) with `per` parameters.
        let value = |table: &[f64], per: usize, c: usize, p: usize| -> f64 {
            let at = |t: usize, a: usize, k: usize| {
                table[(((t * ALBEDOS + a) * SKY_CONTROL_POINTS + k) * BANDS + c) * per + p]
            };
            (0..SKY_CONTROL_POINTS)
                .map(|k| {
                    let by_albedo = |a: usize| (1.0 - tw) * at(t0, a, k) + tw * at(t0 + 1, a, k);
                    let v = (1.0 - albedo[c]) * by_albedo(0) + albedo[c] * by_albedo(1);
                    bezier[k] * v
                })
                .sum()
        };
        SkyModel {
            params: std::array::from_fn(|c| {
                std::array::from_fn(|p| value(&tables.sky_params, SKY_PARAMS, c, p) as f32)
            }),
            radiance: std::array::from_fn(|c| value(&tables.sky_radiance, 1, c, 0) as f32),
        }
    }

    /// The radiance of band `c` at zenith-angle cosine `cos_theta` (≥ 0) and angle `gamma`
    /// from the sun (eq. 9 of the 2012 paper, with Mitsuba's order of the coefficients: G
    /// weighs χ, H the √cos θ term, I is χ's parameter).
    #[inline]
    pub fn band(&self, c: usize, cos_theta: f32, gamma: f32, cos_gamma: f32) -> f32 {
        let [a, b, cc, d, e, f, g, h, i] = self.params[c];
        let cos2 = cos_gamma * cos_gamma;
        let c1 = 1.0 + a * (b / (cos_theta + 0.01)).exp();
        let chi = (1.0 + cos2) / (1.0 + i * i - 2.0 * i * cos_gamma).powf(1.5);
        let c2 = cc + d * (e * gamma).exp() + f * cos2 + g * chi + h * cos_theta.max(0.0).sqrt();
        c1 * c2 * self.radiance[c]
    }
}

impl SunModel {
    /// The sun for `turbidity` ∈ [1, 10] at elevation `eta` (radians).
    pub fn new(tables: &SunskyTables, turbidity: f64, eta: f64) -> SunModel {
        let (t0, tw) = turbidity_levels(turbidity);
        // The irradiance table's elevations are 2°, 5°, …, 89°.
        let e = ((eta.to_degrees() - 2.0) / 3.0).clamp(0.0, (IRRADIANCE_ELEVATIONS - 1) as f64);
        let e0 = (e as usize).min(IRRADIANCE_ELEVATIONS - 2);
        let ew = e - e0 as f64;
        let irradiance = |t: usize, e: usize, c: usize| {
            tables.sun_irradiance[(t * IRRADIANCE_ELEVATIONS + e) * BANDS + c]
        };
        let real_solid_angle = 2.0 * PI * (1.0 - SUN_HALF_APERTURE.cos());
        let disc_radiance = std::array::from_fn(|c| {
            let at = |e: usize| (1.0 - tw) * irradiance(t0, e, c) + tw * irradiance(t0 + 1, e, c);
            (((1.0 - ew) * at(e0) + ew * at(e0 + 1)) / real_solid_angle) as f32
        });
        let polynomial = |t: usize, s: usize, c: usize, k: usize| {
            tables.sun_radiance[((t * SUN_SEGMENTS + s) * BANDS + c) * SUN_CONTROL_POINTS + k]
        };
        let polynomials = (0..SUN_SEGMENTS)
            .map(|s| {
                std::array::from_fn(|c| {
                    std::array::from_fn(|k| {
                        ((1.0 - tw) * polynomial(t0, s, c, k) + tw * polynomial(t0 + 1, s, c, k))
                            as f32
                    })
                })
            })
            .collect();
        let limb_darkening = std::array::from_fn(|c| {
            std::array::from_fn(|j| tables.sun_limb_darkening[c * SUN_LD_PARAMS + j] as f32)
        });
        SunModel {
            disc_radiance,
            polynomials,
            limb_darkening,
        }
    }

    /// The 2013 paper's solar radiance of band `c` seen at elevation `elevation` (radians),
    /// before limb darkening.
    pub fn radiance_function(&self, c: usize, elevation: f32) -> f32 {
        let elevation = elevation.max(0.0);
        let segments = SUN_SEGMENTS as f32;
        let position = (((2.0 * elevation / std::f32::consts::PI).cbrt() * segments) as usize)
            .min(SUN_SEGMENTS - 1);
        let start = 0.5 * std::f32::consts::PI * (position as f32 / segments).powi(3);
        let x = elevation - start;
        let coefficients = &self.polynomials[position][c];
        let mut power = 1.0;
        let mut sum = 0.0;
        for k in coefficients {
            sum += k * power;
            power *= x;
        }
        sum
    }

    /// Limb darkening at `cos_psi` for the wavelength between bands `low` and `high` with
    /// weight `w` (the coefficients interpolated, then the polynomial evaluated).
    pub fn limb_darkening(&self, low: usize, high: usize, w: f32, cos_psi: f32) -> f32 {
        let mut power = 1.0;
        let mut sum = 0.0;
        for j in 0..SUN_LD_PARAMS {
            let coefficient =
                (1.0 - w) * self.limb_darkening[low][j] + w * self.limb_darkening[high][j];
            sum += coefficient * power;
            power *= cos_psi;
        }
        sum
    }
}
