//! Mitsuba's `cylinder` shape (`src/shapes/cylinder.cpp`): an open tube without caps. In its
//! object frame it is x² + y² = 1, 0 ≤ z ≤ 1; the scene reader's `to_world` maps that onto the
//! cylinder from `p0` to `p1` of radius `radius` (Mitsuba's translate(p0) · frame(p1 − p0) ·
//! scale(r, r, |p1 − p0|)), then the user's `to_world`. The normal points away from the axis
//! unless `flip_normals`; both sides are hit.
//!
//! Parametrisation as Mitsuba's: (u, v) = (φ/2π, z) with φ = atan2(y, x) in [0, 2π), so
//! ∂p/∂u = 2π (−y, x, 0) and ∂p/∂v = (0, 0, 1) in the object frame.

use std::f32::consts::PI;

use glam::{DVec3, Vec2, Vec3};

use super::mesh::SurfaceSample;
use super::{Segments, ShapeGeometry};
use crate::geometry::interaction::{AttributeValues, SurfaceInteraction};
use crate::geometry::triangle::TriangleHit;
use crate::math::{Frame, Ray, Transform};

/// A circular cylinder (the scene reader allows no transform that would make it elliptic or
/// sheared, so that its area and uniform sampling are exact).
#[derive(Clone, Debug)]
pub struct Cylinder {
    /// Object frame (unit radius, z from 0 to 1) to world.
    pub to_world: Transform,
    pub flip_normals: bool,
    area: f32,
}

impl Cylinder {
    pub fn new(to_world: Transform, flip_normals: bool) -> Cylinder {
        let radius = to_world.vector(Vec3::X).length();
        let length = to_world.vector(Vec3::Z).length();
        Cylinder {
            to_world,
            flip_normals,
            area: 2.0 * PI * radius * length,
        }
    }

    /// Nearest t in (0, t_max) where the ray meets the tube: the roots of
    /// (o_x + t d_x)² + (o_y + t d_y)² = 1 in the object frame (t is the same there, the map
    /// being affine), solved in double precision in the cancellation-free form (pbrt-v4 §6.3),
    /// the nearer first, each kept only if its z lies in [0, 1].
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let o = self.to_world.inverse_point(o).as_dvec3();
        let d = self.to_world.inverse_vector(d).as_dvec3();
        let a = d.x * d.x + d.y * d.y;
        if a == 0.0 {
            return None;
        }
        let b = o.x * d.x + o.y * d.y;
        // The discriminant as a (1 − |o⊥ − (o⊥·d⊥/a) d⊥|²), which keeps its precision for rays
        // far from the axis (as for spheres, Haines et al. 2019).
        let closest_x = o.x - d.x * (b / a);
        let closest_y = o.y - d.y * (b / a);
        let discriminant = a * (1.0 - (closest_x * closest_x + closest_y * closest_y));
        if discriminant < 0.0 {
            return None;
        }
        let q = -(b + discriminant.sqrt().copysign(b));
        if q == 0.0 {
            return None;
        }
        let c = o.x * o.x + o.y * o.y - 1.0;
        let (mut t0, mut t1) = (c / q, q / a);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        let t_max = f64::from(t_max);
        [t0, t1]
            .into_iter()
            .find(|&t| {
                let z = o.z + t * d.z;
                t > 0.0 && t < t_max && (0.0..=1.0).contains(&z)
            })
            .map(|t| t as f32)
    }

    /// The surface interaction at the point hit at distance `t`, projected back onto the tube.
    pub fn interaction_at(&self, o: Vec3, d: Vec3, t: f32, shape: u32) -> SurfaceInteraction {
        let local = self.to_world.inverse_point(o + d * t).as_dvec3();
        let radial = DVec3::new(local.x, local.y, 0.0).normalize_or(DVec3::X);
        let local = Vec3::new(
            radial.x as f32,
            radial.y as f32,
            local.z.clamp(0.0, 1.0) as f32,
        );
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let dp_du = self
            .to_world
            .vector(Vec3::new(-local.y, local.x, 0.0) * (2.0 * PI));
        let dp_dv = self.to_world.vector(Vec3::Z);
        let n = self.normal_at(local);
        SurfaceInteraction {
            p: self.to_world.point(local),
            t,
            n,
            shading: Frame::from_normal_and_tangent(n, dp_du),
            uv: Vec2::new(phi / (2.0 * PI), local.z),
            dp_du,
            dp_dv,
            shape,
            primitive: 0,
            time: 0.0,
            attributes: AttributeValues::default(),
        }
    }

    /// The unit world normal at an object-space point of the tube.
    fn normal_at(&self, local: Vec3) -> Vec3 {
        let n = self
            .to_world
            .normal(Vec3::new(local.x, local.y, 0.0))
            .normalize();
        if self.flip_normals { -n } else { n }
    }

    /// The point with texture coordinates `uv` (φ = 2π u, z = v in the object frame).
    fn point_at_uv(&self, uv: Vec2, pdf: f32) -> SurfaceSample {
        let (sin_phi, cos_phi) = (2.0 * PI * uv.x).sin_cos();
        let local = Vec3::new(cos_phi, sin_phi, uv.y);
        let n = self.normal_at(local);
        SurfaceSample {
            p: self.to_world.point(local),
            n,
            shading_n: n,
            uv,
            primitive: 0,
            pdf,
        }
    }
}

impl ShapeGeometry for Cylinder {
    /// 2π r L.
    fn area(&self) -> f32 {
        self.area
    }

    fn object_bounds(&self) -> (Vec3, Vec3) {
        (0..8)
            .map(|corner| {
                let bit = |b: u32| if corner & (1 << b) != 0 { 1.0 } else { 0.0 };
                let x = 2.0 * bit(0) - 1.0;
                let y = 2.0 * bit(1) - 1.0;
                self.to_world.point(Vec3::new(x, y, bit(2)))
            })
            .fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), p| (lo.min(p), hi.max(p)),
            )
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

    /// A uniform point: (u, v) uniform, which a similarity of the tube keeps uniform in area;
    /// pdf 1/(2π r L) per unit area.
    fn sample_area(&self, _u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        Some(self.point_at_uv(u, 1.0 / self.area))
    }

    /// The point at `uv` in [0, 1]² and |∂p/∂u × ∂p/∂v| = 2π r L there (Mitsuba's
    /// `eval_parameterization`); None outside [0, 1]².
    fn at_uv(&self, uv: Vec2) -> Option<(SurfaceSample, f32)> {
        if !(uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0) {
            return None;
        }
        Some((self.point_at_uv(uv, 0.0), self.area))
    }

    fn uv_jacobian_at(&self, _primitive: u32, uv: Vec2) -> Option<f32> {
        self.at_uv(uv).map(|(_, jacobian)| jacobian)
    }

    fn heap_bytes(&self) -> usize {
        0
    }
}
