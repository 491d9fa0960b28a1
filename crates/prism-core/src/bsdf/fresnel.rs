//! Fresnel equations and the mirror and refraction maps, in the local shading frame (normal +z).
//!
//! Conventions follow Mitsuba 3 (`include/mitsuba/render/fresnel.h`): a relative index of
//! refraction η = η_interior / η_exterior, where the exterior is the side the normal points to.

use glam::Vec3;
use wide::f32x4;

/// The Fresnel reflectance of a dielectric interface and the refraction it implies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricFresnel {
    /// Unpolarised reflectance F = (r_s² + r_p²)/2; 1 under total internal reflection.
    pub reflectance: f32,
    /// Cosine of the refracted direction, with the sign opposite to cos θᵢ (0 under total
    /// internal reflection).
    pub cos_theta_t: f32,
    /// Relative index of refraction in the direction of travel: η coming from outside, 1/η
    /// from inside.
    pub eta_it: f32,
    /// 1/eta_it: the factor that scales the tangential components of the refracted direction.
    pub eta_ti: f32,
}

/// Fresnel equations for unpolarised light at a smooth dielectric interface with relative index
/// `eta` (Born & Wolf, "Principles of Optics", §1.5.2): with η = η_t/η_i in the direction of
/// travel, cos θ_t from Snell's law sin θ_t = sin θ_i / η,
///
///   r_s = (cos θ_i − η cos θ_t) / (cos θ_i + η cos θ_t),
///   r_p = (η cos θ_i − cos θ_t) / (η cos θ_i + cos θ_t),   F = (r_s² + r_p²) / 2.
///
/// `cos_theta_i` is signed: negative means the light arrives from the interior.
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> DielectricFresnel {
    let outside = cos_theta_i >= 0.0;
    let (eta_it, eta_ti) = if outside {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let cos_i = cos_theta_i.abs();
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) * eta_ti * eta_ti;
    if sin2_t >= 1.0 {
        return DielectricFresnel {
            reflectance: 1.0,
            cos_theta_t: 0.0,
            eta_it,
            eta_ti,
        };
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let reflectance = if eta == 1.0 {
        0.0
    } else if cos_i == 0.0 {
        1.0
    } else {
        let r_s = (cos_i - eta_it * cos_t) / (cos_i + eta_it * cos_t);
        let r_p = (eta_it * cos_i - cos_t) / (eta_it * cos_i + cos_t);
        0.5 * (r_s * r_s + r_p * r_p)
    };
    DielectricFresnel {
        reflectance,
        cos_theta_t: if outside { -cos_t } else { cos_t },
        eta_it,
        eta_ti,
    }
}

/// Unpolarised reflectance of a conductor with complex index η + ik, for light arriving from
/// outside at cos θ ≥ 0 (the exact formula in the form of Lagarde 2013, "Memo on Fresnel
/// equations", after Moeller, "Optics", 1988):
///
///   a² + b² = √((η² − k² − sin²θ)² + 4η²k²),  a = √((a² + b² + η² − k² − sin²θ)/2),
///   R_s = (a² + b² − 2a cos θ + cos²θ) / (a² + b² + 2a cos θ + cos²θ),
///   R_p = R_s (cos²θ (a² + b²) − 2a cos θ sin²θ + sin⁴θ) / (cos²θ (a² + b²) + 2a cos θ sin²θ + sin⁴θ),
///
/// F = (R_s + R_p)/2. At normal incidence F = ((η − 1)² + k²) / ((η + 1)² + k²); η = 0, k = 1
/// (Mitsuba's default) is a perfect mirror.
#[inline]
pub fn fresnel_conductor(cos_theta_i: f32, eta: f32, k: f32) -> f32 {
    fresnel_conductor4(cos_theta_i, f32x4::splat(eta), f32x4::splat(k)).to_array()[0]
}

/// [`fresnel_conductor`] for four (η, k) at once, one per wavelength of a path, in SIMD; a
/// result that is not finite (from an infinite or NaN index) is 1.
#[inline]
pub fn fresnel_conductor4(cos_theta_i: f32, eta: f32x4, k: f32x4) -> f32x4 {
    let cos2 = cos_theta_i * cos_theta_i;
    let sin2 = (1.0 - cos2).max(0.0);
    let sin4 = sin2 * sin2;
    let (cos, cos2, sin2, sin4) = (
        f32x4::splat(cos_theta_i),
        f32x4::splat(cos2),
        f32x4::splat(sin2),
        f32x4::splat(sin4),
    );
    let t0 = eta * eta - k * k - sin2;
    let a2_plus_b2 = (t0 * t0 + f32x4::splat(4.0) * eta * eta * k * k)
        .max(f32x4::ZERO)
        .sqrt();
    let a = (f32x4::splat(0.5) * (a2_plus_b2 + t0))
        .max(f32x4::ZERO)
        .sqrt();
    let t1 = a2_plus_b2 + cos2;
    let t2 = f32x4::splat(2.0) * cos * a;
    let r_s = (t1 - t2) / (t1 + t2);
    let t3 = a2_plus_b2 * cos2 + sin4;
    let t4 = t2 * sin2;
    let r_p = r_s * (t3 - t4) / (t3 + t4);
    let f = f32x4::splat(0.5) * (r_s + r_p);
    f.is_finite()
        .blend(f.max(f32x4::ZERO).min(f32x4::ONE), f32x4::ONE)
}

/// The hemispherical average of the dielectric Fresnel reflectance for light arriving from
/// the side where the relative index is `eta` (Mitsuba's `fresnel_diffuse_reflectance`, "Fdr"):
/// the polynomial fits of Egan & Hilgeman 1973 for η < 1 and of d'Eon & Irving 2011, "A
/// Quantized-Diffusion Model for Rendering Translucent Materials", eq. 27, for η ≥ 1.
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    if eta < 1.0 {
        -1.4399 * eta * eta + 0.7099 * eta + 0.6681 + 0.0636 / eta
    } else {
        let inv = 1.0 / eta;
        let (inv2, inv3) = (inv * inv, inv * inv * inv);
        0.919_317 - 3.4793 * inv + 6.753_35 * inv2 - 7.809_89 * inv3 + 4.985_54 * inv2 * inv2
            - 1.368_81 * inv2 * inv3
    }
}

/// The mirror direction of `w` about the normal +z.
#[inline]
pub fn reflect_z(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// The mirror direction of `w` about the unit vector `m`.
#[inline]
pub fn reflect(w: Vec3, m: Vec3) -> Vec3 {
    2.0 * w.dot(m) * m - w
}

/// The refraction of `w` through a surface with normal +z, given `cos_theta_t` and `eta_ti`
/// from [`fresnel_dielectric`].
#[inline]
pub fn refract_z(w: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    Vec3::new(-eta_ti * w.x, -eta_ti * w.y, cos_theta_t)
}

/// The refraction of `w` through a microfacet with unit normal `m` (Walter et al. 2007, eq. 40):
/// w_t = m (w·m η_ti + cos θ_t) − w η_ti, with `cos_theta_t` and `eta_ti` from
/// [`fresnel_dielectric`] evaluated at w·m.
#[inline]
pub fn refract(w: Vec3, m: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    m * (w.dot(m) * eta_ti + cos_theta_t) - w * eta_ti
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The four lanes are four independent evaluations: each equals the one-index formula
    /// (itself the first lane of a splat), including a NaN index, whose reflectance is 1.
    #[test]
    fn conductor_lanes_are_independent() {
        let mut rng = crate::sampling::rng::Pcg32::seeded(8);
        for _ in 0..1000 {
            let cos = rng.next_f32();
            let eta: [f32; 4] = std::array::from_fn(|_| 4.0 * rng.next_f32());
            let mut k: [f32; 4] = std::array::from_fn(|_| 5.0 * rng.next_f32());
            k[3] = f32::NAN;
            let four = fresnel_conductor4(cos, f32x4::from(eta), f32x4::from(k)).to_array();
            for i in 0..4 {
                assert_eq!(
                    four[i].to_bits(),
                    fresnel_conductor(cos, eta[i], k[i]).to_bits()
                );
            }
            assert_eq!(four[3], 1.0);
            // Normal incidence: ((η − 1)² + k²) / ((η + 1)² + k²).
            let normal = fresnel_conductor4(1.0, f32x4::from(eta), f32x4::from(k)).to_array();
            for i in 0..3 {
                let expected =
                    ((eta[i] - 1.0).powi(2) + k[i] * k[i]) / ((eta[i] + 1.0).powi(2) + k[i] * k[i]);
                assert!((normal[i] - expected).abs() < 1e-5, "{} {}", eta[i], k[i]);
            }
        }
    }

    #[test]
    fn normal_incidence_matches_the_closed_forms() {
        for eta in [1.33f32, 1.5, 2.419, 0.7] {
            let f = fresnel_dielectric(1.0, eta).reflectance;
            let expected = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((f - expected).abs() < 1e-6, "{eta}: {f} vs {expected}");
        }
        for (eta, k) in [(0.2f32, 3.9f32), (1.1, 2.1), (0.05, 4.0), (2.8, 3.0)] {
            let f = fresnel_conductor(1.0, eta, k);
            let expected = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
            assert!((f - expected).abs() < 1e-5, "{eta}+{k}i: {f} vs {expected}");
        }
        assert_eq!(fresnel_conductor(0.3, 0.0, 1.0), 1.0);
    }

    /// A conductor with k = 0 is a dielectric seen from outside.
    #[test]
    fn conductor_without_absorption_is_a_dielectric() {
        for cos in [1.0f32, 0.8, 0.5, 0.2, 0.05] {
            let a = fresnel_conductor(cos, 1.5, 0.0);
            let b = fresnel_dielectric(cos, 1.5).reflectance;
            assert!((a - b).abs() < 2e-5, "{cos}: {a} vs {b}");
        }
    }

    #[test]
    fn total_internal_reflection_and_refraction_obey_snell() {
        let eta = 1.5;
        // From inside beyond the critical angle.
        let cos_i = -(1.0f32 - 0.8f32 * 0.8).sqrt();
        assert_eq!(fresnel_dielectric(cos_i, eta).reflectance, 1.0);
        let w = Vec3::new(0.6, 0.0, 0.8);
        let f = fresnel_dielectric(w.z, eta);
        let t = refract_z(w, f.cos_theta_t, f.eta_ti);
        assert!((t.length() - 1.0).abs() < 1e-6 && t.z < 0.0);
        assert!((t.x.abs() * eta - w.x).abs() < 1e-6, "sin θi = η sin θt");
        let t2 = refract(w, Vec3::Z, f.cos_theta_t, f.eta_ti);
        assert!((t - t2).length() < 1e-6);
    }

    #[test]
    fn diffuse_fresnel_matches_the_hemispherical_average() {
        for eta in [1.2f32, 1.5, 2.0, 1.0 / 1.5] {
            let n = 20_000;
            let average: f64 = (0..n)
                .map(|i| {
                    // ∫ F(cos θ) 2 cos θ dcos θ by the midpoint rule in cos²θ.
                    let mu2 = (i as f64 + 0.5) / n as f64;
                    f64::from(fresnel_dielectric(mu2.sqrt() as f32, eta).reflectance)
                })
                .sum::<f64>()
                / n as f64;
            let fit = f64::from(fresnel_diffuse_reflectance(eta));
            assert!((average - fit).abs() < 4e-3, "{eta}: {average} vs {fit}");
        }
    }
}
