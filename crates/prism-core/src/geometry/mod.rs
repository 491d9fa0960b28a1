//! Geometry, in layers: ray–triangle tests, surface interactions and robust ray offsets at the
//! bottom; the shapes (triangle meshes, spheres, disks) above them; then the BVH, the
//! aggregates built with it, instances (shapes in their own space, placed by a moving
//! transform) and the scene's primitives.

pub mod aggregate;
pub mod bvh;
pub mod instance;
pub mod interaction;
pub mod offset;
pub mod primitive;
pub mod shape;
pub mod triangle;
pub mod triangle_pack;

pub use aggregate::{Aggregate, AggregateElement, ExternalRayQueries, Hit};
pub use instance::Instance;
pub use interaction::SurfaceInteraction;
pub use primitive::{Geometry, Primitive};
pub use shape::{Disk, Shape, ShapeGeometry, ShapeSampling, Sphere, SurfaceSample, TriangleMesh};
