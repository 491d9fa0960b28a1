//! The building blocks of Burley's "principled" BSDFs (Burley 2012, "Physically Based Shading at
//! Disney"; Burley 2015, "Extending the Disney BRDF to a BSDF with Integrated Subsurface
//! Scattering") as Mitsuba 3 defines them (`principledhelpers.h`): Schlick's Fresnel
//! approximation, the GTR1 distribution of the clearcoat, its GGX masking term, and the mapping
//! from `roughness` and `anisotropic` to α.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::spectrum::{SampledSpectrum, SampledWavelengths, cie::cie_y};
use crate::texture::TextureValues;
use crate::texture::{Texture, TexturePoint};

/// An optional parameter's value at a point (absent: the lobe it scales is off).
#[inline]
pub fn optional_value(texture: &Option<Texture>, at: TexturePoint) -> Option<f32> {
    texture.as_ref().map(|t| t.eval_1(at))
}

/// Schlick's weight (1 − cos θ)⁵ (Schlick 1994), with 1 − cos θ clamped to [0, 1].
#[inline]
pub fn schlick_weight(cos_theta: f32) -> f32 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's approximation F ≈ R₀ + (1 − R₀)(1 − cos θ)⁵ at an interface of relative index
/// `eta`, seen at the signed cosine `cos_theta_i`; from the denser side the transmitted angle's
/// cosine is used (Mitsuba's `calc_schlick`).
#[inline]
pub fn schlick_fresnel(r0: f32, cos_theta_i: f32, eta: f32) -> f32 {
    let eta_it = if cos_theta_i >= 0.0 { eta } else { 1.0 / eta };
    let cos = if eta_it > 1.0 {
        cos_theta_i.abs()
    } else {
        let eta_ti = 1.0 / eta_it;
        (1.0 - (1.0 - cos_theta_i * cos_theta_i) * eta_ti * eta_ti)
            .max(0.0)
            .sqrt()
    };
    r0 + (1.0 - r0) * schlick_weight(cos)
}

/// The reflectance at normal incidence of an interface of relative index η: ((η − 1)/(η + 1))².
#[inline]
pub fn schlick_r0(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// The roughness of the main specular lobes: α = roughness², and with anisotropy
/// (α_u, α_v) = (α/a, α·a), a = √(1 − 0.9·anisotropic) (Burley 2012, §5.4), each at least 10⁻³.
#[inline]
pub fn specular_alphas(roughness: f32, anisotropic: Option<f32>) -> (f32, f32) {
    let alpha = roughness * roughness;
    match anisotropic {
        None => (alpha.max(1e-3), alpha.max(1e-3)),
        Some(anisotropic) => {
            let aspect = (1.0 - 0.9 * anisotropic).sqrt();
            ((alpha / aspect).max(1e-3), (alpha * aspect).max(1e-3))
        }
    }
}

/// The clearcoat's roughness: α = 0.1 at `clearcoat_gloss` 0, 0.001 at 1 (Burley 2012, §5.5).
#[inline]
pub fn clearcoat_alpha(clearcoat_gloss: f32) -> f32 {
    0.1 + (0.001 - 0.1) * clearcoat_gloss
}

/// The colour's luminance as Mitsuba 3's spectral variants compute it for a tint: the mean of
/// ȳ(λᵢ) c(λᵢ) over the path's wavelengths (not divided by the mean of ȳ, so that a white base
/// is tinted by 1/mean ȳ(λᵢ), as in Mitsuba).
#[inline]
fn tint_luminance(color: &SampledSpectrum, lambda: &SampledWavelengths) -> f32 {
    SampledSpectrum::from_fn(|i| cie_y(lambda.lambda(i)) * color[i]).average()
}

/// Burley's C_tint, for lobes that are tinted (`spec_tint`, `sheen_tint`; `tinted`): the colour
/// normalised to luminance 1 (white where it is black); the colour itself where none is.
#[inline]
pub fn tint(color: &SampledSpectrum, tinted: bool, lambda: &SampledWavelengths) -> SampledSpectrum {
    let luminance = if tinted {
        tint_luminance(color, lambda)
    } else {
        1.0
    };
    if luminance > 0.0 {
        *color * (1.0 / luminance)
    } else {
        SampledSpectrum::ONE
    }
}

/// The diffuse lobe's factor of c/π cos θi (Burley 2012, §5.3; Burley 2015, §5.3):
/// (1 − ½F_o)(1 − ½F_i) + R_r (F_o + F_i + F_o F_i (R_r − 1)), F_x = (1 − cos θx)⁵ and
/// R_r = 2 roughness cos²θ_d (`cos_d` = h·wi), blended towards the fake subsurface
/// 1.25 (F_ss (1/(cos θo + cos θi) − ½) + ½) by `flatness`.
#[inline]
pub fn diffuse_factor(
    roughness: f32,
    flatness: Option<f32>,
    cos_o: f32,
    cos_i: f32,
    cos_d: f32,
) -> f32 {
    let (f_o, f_i) = (schlick_weight(cos_i), schlick_weight(cos_o));
    let retro = 2.0 * roughness * cos_d * cos_d;
    let lambert = (1.0 - 0.5 * f_i) * (1.0 - 0.5 * f_o);
    let mut diffuse = lambert + retro * (f_o + f_i + f_o * f_i * (retro - 1.0));
    if let Some(flatness) = flatness {
        let f_ss90 = 0.5 * retro;
        let f_ss = (1.0 + f_o * (f_ss90 - 1.0)) * (1.0 + f_i * (f_ss90 - 1.0));
        let subsurface = 1.25 * (f_ss * (1.0 / (cos_o + cos_i) - 0.5) + 0.5);
        diffuse += flatness * (subsurface - diffuse);
    }
    diffuse
}

/// The sheen's colour lerp(1, C_tint, `sheen_tint`).
#[inline]
pub fn sheen_colour(sheen_tint: Option<f32>, tint: &SampledSpectrum) -> SampledSpectrum {
    match sheen_tint {
        Some(t) => SampledSpectrum::from_fn(|i| 1.0 + t * (tint[i] - 1.0)),
        None => SampledSpectrum::ONE,
    }
}

/// Burley's GTR1 ("generalised Trowbridge–Reitz" with γ = 1) distribution of the clearcoat's
/// normals (Burley 2012, appendix B.2, eqs. 4 and 5):
///
///   D(m) = (α² − 1) / (π ln α² (1 + (α² − 1) cos²θ_m)),
///
/// sampled as φ = 2πu₁, cos²θ = (1 − α^(2(1 − u₂))) / (1 − α²), with density D(m) cos θ_m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gtr1 {
    pub alpha: f32,
}

impl Gtr1 {
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        let alpha2 = self.alpha * self.alpha;
        let d = (alpha2 - 1.0) / (PI * alpha2.ln() * (1.0 + (alpha2 - 1.0) * m.z * m.z));
        if d * m.z > 1e-20 { d } else { 0.0 }
    }

    /// The density of [`Self::sample`] over normals.
    #[inline]
    pub fn pdf(&self, m: Vec3) -> f32 {
        if m.z < 0.0 { 0.0 } else { m.z * self.d(m) }
    }

    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (sin_phi, cos_phi) = (2.0 * PI * u.x).sin_cos();
        let alpha2 = self.alpha * self.alpha;
        let cos2_theta = (1.0 - alpha2.powf(1.0 - u.y)) / (1.0 - alpha2);
        let sin_theta = (1.0 - cos2_theta).max(0.0).sqrt();
        Vec3::new(
            cos_phi * sin_theta,
            sin_phi * sin_theta,
            cos2_theta.max(0.0).sqrt(),
        )
    }
}

/// Smith's masking for GGX of roughness α, G₁(v) = 2 / (1 + √(1 + α² tan²θ_v)), zero when m
/// faces away from v (Mitsuba's `smith_ggx1`, used with α = 0.25 for the clearcoat).
#[inline]
pub fn smith_ggx1(v: Vec3, m: Vec3, alpha: f32) -> f32 {
    if v.dot(m) * v.z <= 0.0 {
        return 0.0;
    }
    if v.z == 1.0 {
        return 1.0;
    }
    let cos2 = v.z * v.z;
    let tan2 = (1.0 - cos2) / cos2;
    2.0 / (1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}
