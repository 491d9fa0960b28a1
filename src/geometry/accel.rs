//! Ray queries against all shapes of a scene through a compressed 8-wide BVH, or through Embree
//! for comparison (cargo feature `embree`, see [`super::embree`]).
//!
//! The hierarchy is built by the `obvhs` crate: PLOC clustering (Meister & Bittner 2018) refined
//! by parallel reinsertion under the SAH cost (Meister & Bittner 2017), then collapsed into the
//! compressed wide BVH of Ylitie et al. 2017 with 8 children per node, traversed four children at
//! a time with SIMD. Triangles are stored with their vertices in leaf order for locality;
//! analytic shapes (spheres, disks) and moving shapes (with their own hierarchy, see
//! [`super::instance`]) are single primitives.

use std::str::FromStr;
use std::time::Duration;

use glam::Vec3;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;

use super::interaction::SurfaceInteraction;
use super::shape::Shape;
use super::triangle::{TriangleHit, WatertightRay};
use crate::error::Result;
use crate::math::Ray;

/// Which structure answers the ray queries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Accel {
    /// Our compressed wide BVH.
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

/// A BVH primitive: one triangle, or a whole analytic shape.
#[derive(Clone, Copy, Debug)]
enum Primitive {
    Triangle {
        vertices: [Vec3; 3],
        shape: u32,
        index: u32,
    },
    Analytic {
        shape: u32,
    },
}

/// The scene's shapes and the hierarchy over them.
#[derive(Clone, Debug)]
pub struct Geometry {
    pub shapes: Vec<Shape>,
    bvh: Option<CwBvh>,
    /// Primitives in BVH leaf order (the builder's index map applied, then dropped).
    primitives: Vec<Primitive>,
    /// The same shapes in Embree, which then answers the queries instead of `bvh`.
    #[cfg(feature = "embree")]
    embree: Option<super::embree::EmbreeScene>,
}

fn to_obvhs(v: Vec3) -> glam::Vec3A {
    glam::Vec3A::new(v.x, v.y, v.z)
}

impl Geometry {
    /// Builds the hierarchy over all shapes.
    pub fn new(shapes: Vec<Shape>) -> Geometry {
        let mut primitives = Vec::new();
        let mut bounds = Vec::new();
        for (shape_index, shape) in shapes.iter().enumerate() {
            let shape_index = shape_index as u32;
            match shape {
                Shape::Mesh(mesh) => {
                    for i in 0..mesh.triangles.len() {
                        if mesh.triangle_area(i) == 0.0 {
                            continue;
                        }
                        let vertices = mesh.vertices(i);
                        let mut aabb = Aabb::from_point(to_obvhs(vertices[0]));
                        aabb.extend(to_obvhs(vertices[1]));
                        aabb.extend(to_obvhs(vertices[2]));
                        bounds.push(aabb);
                        primitives.push(Primitive::Triangle {
                            vertices,
                            shape: shape_index,
                            index: i as u32,
                        });
                    }
                }
                Shape::Sphere(_) | Shape::Disk(_) | Shape::Instance(_) => {
                    let (lo, hi) = shape.object_bounds();
                    bounds.push(Aabb::new(to_obvhs(lo), to_obvhs(hi)));
                    primitives.push(Primitive::Analytic { shape: shape_index });
                }
            }
        }
        if primitives.is_empty() {
            return Geometry {
                shapes,
                bvh: None,
                primitives,
                #[cfg(feature = "embree")]
                embree: None,
            };
        }
        let bvh = build_cwbvh(
            &bounds,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let mut bvh = bvh;
        let primitives = bvh
            .primitive_indices
            .iter()
            .map(|&i| primitives[i as usize])
            .collect();
        // Leaves now address `primitives` directly: the index map is not needed any more, and
        // the builder's spare capacity is given back.
        bvh.primitive_indices = Vec::new();
        bvh.nodes.shrink_to_fit();
        Geometry {
            shapes,
            bvh: Some(bvh),
            primitives,
            #[cfg(feature = "embree")]
            embree: None,
        }
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
        self.primitives.len()
    }

    /// Bytes of memory held by the shapes and the hierarchy: meshes' vertex attributes and
    /// indices, the BVH nodes, and the primitives in leaf order. Counted from the data
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
        let bvh = self.bvh.as_ref().map_or(0, |bvh| {
            bvh.nodes.capacity() * size_of::<obvhs::cwbvh::node::CwBvhNode>()
                + bvh.primitive_indices.capacity() * size_of::<u32>()
        });
        size_of::<Geometry>() + shapes + bvh + self.primitives.capacity() * size_of::<Primitive>()
    }

    /// The axis-aligned box (min, max) around all shapes; None for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let aabb = self.bvh.as_ref()?.total_aabb;
        Some((Vec3::from(aabb.min), Vec3::from(aabb.max)))
    }

    fn bvh_ray(ray: &Ray) -> obvhs::ray::Ray {
        obvhs::ray::Ray::new(to_obvhs(ray.o), to_obvhs(ray.d), 0.0, ray.t_max)
    }

    /// The hit of the ray with leaf primitive `id` in (0, t_max); barycentrics are zero for
    /// analytic shapes.
    #[inline]
    fn hit_primitive(
        &self,
        id: usize,
        ray: &Ray,
        watertight: &WatertightRay,
        t_max: f32,
    ) -> Option<TriangleHit> {
        match &self.primitives[id] {
            Primitive::Triangle { vertices, .. } => {
                watertight.intersect(t_max, vertices[0], vertices[1], vertices[2])
            }
            Primitive::Analytic { shape } => self.shapes[*shape as usize]
                .intersect_analytic(ray, t_max)
                .map(|t| TriangleHit {
                    t,
                    b0: 0.0,
                    b1: 0.0,
                    b2: 0.0,
                }),
        }
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
        let mut closest: Option<(usize, TriangleHit)> = None;
        let mut hit = obvhs::ray::RayHit::none();
        let watertight = WatertightRay::new(ray.o, ray.d);
        bvh.ray_traverse(Self::bvh_ray(ray), &mut hit, |bvh_ray, id| {
            let t_max = bvh_ray.tmax;
            match self.hit_primitive(id, ray, &watertight, t_max) {
                Some(h) if h.t < t_max => {
                    closest = Some((id, h));
                    h.t
                }
                _ => f32::INFINITY,
            }
        });
        let (id, triangle) = closest?;
        let (shape, primitive) = match self.primitives[id] {
            Primitive::Triangle { shape, index, .. } => (shape, index),
            Primitive::Analytic { shape } => (shape, 0),
        };
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
        !bvh.ray_traverse_miss(Self::bvh_ray(ray), |bvh_ray, id| {
            self.hit_primitive(id, ray, &watertight, bvh_ray.tmax)
                .map_or(f32::INFINITY, |h| h.t)
        })
    }
}
