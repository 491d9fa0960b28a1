//! Mitsuba's `ellipsoids` shape (`src/shapes/ellipsoids.cpp`, Condor et al. 2024, "Don't
//! Splat your Gaussians"): a cloud of anisotropic ellipsoids, each given by its centre c, its
//! radii s (Mitsuba's scales times the shape's extent) and a rotation R, the set
//! {c + R S x : |x| = 1} with S = diag(s). Each ellipsoid is one primitive of the hierarchy,
//! bounded by the box c ± (|R₀·s|, |R₁·s|, |R₂·s|) (Rᵢ the rows of R scaled by s, as Mitsuba).
//!
//! Intersection as Mitsuba's, exact: in the ellipsoid's unit-sphere space, o' = S⁻¹ Rᵀ (o − c)
//! and d' = S⁻¹ Rᵀ d, the ray meets |o' + t d'| = 1 at the roots of a quadratic (solved in
//! double precision, the discriminant in Haines et al.'s precise form). Back faces are culled
//! as in Mitsuba: a ray whose origin lies inside an ellipsoid does not hit it. The normal is the
//! gradient of the implicit form, n ∝ R S⁻² Rᵀ (p − c) (Mitsuba's
//! `normalize(rot * (local / scale²))`), which is also the shading normal.
//!
//! As in Mitsuba the shape has no parametrisation (uv = 0) and no sampling of its surface, so
//! it cannot be an area light; its tangents are those of the frame around the normal.

use glam::{DVec3, Mat3, Vec2, Vec3};

use super::{Segments, ShapeGeometry};
use crate::geometry::interaction::{AttributeValues, SurfaceInteraction};
use crate::geometry::triangle::TriangleHit;
use crate::math::{Frame, Ray};

/// One ellipsoid: the set {center + rotation · diag(radii) · x : |x| = 1}.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    pub center: Vec3,
    /// The semi-axes' lengths along the rotation's columns, each positive and finite.
    pub radii: Vec3,
    /// Object to world rotation, orthonormal columns.
    pub rotation: Mat3,
}

impl Ellipsoid {
    /// The rotation of the unit quaternion (x, y, z, w) (Mitsuba's `quat_to_matrix`).
    pub fn rotation_of_quaternion(x: f32, y: f32, z: f32, w: f32) -> Mat3 {
        Mat3::from_quat(glam::Quat::from_xyzw(x, y, z, w))
    }

    /// The axis-aligned box around the ellipsoid: c ± sqrt(Σⱼ (R_ij s_j)²) per axis i.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let m = self.rotation * Mat3::from_diagonal(self.radii);
        let row = |i: usize| Vec3::new(m.x_axis[i], m.y_axis[i], m.z_axis[i]).length();
        let delta = Vec3::new(row(0), row(1), row(2));
        (self.center - delta, self.center + delta)
    }

    /// `p` in the ellipsoid's unit-sphere space, S⁻¹ Rᵀ (p − c), in double precision.
    fn in_unit_sphere_space(&self, v: DVec3) -> DVec3 {
        self.rotation.as_dmat3().transpose() * v / self.radii.as_dvec3()
    }

    /// The nearest t in (0, t_max) where the ray meets the ellipsoid from outside; None when
    /// it misses, or when its origin is inside (back faces are culled, as in Mitsuba).
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let f = self.in_unit_sphere_space(o.as_dvec3() - self.center.as_dvec3());
        let d = self.in_unit_sphere_space(d.as_dvec3());
        let a = d.dot(d);
        if !(a > 0.0) {
            return None;
        }
        let b = f.dot(d);
        // Haines et al. 2019, "Precision Improvements for Ray/Sphere Intersection": the
        // discriminant as a (1 − |f − (b/a) d|²).
        let closest = f - d * (b / a);
        let discriminant = a * (1.0 - closest.dot(closest));
        if discriminant < 0.0 {
            return None;
        }
        let q = -(b + discriminant.sqrt().copysign(b));
        if q == 0.0 {
            return None;
        }
        let c = f.dot(f) - 1.0;
        let near = (c / q).min(q / a);
        (near > 0.0 && near < f64::from(t_max)).then_some(near as f32)
    }

    /// The point of the ellipsoid nearest to `hit` along its radial line and the unit outward
    /// normal there, R S⁻¹ x / |R S⁻¹ x| with x the point on the unit sphere.
    pub fn surface_at(&self, hit: Vec3) -> (Vec3, Vec3) {
        let x = self
            .in_unit_sphere_space(hit.as_dvec3() - self.center.as_dvec3())
            .normalize_or(DVec3::Z);
        let rotation = self.rotation.as_dmat3();
        let radii = self.radii.as_dvec3();
        let p = self.center.as_dvec3() + rotation * (x * radii);
        let n = (rotation * (x / radii)).normalize();
        (p.as_vec3(), n.as_vec3())
    }
}

/// A set of ellipsoids, one primitive of the hierarchy each.
#[derive(Clone, Debug)]
pub struct Ellipsoids {
    ellipsoids: Vec<Ellipsoid>,
}

impl Ellipsoids {
    /// The ellipsoids; None when there are none, or one has a radius that is not positive and
    /// finite, a centre that is not finite or a rotation whose columns are not orthonormal.
    pub fn new(ellipsoids: Vec<Ellipsoid>) -> Option<Ellipsoids> {
        let valid = |e: &Ellipsoid| {
            e.center.is_finite()
                && e.radii.is_finite()
                && e.radii.min_element() > 0.0
                && e.rotation.is_finite()
                && (e.rotation.transpose() * e.rotation).abs_diff_eq(Mat3::IDENTITY, 1e-4)
        };
        (!ellipsoids.is_empty() && ellipsoids.iter().all(valid))
            .then_some(Ellipsoids { ellipsoids })
    }

    /// The ellipsoids, in the order given.
    pub fn ellipsoids(&self) -> &[Ellipsoid] {
        &self.ellipsoids
    }

    /// The number of ellipsoids (primitives of the hierarchy).
    pub fn count(&self) -> usize {
        self.ellipsoids.len()
    }

    /// The bounds of ellipsoid `i`.
    pub fn ellipsoid_bounds(&self, i: usize) -> (Vec3, Vec3) {
        self.ellipsoids[i].bounds()
    }

    /// The nearest front-face hit in (0, t_max) on ellipsoid `i`.
    pub fn intersect_ellipsoid(&self, i: usize, ray: &Ray, t_max: f32) -> Option<f32> {
        self.ellipsoids[i].intersect(ray.o, ray.d, t_max)
    }

    /// The ellipsoid `ray` hits first in (0, t_max), with the distance.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(usize, f32)> {
        let mut best: Option<(usize, f32)> = None;
        for i in 0..self.ellipsoids.len() {
            let limit = best.map_or(t_max, |(_, t)| t);
            if let Some(t) = self.intersect_ellipsoid(i, ray, limit) {
                best = Some((i, t));
            }
        }
        best
    }

    /// The surface interaction of a hit at distance `t` on ellipsoid `i`, recorded as shape
    /// `index`.
    fn interaction_on(&self, ray: &Ray, i: u32, t: f32, index: u32) -> SurfaceInteraction {
        let (p, n) = self.ellipsoids[i as usize].surface_at(ray.at(t));
        let frame = Frame::from_normal(n);
        SurfaceInteraction {
            p,
            t,
            n,
            shading: frame,
            uv: Vec2::ZERO,
            dp_du: frame.s,
            dp_dv: frame.t,
            shape: index,
            primitive: i,
            time: 0.0,
            attributes: AttributeValues::default(),
        }
    }
}

impl ShapeGeometry for Ellipsoids {
    /// No area: Mitsuba's ellipsoids have no surface sampling, so they cannot emit.
    fn area(&self) -> f32 {
        0.0
    }

    /// The bounds of all ellipsoids.
    fn object_bounds(&self) -> (Vec3, Vec3) {
        self.ellipsoids.iter().map(Ellipsoid::bounds).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
        )
    }

    fn as_segments(&self) -> Option<Segments<'_>> {
        Some(Segments::Ellipsoids(self))
    }

    fn intersect_analytic(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        self.intersect(ray, t_max).map(|(_, t)| t)
    }

    /// On the ellipsoid named, if the ray hits it at `hit.t`; else on the one the ray hits
    /// first (a structure that intersects the shape as a whole does not name it).
    fn interaction(
        &self,
        ray: &Ray,
        primitive: u32,
        hit: &TriangleHit,
        index: u32,
    ) -> SurfaceInteraction {
        let named = (primitive as usize) < self.ellipsoids.len()
            && self
                .intersect_ellipsoid(primitive as usize, ray, f32::INFINITY)
                .is_some_and(|t| t == hit.t);
        let ellipsoid = if named {
            primitive
        } else {
            self.intersect(ray, f32::INFINITY)
                .map_or(0, |(found, _)| found as u32)
        };
        self.interaction_on(ray, ellipsoid, hit.t, index)
    }

    fn heap_bytes(&self) -> usize {
        self.ellipsoids.capacity() * std::mem::size_of::<Ellipsoid>()
    }
}
