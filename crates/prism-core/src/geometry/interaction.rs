//! The record of a ray hitting a surface.

use glam::{Vec2, Vec3};

use super::offset::offset_ray_origin;
use crate::math::{Frame, Ray};

/// How many distinct mesh attributes (Mitsuba's `vertex_color`, `face_color`, ...) the textures
/// of one scene may read.
pub const MAX_MESH_ATTRIBUTES: usize = 4;

/// Mesh attribute values at a surface point (a colour: linear RGB), by the slot the scene gave
/// each attribute name.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AttributeValues(pub [Vec3; MAX_MESH_ATTRIBUTES]);

/// A point on a surface where a ray arrived, with its local geometry.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    /// The point, on the surface up to rounding.
    pub p: Vec3,
    /// Distance along the ray (in units of the ray direction's length).
    pub t: f32,
    /// Unit geometric normal (the side a shape calls "outside", flipped by `flip_normals`).
    pub n: Vec3,
    /// Shading frame: the interpolated normal for smooth meshes, else the geometric one.
    pub shading: Frame,
    /// Surface parametrisation.
    pub uv: Vec2,
    /// ∂p/∂u and ∂p/∂v (not normalised): the tangents of the parametrisation, which orient
    /// anisotropic BSDFs and bump maps. The shading frame's first axis follows ∂p/∂u.
    pub dp_du: Vec3,
    pub dp_dv: Vec3,
    /// Index of the shape in the scene.
    pub shape: u32,
    /// Index of the primitive within the shape (triangle index; 0 for analytic shapes).
    pub primitive: u32,
    /// The time of the ray that found the point; rays leaving it keep it.
    pub time: f32,
    /// The mesh attributes that the scene's textures read, interpolated at the point (zero
    /// for shapes without them).
    pub attributes: AttributeValues,
}

impl SurfaceInteraction {
    /// A ray leaving the surface in direction `d`, starting just off the surface on the side
    /// `d` points to.
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        let n = if d.dot(self.n) >= 0.0 {
            self.n
        } else {
            -self.n
        };
        Ray::new(offset_ray_origin(self.p, n), d, f32::INFINITY, self.time)
    }

    /// A shadow ray from this surface to the point `target` on another surface with geometric
    /// normal `target_n`; both ends are moved off their surfaces, and the ray stops short of
    /// the target (t < 1 − ε) so that the target itself is never reported as an occluder.
    pub fn spawn_ray_to(&self, target: Vec3, target_n: Vec3) -> Ray {
        let d = target - self.p;
        let n = if d.dot(self.n) >= 0.0 {
            self.n
        } else {
            -self.n
        };
        let origin = offset_ray_origin(self.p, n);
        let end = if target_n == Vec3::ZERO {
            target
        } else {
            let m = if d.dot(target_n) <= 0.0 {
                target_n
            } else {
                -target_n
            };
            offset_ray_origin(target, m)
        };
        Ray::new(origin, end - origin, 1.0 - SHADOW_EPSILON, self.time)
    }
}

/// Fraction of a shadow ray's length left unchecked at its end (pbrt-v4's ShadowEpsilon).
pub const SHADOW_EPSILON: f32 = 1e-4;
