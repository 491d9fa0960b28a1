//! Mitsuba's `sphere` shape.

use std::f32::consts::PI;

use glam::{DVec3, Mat3, Vec2, Vec3};

use super::mesh::SurfaceSample;
use super::{Segments, ShapeGeometry, SolidAngleSampler};
use crate::geometry::interaction::{AttributeValues, SurfaceInteraction};
use crate::geometry::triangle::TriangleHit;
use crate::math::{Frame, Ray};
use crate::sampling::warp::sample_uniform_sphere;

/// A sphere; the normal points outwards unless `flip_normals`.
#[derive(Clone, Debug)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: f32,
    /// Rotation of the object frame (for the uv parametrisation), orthonormal columns.
    pub rotation: Mat3,
    pub flip_normals: bool,
}

/// Relative margin by which a reference point must lie outside the sphere for the cone to be
/// sampled: points on the surface itself (a sphere lighting its own inside, say) are rounded to
/// either side, and only area sampling is valid for them.
const OUTSIDE_MARGIN: f32 = 1e-4;

impl Sphere {
    /// Nearest t in (0, t_max) where the ray meets the sphere. Solved in double precision with
    /// the discriminant written as r² − |f − (f·d/d·d) d|² (Haines et al. 2019, "Precision
    /// Improvements for Ray/Sphere Intersection", Ray Tracing Gems ch. 7), which keeps its
    /// precision for rays far from the sphere.
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let f = o.as_dvec3() - self.center.as_dvec3();
        let d = d.as_dvec3();
        let r = f64::from(self.radius);
        let a = d.dot(d);
        let b = f.dot(d);
        let closest = f - d * (b / a);
        let discriminant = a * (r * r - closest.dot(closest));
        if discriminant < 0.0 {
            return None;
        }
        let c = f.dot(f) - r * r;
        let q = -(b + discriminant.sqrt().copysign(b));
        let (mut t0, mut t1) = (c / q, q / a);
        if q == 0.0 {
            // The ray starts on the sphere and is tangent to it.
            return None;
        }
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let t = if t0 > 0.0 { t0 } else { t1 };
        (t > 0.0 && t < f64::from(t_max)).then_some(t as f32)
    }

    /// The surface interaction at the point hit at distance `t`; the point is projected back
    /// onto the sphere, where it is accurate to a few ulps.
    pub fn interaction_at(&self, o: Vec3, d: Vec3, t: f32, shape: u32) -> SurfaceInteraction {
        let c = self.center.as_dvec3();
        let hit = o.as_dvec3() + d.as_dvec3() * f64::from(t);
        let outward = (hit - c).normalize_or(DVec3::Z);
        let p = (c + outward * f64::from(self.radius)).as_vec3();
        let outward = outward.as_vec3();
        let n = if self.flip_normals { -outward } else { outward };
        let (dp_du, dp_dv) = self.tangents(outward);
        SurfaceInteraction {
            p,
            t,
            n,
            shading: Frame::from_normal_and_tangent(n, dp_du),
            uv: self.uv(outward),
            dp_du,
            dp_dv,
            shape,
            primitive: 0,
            time: 0.0,
            attributes: AttributeValues::default(),
        }
    }

    /// ∂p/∂u and ∂p/∂v of the (φ/2π, θ/π) parametrisation: 2π r (−y, x, 0) and
    /// π r (z cos φ, z sin φ, −sin θ) in the object frame.
    fn tangents(&self, outward: Vec3) -> (Vec3, Vec3) {
        let local = self.rotation.transpose() * outward;
        let sin_theta = (local.x * local.x + local.y * local.y).sqrt();
        let (cos_phi, sin_phi) = if sin_theta > 0.0 {
            (local.x / sin_theta, local.y / sin_theta)
        } else {
            (1.0, 0.0)
        };
        let r = self.radius;
        let dp_du = Vec3::new(-local.y, local.x, 0.0) * (2.0 * PI * r);
        let dp_dv = Vec3::new(local.z * cos_phi, local.z * sin_phi, -sin_theta) * (PI * r);
        (self.rotation * dp_du, self.rotation * dp_dv)
    }

    /// Mitsuba's parametrisation: (φ/2π, θ/π) in the object frame.
    fn uv(&self, outward: Vec3) -> Vec2 {
        let local = self.rotation.transpose() * outward;
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Vec2::new(phi / (2.0 * PI), local.z.clamp(-1.0, 1.0).acos() / PI)
    }

    fn surface_point(&self, outward: Vec3) -> SurfaceSample {
        let n = if self.flip_normals { -outward } else { outward };
        SurfaceSample {
            p: self.center + outward * self.radius,
            n,
            shading_n: n,
            uv: self.uv(outward),
            primitive: 0,
            pdf: 0.0,
        }
    }

    /// |∂p/∂u × ∂p/∂v| = 2π² r² sin θ at texture coordinates `uv` (θ = π v), from
    /// [`Self::tangents`].
    pub fn uv_jacobian(&self, uv: Vec2) -> f32 {
        2.0 * PI * PI * self.radius * self.radius * (PI * uv.y).sin().abs()
    }

    /// Whether a point at squared distance `dc2` from the centre is clearly outside the sphere.
    fn is_outside(&self, dc2: f32) -> bool {
        dc2 > self.radius * self.radius * (1.0 + OUTSIDE_MARGIN)
    }
}

impl ShapeGeometry for Sphere {
    fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    fn object_bounds(&self) -> (Vec3, Vec3) {
        (self.center - self.radius, self.center + self.radius)
    }

    fn as_segments(&self) -> Option<Segments<'_>> {
        None
    }

    fn intersect_analytic(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        self.intersect(ray.o, ray.d, t_max)
    }

    fn interaction(
        &self,
        ray: &Ray,
        _primitive: u32,
        hit: &TriangleHit,
        index: u32,
    ) -> SurfaceInteraction {
        self.interaction_at(ray.o, ray.d, hit.t, index)
    }

    /// A uniform point on the whole sphere; pdf per unit area.
    fn sample_area(&self, _u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        Some(SurfaceSample {
            pdf: 1.0 / self.area(),
            ..self.surface_point(sample_uniform_sphere(u))
        })
    }

    /// From outside, the cone the sphere subtends (the lecture's "sample the front-facing
    /// part", pbrt-v4 §6.2.4), so no sample is wasted on the far side; from inside (or on the
    /// surface: a sphere lighting its own inside), None: points are uniform in area.
    fn solid_angle_sampler(&self, reference: Vec3) -> Option<SolidAngleSampler<'_>> {
        let to_center = self.center - reference;
        let dc2 = to_center.length_squared();
        self.is_outside(dc2)
            .then_some(SolidAngleSampler::SphereCone(SphereCone {
                sphere: self,
                to_center,
                dc2,
            }))
    }

    /// The surface point with texture coordinates `uv` in [0, 1]² (the inverse of
    /// [`Self::uv`]), with its [`Self::uv_jacobian`]. The sample's pdf is 0.
    fn at_uv(&self, uv: Vec2) -> Option<(SurfaceSample, f32)> {
        if !(uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0) {
            return None;
        }
        let (sin_phi, cos_phi) = (2.0 * PI * uv.x).sin_cos();
        let (sin_theta, cos_theta) = (PI * uv.y).sin_cos();
        let outward =
            self.rotation * Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
        let sample = SurfaceSample {
            uv,
            ..self.surface_point(outward.normalize())
        };
        Some((sample, self.uv_jacobian(uv)))
    }

    fn uv_jacobian_at(&self, _primitive: u32, uv: Vec2) -> Option<f32> {
        self.at_uv(uv).map(|(_, jacobian)| jacobian)
    }

    fn heap_bytes(&self) -> usize {
        0
    }
}

/// The cone a sphere subtends at a point outside it, sampled uniformly in solid angle.
#[derive(Clone, Copy, Debug)]
pub struct SphereCone<'a> {
    sphere: &'a Sphere,
    /// From the reference point to the centre, and its squared length.
    to_center: Vec3,
    dc2: f32,
}

impl SphereCone<'_> {
    /// A point of the sphere whose direction is uniform in the cone; pdf per unit solid angle.
    pub fn sample(&self, u: Vec2) -> Option<SurfaceSample> {
        let (to_center, dc2, r) = (self.to_center, self.dc2, self.sphere.radius);
        let dc = dc2.sqrt();
        let sin2_max = r * r / dc2;
        let one_minus_cos_max = one_minus_cos(sin2_max);
        // θ within the cone, uniform in solid angle: 1 − cos θ uniform on [0, 1 − cos θmax].
        // Carrying 1 − cos θ (not cos θ) keeps sin²θ = (1 − cos θ)(1 + cos θ) exact for the
        // tiny cones of small or distant spheres, where cos θ rounds to 1.
        let one_minus_cos_theta = one_minus_cos_max * u.x;
        let cos_theta = 1.0 - one_minus_cos_theta;
        let sin2_theta = one_minus_cos_theta * (2.0 - one_minus_cos_theta);
        // α: angle at the centre between the axis back to the reference and the surface point.
        let cos_alpha = sin2_theta / sin2_max.sqrt()
            + cos_theta * (1.0 - sin2_theta / sin2_max).max(0.0).sqrt();
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let frame = Frame::from_normal(-to_center / dc);
        let outward = frame
            .to_world(Vec3::new(
                sin_alpha * phi.cos(),
                sin_alpha * phi.sin(),
                cos_alpha,
            ))
            .normalize();
        Some(SurfaceSample {
            pdf: 1.0 / (2.0 * PI * one_minus_cos_max),
            ..self.sphere.surface_point(outward)
        })
    }

    /// The density of [`Self::sample`], 1 / (2π (1 − cos θ_max)).
    pub fn pdf(&self) -> f32 {
        let r = self.sphere.radius;
        1.0 / (2.0 * PI * one_minus_cos(r * r / self.dc2))
    }
}

/// 1 − cos θ from sin²θ (θ ≤ π/2), as sin²θ / (1 + cos θ): unlike 1 − √(1 − sin²θ), which
/// loses all its digits in single precision below θ ≈ 1.5° (pbrt-v4 §6.2.4 switches to a
/// Taylor series there), this is accurate to a few ulps at every angle.
fn one_minus_cos(sin2: f32) -> f32 {
    sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt())
}

/// Converts a density per unit area at `p` (normal `n`) into one per unit solid angle seen from
/// `reference`: p_ω = p_A · |p − reference|² / |cos θ|; None at grazing angles.
pub fn area_to_solid_angle(pdf_area: f32, reference: Vec3, p: Vec3, n: Vec3) -> Option<f32> {
    let d = p - reference;
    let dist2 = d.length_squared();
    let cos = (d.dot(n) / dist2.sqrt()).abs();
    if !(cos > 0.0) || dist2 == 0.0 {
        return None;
    }
    Some(pdf_area * dist2 / cos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shape::ShapeSampling;

    fn unit_sphere() -> Sphere {
        Sphere {
            center: Vec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
            rotation: Mat3::IDENTITY,
            flip_normals: false,
        }
    }

    #[test]
    fn ray_hits_front_then_back() {
        let s = unit_sphere();
        let t = s.intersect(Vec3::ZERO, Vec3::Z, f32::INFINITY).unwrap();
        assert!((t - 4.0).abs() < 1e-6);
        let si = s.interaction_at(Vec3::ZERO, Vec3::Z, t, 0);
        assert!((si.n + Vec3::Z).length() < 1e-6);
        // From inside, the far wall.
        let t = s
            .intersect(Vec3::new(0.0, 0.0, 5.0), Vec3::Z, f32::INFINITY)
            .unwrap();
        assert!((t - 1.0).abs() < 1e-6);
        assert!(s.intersect(Vec3::ZERO, Vec3::X, f32::INFINITY).is_none());
        // Rays leaving the surface do not hit it again.
        let si = s.interaction_at(Vec3::ZERO, Vec3::Z, 4.0, 0);
        let ray = si.spawn_ray(-Vec3::Z);
        assert!(s.intersect(ray.o, ray.d, f32::INFINITY).is_none());
    }

    /// A point on the inside of a sphere that lights itself sees the whole sphere: for every
    /// light sample cos θ_x cos θ_y A / d² = π exactly, so the irradiance estimate has no variance.
    #[test]
    fn points_on_the_inner_surface_sample_the_whole_sphere() {
        let s = Sphere {
            flip_normals: true,
            ..unit_sphere()
        };
        for k in 0..1000 {
            let u = Vec2::new((k % 31) as f32 / 31.0 + 0.01, (k / 31) as f32 / 33.0 + 0.01);
            let x = s.sample_area(0.5, u).unwrap();
            let v = Vec2::new(
                ((k * 7) % 29) as f32 / 29.0 + 0.02,
                ((k * 3) % 37) as f32 / 37.0 + 0.03,
            );
            let y = s
                .sample_from(x.p, 0.5, v, ShapeSampling::SolidAngle)
                .unwrap();
            let w = (y.p - x.p).normalize();
            let estimate = w.dot(x.n).max(0.0) / y.pdf;
            assert!((estimate - PI).abs() < 1e-2 * PI, "sample {k}: {estimate}");
        }
    }

    #[test]
    fn cone_samples_are_visible_points_on_the_sphere() {
        let s = unit_sphere();
        for (i, reference) in [Vec3::ZERO, Vec3::new(0.0, 0.0, -1e4)]
            .into_iter()
            .enumerate()
        {
            for k in 0..1000 {
                let u = Vec2::new((k % 37) as f32 / 37.0, (k / 37) as f32 / 27.0);
                let sample = s
                    .sample_from(reference, 0.5, u, ShapeSampling::SolidAngle)
                    .unwrap();
                assert!(
                    ((sample.p - s.center).length() - 1.0).abs() < 1e-4,
                    "case {i}"
                );
                // Visible: the normal faces the reference.
                assert!(sample.n.dot(reference - sample.p) >= -1e-3, "case {i}");
                assert!(
                    (s.pdf_from(reference, sample.p, sample.n, ShapeSampling::SolidAngle)
                        - sample.pdf)
                        .abs()
                        <= 1e-6 * sample.pdf
                );
            }
        }
    }
}
