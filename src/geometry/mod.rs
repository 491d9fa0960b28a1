//! Geometry: shapes (triangle meshes, spheres, disks), ray intersection, the BVH, and robust
//! ray offsets.

pub mod accel;
pub mod bvh;
pub mod disk;
#[cfg(feature = "embree")]
pub mod embree;
pub mod instance;
pub mod interaction;
pub mod mesh;
pub mod offset;
pub mod shape;
pub mod sphere;
pub mod triangle;
pub mod triangle_pack;

pub use accel::{Accel, Geometry, Hit};
pub use interaction::SurfaceInteraction;
pub use mesh::{SurfaceSample, TriangleMesh};
pub use shape::Shape;
