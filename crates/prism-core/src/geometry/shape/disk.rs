//! Mitsuba's `disk` shape: the unit disk in the xy plane of its object frame, normal +z.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::mesh::SurfaceSample;
use super::{Segments, ShapeGeometry};
use crate::geometry::interaction::{AttributeValues, SurfaceInteraction};
use crate::geometry::triangle::TriangleHit;
use crate::math::{Frame, Ray, Transform};
use crate::sampling::warp::sample_uniform_disk_concentric;

/// A (possibly elliptic, by a non-uniform `to_world`) disk.
#[derive(Clone, Debug)]
pub struct Disk {
    pub to_world: Transform,
    /// Unit world-space normal (after `flip_normals`).
    pub normal: Vec3,
    area: f32,
}

impl Disk {
    pub fn new(to_world: Transform, flip_normals: bool) -> Disk {
        let n = to_world.normal(Vec3::Z).normalize();
        let area = PI
            * to_world
                .vector(Vec3::X)
                .cross(to_world.vector(Vec3::Y))
                .length();
        Disk {
            to_world,
            normal: if flip_normals { -n } else { n },
            area,
        }
    }

    /// Intersection in the object frame, where the disk is z = 0, x² + y² ≤ 1; t is the same
    /// in both frames because the map is affine.
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let o_local = self.to_world.inverse_point(o);
        let d_local = self.to_world.inverse_vector(d);
        if d_local.z == 0.0 {
            return None;
        }
        let t = -o_local.z / d_local.z;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let p = o_local + d_local * t;
        (p.x * p.x + p.y * p.y <= 1.0).then_some(t)
    }

    pub fn interaction_at(&self, o: Vec3, d: Vec3, t: f32, shape: u32) -> SurfaceInteraction {
        let local = self.to_world.inverse_point(o + d * t);
        let local = Vec3::new(local.x, local.y, 0.0);
        let r = (local.x * local.x + local.y * local.y).sqrt();
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        // (u, v) = (r, φ/2π): ∂p/∂u = (cos φ, sin φ, 0), ∂p/∂v = 2π r (−sin φ, cos φ, 0).
        let (sin_phi, cos_phi) = phi.sin_cos();
        let dp_du = self.to_world.vector(Vec3::new(cos_phi, sin_phi, 0.0));
        let dp_dv = self
            .to_world
            .vector(Vec3::new(-sin_phi, cos_phi, 0.0) * (2.0 * PI * r));
        SurfaceInteraction {
            p: self.to_world.point(local),
            t,
            n: self.normal,
            shading: Frame::from_normal_and_tangent(self.normal, dp_du),
            uv: Vec2::new(r, phi / (2.0 * PI)),
            dp_du,
            dp_dv,
            shape,
            primitive: 0,
            time: 0.0,
            attributes: AttributeValues::default(),
        }
    }

    /// |∂p/∂u × ∂p/∂v| = 2π r |X × Y| = 2 r · area at texture coordinates `uv` (r = u), from the
    /// tangents of [`Self::interaction`] (X, Y: the images of the object frame's x and y axes).
    pub fn uv_jacobian(&self, uv: Vec2) -> f32 {
        2.0 * uv.x.abs() * self.area
    }
}

impl ShapeGeometry for Disk {
    fn area(&self) -> f32 {
        self.area
    }

    fn object_bounds(&self) -> (Vec3, Vec3) {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .into_iter()
            .map(|(x, y)| self.to_world.point(Vec3::new(x, y, 0.0)))
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

    /// A uniform point (a linear map keeps the concentric map's uniformity); pdf per unit area.
    fn sample_area(&self, _u_choice: f32, u: Vec2) -> Option<SurfaceSample> {
        let d = sample_uniform_disk_concentric(u);
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Some(SurfaceSample {
            p: self.to_world.point(Vec3::new(d.x, d.y, 0.0)),
            n: self.normal,
            shading_n: self.normal,
            uv: Vec2::new(d.length(), phi / (2.0 * PI)),
            primitive: 0,
            pdf: 1.0 / self.area,
        })
    }

    /// The surface point with texture coordinates `uv` = (r, φ/2π) in [0, 1]², with its
    /// [`Self::uv_jacobian`]. The sample's pdf is 0.
    fn at_uv(&self, uv: Vec2) -> Option<(SurfaceSample, f32)> {
        if !(uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0) {
            return None;
        }
        let (sin_phi, cos_phi) = (2.0 * PI * uv.y).sin_cos();
        let sample = SurfaceSample {
            p: self
                .to_world
                .point(Vec3::new(uv.x * cos_phi, uv.x * sin_phi, 0.0)),
            n: self.normal,
            shading_n: self.normal,
            uv,
            primitive: 0,
            pdf: 0.0,
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
