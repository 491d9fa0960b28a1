//! Vectors, matrices, shading frames, transforms and rays, and numerical integration.
//!
//! Geometry is single precision (as in Mitsuba 3's scalar variants and pbrt-v4); transforms are
//! composed in double precision by the scene reader and rounded once.

pub mod animated;
pub mod frame;
pub mod lanes;
pub mod quadrature;
pub mod ray;
pub mod special;
pub mod transform;

pub use animated::AnimatedTransform;
pub use frame::Frame;
pub use glam::{DMat4, DVec3, Mat3, Mat4, UVec2, Vec2, Vec3, Vec4};
pub use ray::Ray;
pub use transform::Transform;
