//! Mitsuba 3's `hair` BSDF: the near-field hair model of Chiang et al. 2016 ("A Practical and
//! Controllable Hair and Fur Model for Production Path Tracing"), as Mitsuba 3's
//! `src/bsdfs/hair.cpp` and pbrt-v4's `HairBxDF` (Pharr et al. 2023, §9.9) write it.
//!
//! ```xml
//! <bsdf type="hair">
//!     <float name="eumelanin" value="1.3"/>            <!-- or sigma_a, not both -->
//!     <float name="pheomelanin" value="0.2"/>
//!     <float name="longitudinal_roughness" value="0.3"/>
//!     <float name="azimuthal_roughness" value="0.3"/>
//!     <float name="scale_tilt" value="2"/>              <!-- degrees -->
//!     <string name="int_ior" value="amber"/>
//! </bsdf>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! The fibre is a cylinder of unit radius along the local y axis (the curve's direction: the
//! shading frame's s runs around the fibre, as the curve shapes' ∂p/∂u), so that in the local
//! frame a direction w has the longitudinal angle θ with sin θ = w_y and the azimuth
//! φ = atan2(w_z, w_x). Where the path meets the fibre, the offset h = sin γ_o across it follows
//! from wo alone (γ_o is wo's angle to the normal within the cross section), as in Mitsuba: a
//! single interaction stands for the whole walk inside the fibre. Light leaves after p internal
//! segments, p = 0 (R), 1 (TT), 2 (TRT) and a last term for all longer paths:
//!
//!   f(wo, wi) |cos| = Σ_{p<3} M_p(θ_o′, θ_i) A_p N_p(φ_i − φ_o) + M_3(θ_o, θ_i) A_3 / (2π),
//!
//! where
//! * A_0 = F, A_1 = (1 − F)² T, A_2 = A_1 T F, A_3 = A_2 T F / (1 − T F), with F the Fresnel
//!   reflectance at cos θ_o cos γ_o and T = exp(−σ_a 2 cos γ_t / cos θ_t) the transmittance of
//!   one crossing (Snell's law in the longitudinal plane, and across the section with the
//!   modified index η′ = √(η² − sin²θ_o) / cos θ_o, sin γ_t = h / η′);
//! * M_p is d'Eon et al.'s longitudinal lobe (2011, "An Energy-Conserving Hair Reflectance
//!   Model", with the robust large-κ form of Jakob's notes; I₀ and its logarithm more precise
//!   than Mitsuba's, below) of variance v_p, around θ_o′, θ_o rotated by the scales'
//!   tilt α (−2α for R, α for TT, 4α for TRT);
//! * N_p is a logistic of scale s trimmed to [−π, π] around the specular offset
//!   Φ = 2pγ_t − 2γ_o + pπ.
//!
//! The roughnesses β_m and β_n map to v_0 = (0.726β_m + 0.812β_m² + 3.7β_m²⁰)², v_1 = v_0/4,
//! v_2 = v_3 = 4v_0 and s = √(π/8) (0.265β_n + 1.194β_n² + 5.372β_n²²). With σ_a = 0 the terms
//! sum to 1: the fibre loses no energy.
//!
//! σ_a (per unit of the fibre's radius) is given directly or from the concentrations of the two
//! melanins, c_e σ_e + c_p σ_p with d'Eon et al.'s σ_e = (0.419, 0.697, 1.37) and
//! σ_p = (0.187, 0.4, 1.05) as linear sRGB, upsampled as Mitsuba 3's spectral variants do (each
//! clamped to [0, 1] and turned into a reflectance spectrum).
//!
//! Sampling chooses p in proportion to the luminance of A_p, then θ_i from M_p (d'Eon et al.'s
//! inversion) and φ_i from N_p (uniformly for the last term); the density is that of the whole
//! mixture.

use std::f32::consts::{PI, TAU};
use std::sync::OnceLock;

use glam::{Vec2, Vec3};

use super::fresnel::fresnel_dielectric;
use super::{BsdfEval, BsdfFlags, BsdfSample, Bxdf, BxdfTree, LeafBsdf, mixture_sample};
use crate::spectrum::cie::cie_y;
use crate::spectrum::rgb::{RgbSigmoidPolynomial, RgbToSpectrumTable};
use crate::spectrum::{N_SPECTRUM_SAMPLES, SampledSpectrum, SampledWavelengths};
use crate::texture::{Texture, TexturePoint, TextureValues};

/// Internal path lengths modelled one by one (R, TT, TRT); longer ones form one more term.
const P_MAX: usize = 3;

/// Absorption of eumelanin and pheomelanin per unit concentration and fibre radius, as linear
/// sRGB (d'Eon et al. 2011).
const EUMELANIN_SIGMA_A: [f32; 3] = [0.419, 0.697, 1.37];
const PHEOMELANIN_SIGMA_A: [f32; 3] = [0.187, 0.4, 1.05];

/// Where the fibre's absorption comes from.
#[derive(Clone, Debug)]
pub enum HairAbsorption {
    /// The concentrations of eumelanin and pheomelanin.
    Pigments { eumelanin: f32, pheomelanin: f32 },
    /// σ_a given directly (a spectrum or texture), times `scale`.
    Coefficient { sigma_a: Texture, scale: f32 },
}

#[derive(Clone, Debug)]
pub struct Hair {
    pub absorption: HairAbsorption,
    /// The fibre's index relative to the outside, η_int/η_ext.
    pub eta: f32,
    pub lobes: HairLobeShapes,
}

/// The widths and tilts of the lobes, fixed by the roughnesses and the scales' angle.
#[derive(Clone, Copy, Debug)]
pub struct HairLobeShapes {
    /// Longitudinal variance of each term.
    v: [f32; P_MAX + 1],
    /// Scale of the azimuthal logistic.
    s: f32,
    /// sin and cos of α, 2α and 4α.
    sin_2k_alpha: [f32; 3],
    cos_2k_alpha: [f32; 3],
}

impl HairLobeShapes {
    /// The lobes for the longitudinal roughness β_m and azimuthal roughness β_n (both in
    /// (0, 1]) and scales tilted by `scale_tilt_degrees`.
    pub fn new(
        longitudinal_roughness: f32,
        azimuthal_roughness: f32,
        scale_tilt_degrees: f32,
    ) -> HairLobeShapes {
        let bm = longitudinal_roughness;
        let v0 = (0.726 * bm + 0.812 * bm * bm + 3.7 * bm.powi(20)).powi(2);
        let bn = azimuthal_roughness;
        let s = (PI / 8.0).sqrt() * (0.265 * bn + 1.194 * bn * bn + 5.372 * bn.powi(22));
        let mut sin_2k_alpha = [scale_tilt_degrees.to_radians().sin(), 0.0, 0.0];
        let mut cos_2k_alpha = [(1.0 - sin_2k_alpha[0].powi(2)).max(0.0).sqrt(), 0.0, 0.0];
        for i in 1..3 {
            sin_2k_alpha[i] = 2.0 * cos_2k_alpha[i - 1] * sin_2k_alpha[i - 1];
            cos_2k_alpha[i] = cos_2k_alpha[i - 1].powi(2) - sin_2k_alpha[i - 1].powi(2);
        }
        HairLobeShapes {
            v: [v0, 0.25 * v0, 4.0 * v0, 4.0 * v0],
            s,
            sin_2k_alpha,
            cos_2k_alpha,
        }
    }

    /// (sin θ, |cos θ|) of wo's longitudinal angle tilted for term `p` by the scales.
    #[inline]
    fn tilted(&self, sin_theta: f32, cos_theta: f32, p: usize) -> (f32, f32) {
        let (s, c) = (self.sin_2k_alpha, self.cos_2k_alpha);
        let (sin_p, cos_p) = match p {
            0 => (
                sin_theta * c[1] - cos_theta * s[1],
                cos_theta * c[1] + sin_theta * s[1],
            ),
            1 => (
                sin_theta * c[0] + cos_theta * s[0],
                cos_theta * c[0] - sin_theta * s[0],
            ),
            2 => (
                sin_theta * c[2] + cos_theta * s[2],
                cos_theta * c[2] - sin_theta * s[2],
            ),
            _ => (sin_theta, cos_theta),
        };
        (sin_p, cos_p.abs())
    }

    /// The azimuthal lobe N_p at Δφ: the trimmed logistic around the specular offset.
    #[inline]
    fn azimuthal(&self, delta_phi: f32, p: usize, gamma_o: f32, gamma_t: f32) -> f32 {
        let offset = delta_phi - specular_offset(p, gamma_o, gamma_t);
        let phi = offset - TAU * (offset / TAU).round();
        logistic(phi, self.s) / trimmed_logistic_mass(self.s)
    }
}

/// Φ = 2pγ_t − 2γ_o + pπ, the azimuthal offset of term `p` for a smooth fibre.
#[inline]
fn specular_offset(p: usize, gamma_o: f32, gamma_t: f32) -> f32 {
    let p = p as f32;
    2.0 * p * gamma_t - 2.0 * gamma_o + p * PI
}

/// The logistic density of scale s at x.
#[inline]
fn logistic(x: f32, s: f32) -> f32 {
    let e = (-x.abs() / s).exp();
    e / (s * (1.0 + e) * (1.0 + e))
}

#[inline]
fn logistic_cdf(x: f32, s: f32) -> f32 {
    1.0 / (1.0 + (-x / s).exp())
}

/// The logistic's mass on [−π, π].
#[inline]
fn trimmed_logistic_mass(s: f32) -> f32 {
    logistic_cdf(PI, s) - logistic_cdf(-PI, s)
}

/// Inverts the CDF of the logistic trimmed to [−π, π].
#[inline]
fn sample_trimmed_logistic(u: f32, s: f32) -> f32 {
    let k = trimmed_logistic_mass(s);
    let x = -s * (1.0 / (u * k + logistic_cdf(-PI, s)) - 1.0).ln();
    x.clamp(-PI, PI)
}

/// The modified Bessel function I₀(x) = Σ_k (x²/4)^k / (k!)², summed until the terms no longer
/// matter (for the x ≤ 12 it is used at, at most 30 terms). Mitsuba and pbrt-v4 stop after ten,
/// which loses up to 0.5 % near x = 12, so that the lobe no longer integrates to 1 and its
/// value drifts from the density its sampling follows.
fn bessel_i0(x: f32) -> f32 {
    let quarter_x2 = f64::from(x) * f64::from(x) / 4.0;
    let (mut sum, mut term) = (1.0f64, 1.0f64);
    for k in 1..=30 {
        let k = f64::from(k);
        term *= quarter_x2 / (k * k);
        sum += term;
        if term < 1e-9 * sum {
            break;
        }
    }
    sum as f32
}

/// ln I₀(x); above 12 by the asymptotic expansion I₀(x) ≈ eˣ/√(2πx) (1 + 1/(8x) + 9/(128x²)),
/// whose logarithm is x − ln(2πx)/2 + 1/(8x) + 1/(16x²). Mitsuba and pbrt-v4 write 1/(16x)
/// for the last two terms, 0.5 % too small at x = 12, which again drifts the lobe from its
/// sampling.
fn log_bessel_i0(x: f32) -> f32 {
    if x > 12.0 {
        x - 0.5 * (TAU * x).ln() + 1.0 / (8.0 * x) + 1.0 / (16.0 * x * x)
    } else {
        bessel_i0(x).ln()
    }
}

/// d'Eon et al.'s longitudinal lobe of variance v between the directions of sines `sin_a`,
/// `sin_b` along the fibre, divided by 2π (Mitsuba's `square_to_rough_fiber_pdf`, κ = 1/v):
///
///   M = κ / (2 sinh κ) · exp(−κ sin θ_a sin θ_b) · I₀(κ cos θ_a cos θ_b) / (2π),
///
/// for κ > 10 as exp(ln I₀ − κ sin θ_a sin θ_b − κ + ln κ), where 2 sinh κ = e^κ to float
/// precision and I₀ alone would overflow.
#[inline]
fn longitudinal(sin_a: f32, sin_b: f32, v: f32) -> f32 {
    let kappa = 1.0 / v;
    let cos_a = (1.0 - sin_a * sin_a).max(0.0).sqrt();
    let cos_b = (1.0 - sin_b * sin_b).max(0.0).sqrt();
    let c = cos_a * cos_b * kappa;
    let s = sin_a * sin_b * kappa;
    let m = if kappa > 10.0 {
        (-s + log_bessel_i0(c) - kappa + kappa.ln()).exp()
    } else {
        (-s).exp() * bessel_i0(c) * kappa / (2.0 * kappa.sinh())
    };
    m / TAU
}

/// γ, the angle between the normal and w projected on the fibre's cross section, signed as
/// Mitsuba's (positive where w_x < 0).
#[inline]
fn gamma(w: Vec3) -> f32 {
    let projected = (w.x * w.x + w.z * w.z).sqrt();
    if projected == 0.0 {
        return 0.0;
    }
    let gamma = (w.z / projected).clamp(-1.0, 1.0).acos();
    if w.x < 0.0 { gamma } else { -gamma }
}

/// The linear sRGB σ of a pigment, upsampled as a reflectance (Mitsuba's `srgb_model_fetch`).
fn pigment(index: usize) -> &'static RgbSigmoidPolynomial {
    static PIGMENTS: OnceLock<[RgbSigmoidPolynomial; 2]> = OnceLock::new();
    &PIGMENTS.get_or_init(|| {
        let table = RgbToSpectrumTable::srgb();
        [
            table.fetch(EUMELANIN_SIGMA_A),
            table.fetch(PHEOMELANIN_SIGMA_A),
        ]
    })[index]
}

impl LeafBsdf for Hair {
    type Lobes<'a> = HairLobes<'a>;
    const FLAGS: BsdfFlags = BsdfFlags::GLOSSY
        .union(BsdfFlags::REFLECTION)
        .union(BsdfFlags::TRANSMISSION);

    fn lobes<'a>(&'a self, at: TexturePoint, lambda: &SampledWavelengths) -> HairLobes<'a> {
        let sigma_a = match &self.absorption {
            HairAbsorption::Pigments {
                eumelanin,
                pheomelanin,
            } => SampledSpectrum::from_fn(|i| {
                let l = lambda.lambda(i);
                eumelanin * pigment(0).eval(l) + pheomelanin * pigment(1).eval(l)
            }),
            HairAbsorption::Coefficient { sigma_a, scale } => *scale * sigma_a.eval(at, lambda),
        };
        HairLobes {
            shapes: &self.lobes,
            eta: self.eta,
            sigma_a,
            luminance: std::array::from_fn(|i| cie_y(lambda.lambda(i))),
        }
    }
}

/// The fibre's scattering at a point.
#[derive(Clone, Copy, Debug)]
pub struct HairLobes<'a> {
    shapes: &'a HairLobeShapes,
    eta: f32,
    sigma_a: SampledSpectrum,
    /// ȳ at the path's wavelengths, to choose a term by the luminance of its attenuation.
    luminance: [f32; N_SPECTRUM_SAMPLES],
}

/// What the terms share for one wo: its angles and the attenuation of each term.
struct Entry {
    sin_theta_o: f32,
    cos_theta_o: f32,
    phi_o: f32,
    gamma_o: f32,
    gamma_t: f32,
    attenuation: [SampledSpectrum; P_MAX + 1],
    /// The probability of choosing each term: its share of the luminance of the attenuations.
    choice: [f32; P_MAX + 1],
}

impl HairLobes<'_> {
    /// The geometry and attenuations of the walk inside the fibre that starts from wo; `None`
    /// where wo runs along the fibre or nothing leaves it.
    fn entry(&self, wo: Vec3) -> Option<Entry> {
        let sin_theta_o = wo.y;
        let cos_theta_o = (1.0 - sin_theta_o * sin_theta_o).max(0.0).sqrt();
        if !(cos_theta_o > 0.0) {
            return None;
        }
        let gamma_o = gamma(wo);
        let h = gamma_o.sin();
        let eta = self.eta;
        let sin_theta_t = sin_theta_o / eta;
        let cos_theta_t = (1.0 - sin_theta_t * sin_theta_t).max(0.0).sqrt();
        let eta_p = (eta * eta - sin_theta_o * sin_theta_o).max(0.0).sqrt() / cos_theta_o;
        let sin_gamma_t = h / eta_p;
        let cos_gamma_t = (1.0 - sin_gamma_t * sin_gamma_t).max(0.0).sqrt();
        let gamma_t = sin_gamma_t.clamp(-1.0, 1.0).asin();
        let length = 2.0 * cos_gamma_t / cos_theta_t;
        let t = SampledSpectrum::from_fn(|i| (-self.sigma_a[i] * length).exp());

        let cos_gamma_o = (1.0 - h * h).max(0.0).sqrt();
        let f = fresnel_dielectric(cos_theta_o * cos_gamma_o, eta).reflectance;
        let mut attenuation = [SampledSpectrum::ZERO; P_MAX + 1];
        attenuation[0] = SampledSpectrum::splat(f);
        attenuation[1] = t * ((1.0 - f) * (1.0 - f));
        for p in 2..P_MAX {
            attenuation[p] = attenuation[p - 1] * t * f;
        }
        attenuation[P_MAX] =
            SampledSpectrum::from_fn(|i| attenuation[P_MAX - 1][i] * f * t[i] / (1.0 - t[i] * f));

        let luminance = attenuation.map(|a| {
            (0..N_SPECTRUM_SAMPLES)
                .map(|i| a[i] * self.luminance[i])
                .sum::<f32>()
        });
        let total: f32 = luminance.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        Some(Entry {
            sin_theta_o,
            cos_theta_o,
            phi_o: wo.z.atan2(wo.x),
            gamma_o,
            gamma_t,
            attenuation,
            choice: luminance.map(|l| l / total),
        })
    }
}

impl Bxdf for HairLobes<'_> {
    fn eval(&self, _tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let Some(e) = self.entry(wo) else {
            return BsdfEval::ZERO;
        };
        let shapes = self.shapes;
        let delta_phi = wi.z.atan2(wi.x) - e.phi_o;
        let (mut value, mut pdf) = (SampledSpectrum::ZERO, 0.0f32);
        for p in 0..P_MAX {
            let (sin_tilted, _) = shapes.tilted(e.sin_theta_o, e.cos_theta_o, p);
            let lobe = longitudinal(sin_tilted, wi.y, shapes.v[p])
                * TAU
                * shapes.azimuthal(delta_phi, p, e.gamma_o, e.gamma_t);
            value += e.attenuation[p] * lobe;
            pdf += e.choice[p] * lobe;
        }
        let rest = longitudinal(e.sin_theta_o, wi.y, shapes.v[P_MAX]);
        value += e.attenuation[P_MAX] * rest;
        pdf += e.choice[P_MAX] * rest;
        if !(value.is_finite() && pdf.is_finite()) {
            return BsdfEval::ZERO;
        }
        BsdfEval { value, pdf }
    }

    fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let e = self.entry(wo)?;
        let shapes = self.shapes;
        // The term, and u_lobe rescaled to reuse for the azimuth.
        let mut p = 0;
        let mut rest = u_lobe;
        while p < P_MAX && rest > e.choice[p] {
            rest -= e.choice[p];
            p += 1;
        }
        let u_phi = (rest / e.choice[p]).clamp(0.0, 1.0);

        let (sin_tilted, cos_tilted) = shapes.tilted(e.sin_theta_o, e.cos_theta_o, p);
        let v = shapes.v[p];
        let cos_theta = (1.0 + v * (u.x + (1.0 - u.x) * (-2.0 / v).exp()).ln()).clamp(-1.0, 1.0);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let sin_theta_i = -cos_theta * sin_tilted + sin_theta * (TAU * u.y).cos() * cos_tilted;
        let cos_theta_i = (1.0 - sin_theta_i * sin_theta_i).max(0.0).sqrt();

        let delta_phi = if p < P_MAX {
            specular_offset(p, e.gamma_o, e.gamma_t) + sample_trimmed_logistic(u_phi, shapes.s)
        } else {
            TAU * u_phi
        };
        let (sin_phi, cos_phi) = (e.phi_o + delta_phi).sin_cos();
        let wi = Vec3::new(cos_theta_i * cos_phi, sin_theta_i, cos_theta_i * sin_phi).normalize();
        let BsdfEval { value, pdf } = self.eval(tree, wo, wi);
        let side = if wi.z * wo.z > 0.0 {
            BsdfFlags::REFLECTION
        } else {
            BsdfFlags::TRANSMISSION
        };
        mixture_sample(wi, value, pdf, BsdfFlags::GLOSSY.union(side))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The longitudinal lobe is a density over the sphere once multiplied by 2π: ∫ M cos θ dθ
    /// over [−π/2, π/2] is 1/(2π), in both of its forms and across the switch between the
    /// series and the expansion of I₀ (κ cos θ_a cos θ_b crosses 12).
    #[test]
    fn longitudinal_lobe_is_normalised() {
        for (v, sin_o) in [
            (0.5, 0.3),
            (0.085, 0.2),
            (0.05, -0.6),
            (0.021, 0.2),
            (0.01, 0.1),
        ] {
            let n = 20_000;
            let integral: f64 = (0..n)
                .map(|i| {
                    let theta = -PI / 2.0 + (i as f32 + 0.5) * PI / n as f32;
                    f64::from(longitudinal(sin_o, theta.sin(), v) * theta.cos())
                        * f64::from(PI / n as f32)
                })
                .sum();
            assert!(
                (integral * std::f64::consts::TAU - 1.0).abs() < 2e-4,
                "v = {v}: {integral}"
            );
        }
    }

    /// The trimmed logistic integrates to 1 over [−π, π], and its sampling inverts its CDF.
    #[test]
    fn trimmed_logistic() {
        let s = 0.4;
        let n = 20_000;
        let integral: f32 = (0..n)
            .map(|i| logistic(-PI + (i as f32 + 0.5) * TAU / n as f32, s) * TAU / n as f32)
            .sum();
        assert!((integral / trimmed_logistic_mass(s) - 1.0).abs() < 1e-3);
        let x = sample_trimmed_logistic(0.75, s);
        let cdf = (logistic_cdf(x, s) - logistic_cdf(-PI, s)) / trimmed_logistic_mass(s);
        assert!((cdf - 0.75).abs() < 1e-4, "{cdf}");
    }
}
