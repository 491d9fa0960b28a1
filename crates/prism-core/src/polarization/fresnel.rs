//! The Fresnel equations for polarized light: the complex amplitudes of the s- and
//! p-polarized waves reflected at a smooth interface, and the Mueller matrices of specular
//! reflection and refraction they give (Mitsuba 3, `include/mitsuba/render/fresnel.h` and
//! `mueller.h`; Born & Wolf, "Principles of Optics", §1.5.2).
//!
//! Conventions: `cos_theta_i` is the cosine of the incident direction with the normal, negative
//! when the light arrives from the interior; η = η_interior / η_exterior (a conductor's
//! η + ik with k ≥ 0, as Prism's `conductor` reads it); the amplitude of the p wave follows the
//! Verdet convention (r_p = r_s at normal incidence); the matrices' reference direction is the
//! normal of the plane of incidence (the s direction) on both sides.

use std::ops::{Add, Div, Mul, Sub};

use glam::Mat4;

use super::mueller::from_rows;

/// A complex number, enough for the Fresnel amplitudes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Complex {
    pub re: f32,
    pub im: f32,
}

impl Complex {
    #[inline]
    pub const fn new(re: f32, im: f32) -> Complex {
        Complex { re, im }
    }

    #[inline]
    pub const fn real(re: f32) -> Complex {
        Complex { re, im: 0.0 }
    }

    #[inline]
    pub fn conj(self) -> Complex {
        Complex::new(self.re, -self.im)
    }

    /// |z|².
    #[inline]
    pub fn norm_squared(self) -> f32 {
        self.re * self.re + self.im * self.im
    }

    /// The principal square root (non-negative real part).
    #[inline]
    pub fn sqrt(self) -> Complex {
        let n = self.norm_squared().sqrt();
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        if t1 == 0.0 {
            return Complex::real(0.0);
        }
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 {
            Complex::new(t1, t2)
        } else {
            Complex::new(t2.abs(), t1.copysign(self.im))
        }
    }

    #[inline]
    pub fn recip(self) -> Complex {
        let n = self.norm_squared();
        Complex::new(self.re / n, -self.im / n)
    }
}

impl Add for Complex {
    type Output = Complex;
    #[inline]
    fn add(self, rhs: Complex) -> Complex {
        Complex::new(self.re + rhs.re, self.im + rhs.im)
    }
}

impl Sub for Complex {
    type Output = Complex;
    #[inline]
    fn sub(self, rhs: Complex) -> Complex {
        Complex::new(self.re - rhs.re, self.im - rhs.im)
    }
}

impl Mul for Complex {
    type Output = Complex;
    #[inline]
    fn mul(self, rhs: Complex) -> Complex {
        Complex::new(
            self.re * rhs.re - self.im * rhs.im,
            self.re * rhs.im + self.im * rhs.re,
        )
    }
}

impl Mul<Complex> for f32 {
    type Output = Complex;
    #[inline]
    fn mul(self, rhs: Complex) -> Complex {
        Complex::new(self * rhs.re, self * rhs.im)
    }
}

impl Div for Complex {
    type Output = Complex;
    #[inline]
    fn div(self, rhs: Complex) -> Complex {
        let n = rhs.norm_squared();
        Complex::new(
            (self.re * rhs.re + self.im * rhs.im) / n,
            (self.im * rhs.re - self.re * rhs.im) / n,
        )
    }
}

/// The reflected amplitudes at an interface and the refraction they imply.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FresnelAmplitudes {
    /// The s (perpendicular) wave's reflected amplitude and phase.
    pub a_s: Complex,
    /// The p (parallel) wave's reflected amplitude and phase (Verdet convention).
    pub a_p: Complex,
    /// Cosine of the refracted direction, with the sign opposite to cos θᵢ; 0 under total
    /// internal reflection.
    pub cos_theta_t: f32,
    /// The relative index in the direction of travel: η from outside, 1/η from inside.
    pub eta_it: Complex,
    /// 1/eta_it.
    pub eta_ti: Complex,
}

/// The Fresnel amplitudes for the complex relative index `eta` = η + ik (k ≥ 0), from either
/// side: with η_it the index in the direction of travel and cos θ_t = √(1 − η_ti² sin²θᵢ)
/// (complex, the root with non-positive imaginary part: Clarke, "Stellar Polarimetry", 2010,
/// app. A.2, which gives the phase under total internal reflection),
///
///   a_s = (cos θᵢ − η_it cos θ_t) / (cos θᵢ + η_it cos θ_t),
///   a_p = (η_it cos θᵢ − cos θ_t) / (η_it cos θᵢ + cos θ_t).
///
/// The formulas assume a wave exp(i(ωt − ηx)) whose index has a negative imaginary part, so k
/// is conjugated first (Mitsuba's `fresnel_polarized`). An index of 1 or 0 reflects nothing.
pub fn fresnel_amplitudes(cos_theta_i: f32, eta: Complex) -> FresnelAmplitudes {
    let eta = if eta.im > 0.0 { eta.conj() } else { eta };
    let outside = cos_theta_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, eta.recip())
    } else {
        (eta.recip(), eta)
    };
    let sin2_i = 1.0 - cos_theta_i * cos_theta_i;
    let cos_t_sqr = Complex::real(1.0) - sin2_i * (eta_ti * eta_ti);
    let cos_i = Complex::real(cos_theta_i.abs());
    let mut cos_t = cos_t_sqr.sqrt();
    if cos_t.im > 0.0 {
        cos_t = cos_t.conj();
    }
    let matched_or_invalid =
        (eta.norm_squared() == 1.0 && eta.im == 0.0) || eta.norm_squared() == 0.0;
    let (a_s, a_p) = if matched_or_invalid {
        (Complex::real(0.0), Complex::real(0.0))
    } else {
        (
            (cos_i - eta_it * cos_t) / (cos_i + eta_it * cos_t),
            (eta_it * cos_i - cos_t) / (eta_it * cos_i + cos_t),
        )
    };
    let cos_theta_t = if cos_t_sqr.re >= 0.0 {
        if outside { -cos_t.re } else { cos_t.re }
    } else {
        0.0
    };
    FresnelAmplitudes {
        a_s,
        a_p,
        cos_theta_t,
        eta_it,
        eta_ti,
    }
}

/// The Mueller matrix of specular reflection at an interface of relative index `eta` (a
/// dielectric's has k = 0), for light arriving at `cos_theta_i` (Collett, ch. 8; Mitsuba's
/// `specular_reflection`): with R_s = |a_s|², R_p = |a_p|² and δ = arg a_p − arg a_s,
///
///   ½ [[R_s + R_p, R_s − R_p, 0, 0], [R_s − R_p, R_s + R_p, 0, 0],
///      [0, 0, 2c cos δ, −2c sin δ], [0, 0, 2c sin δ, 2c cos δ]],   c = √(R_s R_p),
///
/// in the s frames of the incident and reflected beams. M₀₀ is the unpolarized reflectance.
pub fn specular_reflection(cos_theta_i: f32, eta: Complex) -> Mat4 {
    let FresnelAmplitudes { a_s, a_p, .. } = fresnel_amplitudes(cos_theta_i, eta);
    let (r_s, r_p) = (a_s.norm_squared(), a_p.norm_squared());
    let (a, b, c) = (0.5 * (r_s + r_p), 0.5 * (r_s - r_p), (r_s * r_p).sqrt());
    // sin δ and cos δ from a_p conj(a_s) / (|a_p| |a_s|).
    let (sin_delta, cos_delta) = if c == 0.0 {
        (0.0, 0.0)
    } else {
        let v = a_p * a_s.conj();
        let normalization = 1.0 / (a_p.norm_squared() * a_s.norm_squared()).sqrt();
        (v.im * normalization, v.re * normalization)
    };
    from_rows([
        [a, b, 0.0, 0.0],
        [b, a, 0.0, 0.0],
        [0.0, 0.0, c * cos_delta, -c * sin_delta],
        [0.0, 0.0, c * sin_delta, c * cos_delta],
    ])
}

/// The Mueller matrix of specular refraction through a dielectric interface of relative index
/// `eta`, for light arriving at `cos_theta_i` (Mitsuba's `specular_transmission`): the
/// transmitted amplitudes t_s = 1 + a_s and t_p = (1 + a_p) η_ti, with T_s = t_s², T_p = t_p²
/// and the factor f = η_it cos θ_t / cos θᵢ that turns amplitudes into power (the refracted
/// beam's other width and speed),
///
///   ½ f [[T_s + T_p, T_s − T_p, 0, 0], [T_s − T_p, T_s + T_p, 0, 0],
///        [0, 0, 2√(T_s T_p), 0], [0, 0, 0, 2√(T_s T_p)]].
///
/// M₀₀ is 1 minus the unpolarized reflectance; zero under total internal reflection. The
/// radiance's change of solid angle across the interface (η_ti²) is not included.
pub fn specular_transmission(cos_theta_i: f32, eta: f32) -> Mat4 {
    let f = fresnel_amplitudes(cos_theta_i, Complex::real(eta));
    let factor = if cos_theta_i.abs() > 1e-8 {
        f.eta_it.re * (f.cos_theta_t / cos_theta_i).abs()
    } else {
        0.0
    };
    let t_s = (1.0 + f.a_s.re).powi(2);
    let t_p = ((1.0 + f.a_p.re) * f.eta_ti.re).powi(2);
    let (a, b, c) = (
        0.5 * factor * (t_s + t_p),
        0.5 * factor * (t_s - t_p),
        factor * (t_s * t_p).sqrt(),
    );
    from_rows([
        [a, b, 0.0, 0.0],
        [b, a, 0.0, 0.0],
        [0.0, 0.0, c, 0.0],
        [0.0, 0.0, 0.0, c],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R_s and R_p against the closed forms of the Fresnel equations in the angles (Born &
    /// Wolf, §1.5.2): R_s = sin²(θᵢ − θ_t)/sin²(θᵢ + θ_t), R_p = tan²(θᵢ − θ_t)/tan²(θᵢ + θ_t);
    /// R_p vanishes at Brewster's angle tan θ_B = η, and R_s and R_p are the matrix's
    /// M₀₀ ± M₀₁.
    #[test]
    fn dielectric_reflectances_match_the_closed_forms() {
        for eta in [1.33f64, 1.5, 2.4] {
            for degrees in [5.0f64, 20.0, 40.0, 60.0, 75.0, 85.0] {
                let theta_i = degrees.to_radians();
                let theta_t = (theta_i.sin() / eta).asin();
                let r_s = ((theta_i - theta_t).sin() / (theta_i + theta_t).sin()).powi(2);
                let r_p = ((theta_i - theta_t).tan() / (theta_i + theta_t).tan()).powi(2);
                let m = specular_reflection(theta_i.cos() as f32, Complex::real(eta as f32));
                let (m00, m01) = (f64::from(m.x_axis.x), f64::from(m.y_axis.x));
                assert!((m00 + m01 - r_s).abs() < 1e-5, "{eta} {degrees}: R_s");
                assert!((m00 - m01 - r_p).abs() < 1e-5, "{eta} {degrees}: R_p");
                let a = fresnel_amplitudes(theta_i.cos() as f32, Complex::real(eta as f32));
                assert!((f64::from(a.a_s.norm_squared()) - r_s).abs() < 1e-5);
                // Energy: what is not reflected is transmitted, in each polarization.
                let t = specular_transmission(theta_i.cos() as f32, eta as f32);
                let (t00, t01) = (f64::from(t.x_axis.x), f64::from(t.y_axis.x));
                assert!(
                    (t00 + t01 - (1.0 - r_s)).abs() < 1e-5,
                    "{eta} {degrees}: T_s"
                );
                assert!(
                    (t00 - t01 - (1.0 - r_p)).abs() < 1e-5,
                    "{eta} {degrees}: T_p"
                );
            }
            let brewster = eta.atan();
            let m = specular_reflection(brewster.cos() as f32, Complex::real(eta as f32));
            assert!(
                (m.x_axis.x - m.y_axis.x).abs() < 1e-6,
                "R_p = 0 at Brewster's angle"
            );
        }
    }

    /// Under total internal reflection both waves are reflected whole, with the phase
    /// difference of Born & Wolf §1.5.4: tan(δ/2) = cos θ √(sin²θ − 1/η²) / sin²θ, with η the
    /// index of the denser side over the thinner; s₂ turns into s₃.
    #[test]
    fn total_internal_reflection_shifts_the_phase() {
        let eta = 1.5f32;
        let degrees = 55.0f32;
        let theta = degrees.to_radians();
        let m = specular_reflection(-theta.cos(), Complex::real(eta));
        assert!((m.x_axis.x - 1.0).abs() < 1e-6 && m.y_axis.x.abs() < 1e-6);
        let sin2 = theta.sin().powi(2);
        let half = (theta.cos() * (sin2 - 1.0 / (eta * eta)).sqrt() / sin2).atan();
        let delta = 2.0 * half;
        // M₂₂ = cos δ, M₃₂ = sin δ.
        assert!(
            (m.z_axis.z - delta.cos()).abs() < 1e-5,
            "{} {}",
            m.z_axis.z,
            delta.cos()
        );
        assert!(
            (m.z_axis.w - delta.sin()).abs() < 1e-5,
            "{} {}",
            m.z_axis.w,
            delta.sin()
        );
        assert_eq!(specular_transmission(-theta.cos(), eta), Mat4::ZERO);
    }

    /// A conductor: at normal incidence R = ((η − 1)² + k²)/((η + 1)² + k²) for both waves; its
    /// retardance δ turns linear light elliptical, and k = 0 is a dielectric.
    #[test]
    fn conductor_reflection_matches_the_closed_forms() {
        for (eta, k) in [(0.2f32, 3.9f32), (1.1, 2.1), (2.8, 3.0)] {
            let m = specular_reflection(1.0, Complex::new(eta, k));
            let expected = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
            assert!((m.x_axis.x - expected).abs() < 1e-5);
            assert!(m.y_axis.x.abs() < 1e-5);
            let oblique = specular_reflection(0.5, Complex::new(eta, k));
            assert!(oblique.w_axis.z.abs() > 1e-3, "a conductor retards");
            let dielectric = specular_reflection(0.5, Complex::new(eta, 0.0));
            let without_k = specular_reflection(0.5, Complex::real(eta));
            assert!(dielectric.abs_diff_eq(without_k, 1e-7));
        }
    }

    /// M₀₀ of the reflection and refraction matrices is the unpolarized reflectance (and its
    /// complement) that Prism's unpolarized BSDFs use, from both sides and for conductors.
    #[test]
    fn first_elements_are_the_unpolarized_fresnel_reflectance() {
        use crate::bsdf::fresnel::{fresnel_conductor, fresnel_dielectric};
        for eta in [1.33f32, 1.5, 1.0 / 1.5, 2.4] {
            for i in 0..=20 {
                let cos = -1.0 + 0.1 * i as f32;
                let unpolarized = fresnel_dielectric(cos, eta).reflectance;
                let m = specular_reflection(cos, Complex::real(eta));
                assert!((m.x_axis.x - unpolarized).abs() < 1e-5, "{eta} {cos}");
                if cos != 0.0 {
                    let t = specular_transmission(cos, eta);
                    assert!(
                        (t.x_axis.x - (1.0 - unpolarized)).abs() < 1e-5,
                        "{eta} {cos}"
                    );
                }
            }
        }
        for (eta, k) in [(0.2f32, 3.9f32), (1.1, 2.1), (2.8, 3.0), (0.05, 4.0)] {
            for i in 1..=10 {
                let cos = 0.1 * i as f32;
                let unpolarized = fresnel_conductor(cos, eta, k);
                let m = specular_reflection(cos, Complex::new(eta, k));
                assert!((m.x_axis.x - unpolarized).abs() < 2e-5, "{eta}+{k}i {cos}");
                // A Mueller matrix of a passive element never gives more than it receives.
                assert!(m.x_axis.x + m.y_axis.x <= 1.0 + 1e-6);
            }
        }
    }

    /// Energy is never above the unpolarized case's bound: whatever the polarization of the
    /// incident light, reflected plus refracted intensity is at most the incident one (exactly
    /// it for a dielectric), and each beam stays physical (S₀ ≥ |(S₁, S₂, S₃)|).
    #[test]
    fn no_polarization_gains_energy() {
        let mut rng = crate::sampling::rng::Pcg32::seeded(12);
        for _ in 0..2000 {
            let direction = crate::sampling::warp::sample_uniform_sphere(glam::Vec2::new(
                rng.next_f32(),
                rng.next_f32(),
            ));
            let incident = glam::Vec4::new(1.0, direction.x, direction.y, direction.z);
            let cos = 2.0 * rng.next_f32() - 1.0;
            let eta = 1.0 + 2.0 * rng.next_f32();
            let reflected = specular_reflection(cos, Complex::real(eta)) * incident;
            let refracted = specular_transmission(cos, eta) * incident;
            assert!(
                (reflected.x + refracted.x - 1.0).abs() < 1e-4,
                "{cos} {eta}"
            );
            let conductor = specular_reflection(
                cos.abs(),
                Complex::new(3.0 * rng.next_f32(), 5.0 * rng.next_f32()),
            ) * incident;
            assert!(conductor.x <= 1.0 + 1e-5);
            for s in [reflected, refracted, conductor] {
                let polarized = glam::Vec3::new(s.y, s.z, s.w).length();
                assert!(polarized <= s.x + 1e-4, "{s}");
            }
        }
    }

    #[test]
    fn complex_square_roots_are_principal() {
        for (re, im) in [
            (4.0f32, 0.0f32),
            (-4.0, 0.0),
            (3.0, 4.0),
            (3.0, -4.0),
            (-3.0, 4.0),
        ] {
            let z = Complex::new(re, im);
            let r = z.sqrt();
            assert!(r.re >= 0.0);
            let back = r * r;
            assert!(
                (back.re - re).abs() < 1e-5 && (back.im - im).abs() < 1e-5,
                "{z:?}"
            );
        }
    }
}
