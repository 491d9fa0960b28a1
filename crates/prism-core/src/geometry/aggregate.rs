//! Ray queries against a set of primitives through our 8-wide BVH ([`super::bvh`]), or through
//! another structure plugged in from outside (the command line's Embree comparison).
//!
//! An aggregate holds either shapes (the object space of an instance) or the scene's
//! primitives (shapes and instances); what it needs of them is [`AggregateElement`]. Every
//! triangle of every mesh, and every element intersected as a whole (sphere, disk, instance),
//! is one primitive of the hierarchy. Primitives are numbered element after element: element s
//! owns the ids `first_id[s]..first_id[s + 1]`, a triangle's id being its element's first id
//! plus its index in the mesh, so a hit names its element and triangle without a table per
//! triangle.

use std::fmt::Debug;
use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::Vec3;

use super::bvh::{BuildPrimitive, Bvh, MAX_INTERLEAVED, PrimitiveKind, PrimitivePlaces};
use super::interaction::SurfaceInteraction;
use super::shape::{Shape, ShapeGeometry, TriangleMesh};
use super::triangle::{TriangleHit, WatertightRay};
use crate::math::Ray;

/// What an aggregate needs to know of the things it holds.
pub trait AggregateElement {
    /// The mesh whose triangles enter the hierarchy one by one; None for an element that is
    /// intersected as a whole by [`Self::intersect_whole`].
    fn mesh(&self) -> Option<&TriangleMesh>;
    /// The bounds of an element intersected as a whole (for a moving one: its sweep).
    fn bounds(&self) -> (Vec3, Vec3);
    /// Distance to the nearest hit in (0, t_max) of an element intersected as a whole.
    fn intersect_whole(&self, ray: &Ray, t_max: f32) -> Option<f32>;
    /// The surface interaction of a hit on this element, recorded as element `hit.shape`.
    fn interaction(&self, ray: &Ray, hit: &Hit) -> Option<SurfaceInteraction>;
    /// Bytes of heap memory the element holds.
    fn heap_bytes(&self) -> usize;
    /// The number of parts (curve segments) of an element that enters the hierarchy part by
    /// part, each intersected by [`Self::intersect_part`]; None for other elements.
    fn part_count(&self) -> Option<usize> {
        None
    }
    /// The bounds of part `part` of an element made of parts.
    fn part_bounds(&self, _part: u32) -> (Vec3, Vec3) {
        self.bounds()
    }
    /// Distance to the nearest hit in (0, t_max) on part `part` (0 for an element intersected
    /// as a whole).
    fn intersect_part(&self, ray: &Ray, _part: u32, t_max: f32) -> Option<f32> {
        self.intersect_whole(ray, t_max)
    }
}

/// Ray queries answered by a structure other than our BVH, over the same elements.
pub trait ExternalRayQueries<P>: Send + Sync + Debug {
    /// The closest hit in (0, t_max) among `elements`, those the structure was built from.
    fn closest_hit(&self, elements: &[P], ray: &Ray) -> Option<Hit>;
    /// Whether anything among `elements` blocks the ray in (0, t_max).
    fn occluded(&self, elements: &[P], ray: &Ray) -> bool;
    /// The structure's name, for messages ("Embree").
    fn name(&self) -> &'static str;
}

/// The closest hit along a ray, before its surface interaction is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Index into [`Aggregate::primitives`].
    pub shape: u32,
    /// Index of the triangle in its mesh; 0 for elements intersected as a whole.
    pub primitive: u32,
    /// The ray parameter, and for triangles the barycentric coordinates of the point (zero for
    /// elements intersected as a whole).
    pub triangle: TriangleHit,
}

/// Elements and the hierarchy over them.
#[derive(Clone, Debug)]
pub struct Aggregate<P> {
    pub primitives: Vec<P>,
    bvh: Option<Bvh>,
    /// The first primitive id of each element, and one past the last id at the end.
    first_id: Vec<u32>,
    /// Primitives in the hierarchy (triangles of non-zero area, and whole elements).
    primitive_count: usize,
    /// Another structure that answers the queries instead of `bvh`.
    external: Option<Arc<dyn ExternalRayQueries<P>>>,
    /// How long building (or refitting) the hierarchy took.
    build_time: Duration,
    /// Whether the hierarchy was refit to moved elements ([`Aggregate::refit`]) rather than
    /// built.
    refit: bool,
}

impl<P: AggregateElement> Aggregate<P> {
    /// Builds the hierarchy over all elements. Panics beyond 2³² primitives, 2³⁰ for the id of
    /// an element intersected whole, or 2.7·10⁸ triangles (2²⁶ packs of the BVH): far more
    /// than fits in memory.
    pub fn new(primitives: Vec<P>) -> Aggregate<P> {
        let start = Instant::now();
        let mut build = Vec::new();
        let mut first_id = Vec::with_capacity(primitives.len() + 1);
        let mut next_id = 0u64;
        for element in &primitives {
            first_id.push(next_id as u32);
            match element.mesh() {
                Some(mesh) => {
                    for i in 0..mesh.triangles().len() {
                        // Degenerate triangles are left out: no ray can hit them.
                        if mesh.triangle_area(i) == 0.0 {
                            continue;
                        }
                        build.push(BuildPrimitive {
                            id: (next_id + i as u64) as u32,
                            kind: PrimitiveKind::Triangle(mesh.vertices(i)),
                        });
                    }
                    next_id += mesh.triangles().len() as u64;
                }
                None if element.part_count().is_some() => {
                    let parts = element.part_count().unwrap_or(0);
                    for i in 0..parts {
                        let (lo, hi) = element.part_bounds(i as u32);
                        build.push(BuildPrimitive {
                            id: (next_id + i as u64) as u32,
                            kind: PrimitiveKind::Analytic { lo, hi },
                        });
                    }
                    next_id += parts as u64;
                }
                None => {
                    let (lo, hi) = element.bounds();
                    build.push(BuildPrimitive {
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
        let bvh = Bvh::build(&build);
        Aggregate {
            primitives,
            bvh,
            first_id,
            primitive_count: build.len(),
            external: None,
            build_time: start.elapsed(),
            refit: false,
        }
    }

    /// The aggregate over `primitives`, this aggregate's elements moved or reshaped in place
    /// (a shape's transform or radius changed): its hierarchy refit ([`Bvh::refit`]) when the
    /// elements give the same primitives as before (the same meshes' triangles, the same ones
    /// degenerate, as many parts) and the refit tree is not too costly; otherwise built anew,
    /// as [`Self::new`] builds it. The structure set by [`Self::set_external`] is dropped.
    pub fn refit(self, primitives: Vec<P>) -> Aggregate<P>
    where
        P: Sync,
    {
        let start = Instant::now();
        let mut first_id = Vec::with_capacity(primitives.len() + 1);
        let mut next_id = 0u64;
        for element in &primitives {
            first_id.push(next_id as u32);
            next_id += id_count(element);
        }
        first_id.push(next_id as u32);
        let Some(bvh) = self.bvh.filter(|_| first_id == self.first_id) else {
            return Aggregate::new(primitives);
        };
        let primitive_count: usize = (primitives.iter())
            .map(|element| match element.mesh() {
                Some(mesh) => (0..mesh.triangles().len())
                    .filter(|&i| mesh.triangle_area(i) != 0.0)
                    .count(),
                None => id_count(element) as usize,
            })
            .sum();
        if primitive_count != self.primitive_count {
            return Aggregate::new(primitives);
        }
        let places = MovedElements {
            elements: &primitives,
            first_id: &first_id,
        };
        let Some(bvh) = bvh.refit(&places) else {
            return Aggregate::new(primitives);
        };
        Aggregate {
            primitives,
            bvh: Some(bvh),
            first_id,
            primitive_count,
            external: None,
            build_time: start.elapsed(),
            refit: true,
        }
    }

    /// The element and, for a mesh, the triangle of primitive `id`.
    #[inline]
    fn element_of(&self, id: u32) -> (u32, u32) {
        element_of(&self.first_id, id)
    }

    /// Whether the hierarchy was refit to moved elements rather than built
    /// ([`Self::refit`]).
    pub fn is_refit(&self) -> bool {
        self.refit
    }

    /// Lets another structure answer the queries (the BVH is kept, so that both can be
    /// compared on the same elements); None goes back to the BVH.
    pub fn set_external(&mut self, external: Option<Arc<dyn ExternalRayQueries<P>>>) {
        self.external = external;
    }

    /// The name of the structure answering the queries when it is not our BVH.
    pub fn external_name(&self) -> Option<&'static str> {
        self.external.as_ref().map(|e| e.name())
    }

    /// How long building or refitting the hierarchy took (an instanced shape's own hierarchy,
    /// built with the shape, not included).
    pub fn build_time(&self) -> Duration {
        self.build_time
    }

    /// The number of BVH primitives (triangles plus elements intersected whole).
    pub fn primitive_count(&self) -> usize {
        self.primitive_count
    }

    /// Bytes of memory held by the elements and the hierarchy: meshes' vertex attributes and
    /// indices, and the BVH's nodes and triangle packs. Counted from the data structures'
    /// capacities, so it does not depend on the allocator.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let elements: usize = self
            .primitives
            .iter()
            .map(|element| size_of::<P>() + element.heap_bytes())
            .sum();
        let bvh = self.bvh.as_ref().map_or(0, Bvh::memory_bytes);
        size_of::<Self>() + elements + bvh + self.first_id.capacity() * size_of::<u32>()
    }

    /// The axis-aligned box (min, max) around all elements; None when there are none.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bvh.as_ref().map(Bvh::bounds)
    }

    /// Intersects primitive `id` (an element intersected as a whole, or one part of an
    /// element) in (0, t_max).
    #[inline]
    fn whole_hit(&self, ray: &Ray, id: u32, t_max: f32) -> Option<f32> {
        let (element, part) = self.element_of(id);
        self.primitives[element as usize].intersect_part(ray, part, t_max)
    }

    /// The closest hit in (0, t_max), found by the structure answering the queries.
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        if let Some(external) = &self.external {
            return external.closest_hit(&self.primitives, ray);
        }
        self.bvh_closest_hit(ray)
    }

    /// The closest hits in (0, t_max) of `rays` (at most [`MAX_INTERLEAVED`], None where
    /// there is no ray), written to `hits`: each the one [`Self::closest_hit`] gives, our
    /// BVH's traversals interleaved ([`Bvh::closest_hits`]).
    pub fn closest_hits(&self, rays: &[Option<&Ray>], hits: &mut [Option<Hit>]) {
        let Some(bvh) = self.bvh.as_ref().filter(|_| self.external.is_none()) else {
            for (ray, hit) in rays.iter().zip(hits) {
                *hit = ray.and_then(|ray| self.closest_hit(ray));
            }
            return;
        };
        let mut found = [None; MAX_INTERLEAVED];
        let found = &mut found[..rays.len()];
        bvh.closest_hits(
            rays,
            |i, id, t_max| rays[i].and_then(|ray| self.whole_hit(ray, id, t_max)),
            found,
        );
        for (hit, found) in hits.iter_mut().zip(found) {
            *hit = found.map(|(id, triangle)| self.hit_of(id, triangle));
        }
    }

    fn bvh_closest_hit(&self, ray: &Ray) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let watertight = WatertightRay::new(ray.o, ray.d);
        let (id, triangle) =
            bvh.closest_hit(ray, &watertight, |id, t_max| self.whole_hit(ray, id, t_max))?;
        Some(self.hit_of(id, triangle))
    }

    /// The hit of the BVH's primitive `id`: its element and part.
    #[inline]
    fn hit_of(&self, id: u32, triangle: TriangleHit) -> Hit {
        let (shape, primitive) = self.element_of(id);
        Hit {
            shape,
            primitive,
            triangle,
        }
    }

    /// The closest surface the ray meets in (0, t_max).
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        let hit = self.closest_hit(ray)?;
        self.interaction(ray, &hit)
    }

    /// The surface interaction of `hit`, the closest hit of `ray` ([`Self::closest_hit`]).
    #[inline]
    pub fn interaction(&self, ray: &Ray, hit: &Hit) -> Option<SurfaceInteraction> {
        let mut si = self.primitives[hit.shape as usize].interaction(ray, hit)?;
        si.time = ray.time;
        Some(si)
    }

    /// Whether anything blocks the ray in (0, t_max).
    pub fn occluded(&self, ray: &Ray) -> bool {
        if let Some(external) = &self.external {
            return external.occluded(&self.primitives, ray);
        }
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let watertight = WatertightRay::new(ray.o, ray.d);
        bvh.occluded(ray, &watertight, |id, t_max| self.whole_hit(ray, id, t_max))
    }
}

/// The element owning primitive `id` and the primitive's index in it, `first_id` holding each
/// element's first id.
#[inline]
fn element_of(first_id: &[u32], id: u32) -> (u32, u32) {
    let element = first_id.partition_point(|&first| first <= id) - 1;
    (element as u32, id - first_id[element])
}

/// The ids an element takes: one per triangle of a mesh, one per part, else one.
fn id_count(element: &impl AggregateElement) -> u64 {
    match element.mesh() {
        Some(mesh) => mesh.triangles().len() as u64,
        None => element.part_count().unwrap_or(1) as u64,
    }
}

/// Elements at their new places, as a refit reads them by primitive id.
struct MovedElements<'a, P> {
    elements: &'a [P],
    first_id: &'a [u32],
}

impl<P: AggregateElement + Sync> PrimitivePlaces for MovedElements<'_, P> {
    fn triangle(&self, id: u32) -> Option<[Vec3; 3]> {
        let (element, triangle) = element_of(self.first_id, id);
        let mesh = self.elements[element as usize].mesh()?;
        (mesh.triangle_area(triangle as usize) != 0.0).then(|| mesh.vertices(triangle as usize))
    }

    fn analytic_bounds(&self, id: u32) -> Option<(Vec3, Vec3)> {
        let (element, part) = element_of(self.first_id, id);
        let element = &self.elements[element as usize];
        if element.mesh().is_some() {
            return None;
        }
        match element.part_count() {
            Some(parts) => (part < parts as u32).then(|| element.part_bounds(part)),
            None => (part == 0).then(|| element.bounds()),
        }
    }
}

impl AggregateElement for Shape {
    #[inline]
    fn mesh(&self) -> Option<&TriangleMesh> {
        let Shape::Mesh(mesh) = self else {
            return None;
        };
        Some(mesh)
    }

    fn bounds(&self) -> (Vec3, Vec3) {
        self.object_bounds()
    }

    #[inline]
    fn intersect_whole(&self, ray: &Ray, t_max: f32) -> Option<f32> {
        self.intersect_analytic(ray, t_max)
    }

    #[inline]
    fn interaction(&self, ray: &Ray, hit: &Hit) -> Option<SurfaceInteraction> {
        Some(ShapeGeometry::interaction(
            self,
            ray,
            hit.primitive,
            &hit.triangle,
            hit.shape,
        ))
    }

    fn heap_bytes(&self) -> usize {
        ShapeGeometry::heap_bytes(self)
    }

    fn part_count(&self) -> Option<usize> {
        ShapeGeometry::part_count(self)
    }

    fn part_bounds(&self, part: u32) -> (Vec3, Vec3) {
        ShapeGeometry::part_bounds(self, part)
    }

    #[inline]
    fn intersect_part(&self, ray: &Ray, part: u32, t_max: f32) -> Option<f32> {
        ShapeGeometry::intersect_part(self, ray, part, t_max)
    }
}
