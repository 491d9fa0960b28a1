//! Ray queries against all shapes of a scene through our 8-wide BVH ([`super::bvh`]), or
//! through Embree for comparison (cargo feature `embree`, see [`super::embree`]).
//!
//! Every triangle of every mesh, and every analytic shape (sphere, disk, moving shape with its
//! own hierarchy, see [`super::instance`]), is one primitive of the hierarchy. Primitives are
//! numbered shape after shape: shape s owns the ids `first_id[s]..first_id[s + 1]`, a triangle's
//! id being its shape's first id plus its index in the mesh, so a hit names its shape and
//! triangle without a table per triangle.

use super::bvh::{BuildPrimitive, Bvh, PrimitiveKind};
use super::interaction::SurfaceInteraction;
use super::shape::Shape;
use super::triangle::{TriangleHit, WatertightRay};
use crate::error::Result;
use crate::math::Ray;
use glam::Vec3;
use std::str::FromStr;

/// Which structure answers the ray queries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Accel {
    /// Our wide BVH ([`super::bvh`]).
    #[default]
    Bvh,
    /// Embree 3's BVH (only in builds with the cargo feature `embree`).
    Embree,
}

impl Accel {
    /// Whether this build can use the structure: Embree needs the cargo feature `embree`.
    pub fn check_available(self) -> Result<()> {
        if self == Accel::Embree && !cfg!(feature = "embree") {
            return Err(crate::error::Error::usage(
                "this prism was built without Embree, so --accel embree is not available",
            )
            .with_help(
                "run tools/install-embree, then rebuild with `cargo build --release --features embree`",
            ));
        }
        Ok(())
    }
}

impl FromStr for Accel {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Accel, String> {
        match text {
            "bvh" => Ok(Accel::Bvh),
            "embree" => Ok(Accel::Embree),
            _ => Err(format!(
                "unknown acceleration structure \"{text}\": expected bvh or embree"
            )),
        }
    }
}

/// The closest hit along a ray, before its surface interaction is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Index into [`Geometry::shapes`].
    pub shape: u32,
    /// Index of the triangle in its mesh; 0 for analytic shapes.
    pub primitive: u32,
    /// The ray parameter, and for triangles the barycentric coordinates of the point (zero for
    /// analytic shapes).
    pub triangle: TriangleHit,
}

/// The scene's shapes and the hierarchy over them.
#[derive(Clone, Debug)]
pub struct Geometry {
    pub shapes: Vec<Shape>,
    bvh: Option<Bvh>,
    /// The first primitive id of each shape, and one past the last id at the end.
    first_id: Vec<u32>,
    /// Primitives in the hierarchy (triangles of non-zero area, and analytic shapes).
    primitive_count: usize,
    /// The same shapes in Embree, which then answers the queries instead of `bvh`.
    #[cfg(feature = "embree")]
    embree: Option<super::embree::EmbreeScene>,
}

impl Geometry {
    /// Builds the hierarchy over all shapes. Panics beyond 2³² primitives, 2³⁰ for the id of
    /// an analytic shape, or 2.7·10⁸ triangles (2²⁶ packs of the BVH): far more than fits in
    /// memory.
    pub fn new(shapes: Vec<Shape>) -> Geometry {
        let mut primitives = Vec::new();
        let mut first_id = Vec::with_capacity(shapes.len() + 1);
        let mut next_id = 0u64;
        for shape in &shapes {
            first_id.push(next_id as u32);
            match shape {
                Shape::Mesh(mesh) => {
                    for i in 0..mesh.triangles().len() {
                        // Degenerate triangles are left out: no ray can hit them.
                        if mesh.triangle_area(i) == 0.0 {
                            continue;
                        }
                        primitives.push(BuildPrimitive {
                            id: (next_id + i as u64) as u32,
                            kind: PrimitiveKind::Triangle(mesh.vertices(i)),
                        });
                    }
                    next_id += mesh.triangles().len() as u64;
                }
                Shape::Sphere(_) | Shape::Disk(_) | Shape::Instance(_) => {
                    let (lo, hi) = shape.object_bounds();
                    primitives.push(BuildPrimitive {
                        id: next_id as u32,
                        kind: PrimitiveKind::Analytic { lo, hi },
                    });
                    next_id += 1;
                }
            }
            assert!(
                next_id < u32::MAX as u64,
                "more than 2³² primitives in one scene"
            );
        }
        first_id.push(next_id as u32);
        Geometry {
            shapes,
            bvh: Bvh::build(&primitives),
            first_id,
            primitive_count: primitives.len(),
            #[cfg(feature = "embree")]
            embree: None,
        }
    }

    /// The shape and, for a mesh, the triangle of primitive `id`.
    #[inline]
    fn shape_of(&self, id: u32) -> (u32, u32) {
        let shape = self.first_id.partition_point(|&first| first <= id) - 1;
        (shape as u32, id - self.first_id[shape])
    }

    /// Chooses the structure that answers the queries; Embree's is built here (the BVH is kept,
    /// so that both can be compared on the same geometry). Moving shapes keep their own BVH
    /// either way. Without the cargo feature `embree`, asking for Embree is an error.
    pub fn set_accel(&mut self, accel: Accel) -> Result<()> {
        accel.check_available()?;
        #[cfg(feature = "embree")]
        match accel {
            Accel::Bvh => self.embree = None,
            Accel::Embree if self.embree.is_none() => {
                self.embree = Some(super::embree::EmbreeScene::new(&self.shapes)?);
            }
            Accel::Embree => {}
        }
        Ok(())
    }

    /// The structure that answers the queries.
    pub fn accel(&self) -> Accel {
        #[cfg(feature = "embree")]
        if self.embree.is_some() {
            return Accel::Embree;
        }
        Accel::Bvh
    }

    /// The number of BVH primitives (triangles plus analytic shapes).
    pub fn primitive_count(&self) -> usize {
        self.primitive_count
    }

    /// Bytes of memory held by the shapes and the hierarchy: meshes' vertex attributes and
    /// indices, and the BVH's nodes and triangle packs. Counted from the data
    /// structures' capacities, so it does not depend on the allocator.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let shapes: usize = self
            .shapes
            .iter()
            .map(|shape| {
                size_of::<Shape>()
                    + match shape {
                        Shape::Mesh(mesh) => mesh.heap_bytes(),
                        Shape::Instance(instance) => instance.object.memory_bytes(),
                        Shape::Sphere(_) | Shape::Disk(_) => 0,
                    }
            })
            .sum();
        let bvh = self.bvh.as_ref().map_or(0, Bvh::memory_bytes);
        size_of::<Geometry>() + shapes + bvh + self.first_id.capacity() * size_of::<u32>()
    }

    /// The axis-aligned box (min, max) around all shapes; None for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bvh.as_ref().map(Bvh::bounds)
    }

    /// Intersects the analytic shape of primitive `id` (its whole shape) in (0, t_max).
    #[inline]
    fn analytic_hit(&self, ray: &Ray, id: u32, t_max: f32) -> Option<f32> {
        let (shape, _) = self.shape_of(id);
        self.shapes[shape as usize].intersect_analytic(ray, t_max)
    }

    /// The closest hit in (0, t_max), found by the chosen structure.
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        #[cfg(feature = "embree")]
        if let Some(embree) = &self.embree {
            return embree.closest_hit(&self.shapes, ray);
        }
        self.bvh_closest_hit(ray)
    }

    fn bvh_closest_hit(&self, ray: &Ray) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let watertight = WatertightRay::new(ray.o, ray.d);
        let (id, triangle) = bvh.closest_hit(ray, &watertight, |id, t_max| {
            self.analytic_hit(ray, id, t_max)
        })?;
        let (shape, primitive) = self.shape_of(id);
        Some(Hit {
            shape,
            primitive,
            triangle,
        })
    }

    /// The closest surface the ray meets in (0, t_max).
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        let hit = self.closest_hit(ray)?;
        let shape = hit.shape;
        let mut si = match &self.shapes[shape as usize] {
            Shape::Mesh(mesh) => mesh.interaction(hit.primitive as usize, &hit.triangle, shape),
            Shape::Sphere(sphere) => sphere.interaction(ray.o, ray.d, hit.triangle.t, shape),
            Shape::Disk(disk) => disk.interaction(ray.o, ray.d, hit.triangle.t, shape),
            // The same query again, now keeping the object's interaction.
            Shape::Instance(instance) => instance.interaction(ray, ray.t_max, shape)?,
        };
        si.time = ray.time;
        Some(si)
    }

    /// Whether anything blocks the ray in (0, t_max).
    pub fn occluded(&self, ray: &Ray) -> bool {
        #[cfg(feature = "embree")]
        if let Some(embree) = &self.embree {
            return embree.occluded(&self.shapes, ray);
        }
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let watertight = WatertightRay::new(ray.o, ray.d);
        bvh.occluded(ray, &watertight, |id, t_max| {
            self.analytic_hit(ray, id, t_max)
        })
    }
}
