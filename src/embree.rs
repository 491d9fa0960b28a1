//! Ray queries through Embree 3 (Wald et al. 2014, "Embree: A Kernel Framework for Efficient CPU
//! Ray Tracing"), to compare our BVH with it (cargo feature `embree`; `prism render --accel
//! embree`). Not used otherwise.
//!
//! Every shape is attached to one Embree scene with its index as geometry ID. Meshes become
//! Embree triangle geometries (without their zero-area triangles, which our BVH leaves out too);
//! analytic and moving shapes become user geometries whose callbacks run our own intersection
//! code, so that the two backends differ only in the hierarchy and the ray–triangle test. The
//! callbacks reach the shapes and the ray through the intersection context, which is extended
//! with them (the Embree 3 idiom), so the Embree scene holds no pointer into Rust data.
//!
//! The scene is built with `RTC_BUILD_QUALITY_HIGH` (binned SAH with spatial splits), Embree's
//! best trees for static geometry: our own BVH is built for quality too (PLOC with reinsertion),
//! and the comparison is about tracing, not building. The scene flags are none: not robust (the
//! default, faster, arithmetic), not compact, not dynamic. Queries are single rays
//! (`rtcIntersect1`, `rtcOccluded1`) from any thread, which Embree allows on a committed scene.
//!
//! The bindings are the `sys` module of the `embree` crate (generated from the Embree 3 headers,
//! whose struct layouts are those of Debian's 3.13.5); its safe wrapper ties scenes to borrowed
//! devices and has no user geometry, so the few calls needed are made here directly.

use std::ffi::c_void;
use std::ptr;

use embree::sys::*;

use prism_core::error::{Error, Result};
use prism_core::geometry::triangle::TriangleHit;
use prism_core::geometry::{AggregateElement, ExternalRayQueries, Hit, Primitive};
use prism_core::math::Ray;

/// Embree's "no geometry" ID (`RTC_INVALID_GEOMETRY_ID`).
const INVALID_ID: u32 = u32::MAX;

/// How a shape is represented in the Embree scene.
#[derive(Clone, Debug)]
enum Kind {
    /// A triangle geometry; Embree's primitive IDs index `triangles`, the mesh's triangle
    /// indices (None when no triangle was left out, so that the IDs are the indices).
    Triangles { triangles: Option<Vec<u32>> },
    /// A user geometry of one primitive, intersected by our code.
    Analytic,
    /// Nothing was attached (a mesh without a triangle of positive area).
    Absent,
}

/// An Embree device and a committed scene holding all primitives of a [`prism_core::geometry::Geometry`].
pub struct EmbreeScene {
    device: RTCDevice,
    scene: RTCScene,
    /// One entry per shape.
    kinds: Vec<Kind>,
}

// SAFETY: a committed Embree scene is immutable and Embree allows concurrent queries on it from
// any thread; the device and scene handles are reference counted by Embree's thread-safe
// retain/release.
unsafe impl Send for EmbreeScene {}
// SAFETY: see `Send`; `&EmbreeScene` only offers queries.
unsafe impl Sync for EmbreeScene {}

impl std::fmt::Debug for EmbreeScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EmbreeScene")
            .field("shapes", &self.kinds.len())
            .finish_non_exhaustive()
    }
}

impl Clone for EmbreeScene {
    /// Another handle on the same (immutable) Embree scene.
    fn clone(&self) -> EmbreeScene {
        // SAFETY: both handles are valid while `self` lives; retaining keeps them alive for the
        // clone, whose drop releases them again.
        unsafe {
            rtcRetainDevice(self.device);
            rtcRetainScene(self.scene);
        }
        EmbreeScene {
            device: self.device,
            scene: self.scene,
            kinds: self.kinds.clone(),
        }
    }
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: the handles were created (or retained) for this value and are released once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}

/// The intersection context handed to Embree, extended with what the user-geometry callbacks
/// need; `rtc` must come first, as Embree passes the callbacks a pointer to it.
#[repr(C)]
struct QueryContext<'a> {
    rtc: RTCIntersectContext,
    shapes: &'a [Primitive],
    ray: &'a Ray,
}

impl<'a> QueryContext<'a> {
    /// As `rtcInitIntersectContext` (an inline function of the header, not in the library).
    fn new(shapes: &'a [Primitive], ray: &'a Ray) -> QueryContext<'a> {
        QueryContext {
            rtc: RTCIntersectContext {
                flags: RTCIntersectContextFlags::INCOHERENT,
                filter: None,
                instID: [INVALID_ID],
            },
            shapes,
            ray,
        }
    }
}

/// Our ray as Embree's, over (0, t_max]. Embree's time is for its own motion blur, which is not
/// used: moving shapes read the time from the context's ray.
fn embree_ray(ray: &Ray) -> RTCRay {
    RTCRay {
        org_x: ray.o.x,
        org_y: ray.o.y,
        org_z: ray.o.z,
        tnear: 0.0,
        dir_x: ray.d.x,
        dir_y: ray.d.y,
        dir_z: ray.d.z,
        time: 0.0,
        tfar: ray.t_max,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// Bounds callback of an analytic shape: the user pointer is its `RTCBounds`.
unsafe extern "C" fn analytic_bounds(args: *const RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes valid arguments; the user pointer was set to an `RTCBounds` that
    // lives until the scene is committed, the only time Embree asks for bounds.
    unsafe {
        let args = &*args;
        *args.bounds_o = *(args.geometryUserPtr as *const RTCBounds);
    }
}

/// Intersection callback of an analytic shape: records a closer hit in the ray.
unsafe extern "C" fn analytic_intersect(args: *const RTCIntersectFunctionNArguments) {
    // SAFETY: Embree passes valid arguments. Only `rtcIntersect1` is called, so there is one ray
    // (N = 1), for which `RTCRayHitN` is laid out as `RTCRayHit`, and the context is the
    // `QueryContext` that `closest_hit` passed, alive for the call.
    unsafe {
        let args = &*args;
        if args.N != 1 || *args.valid == 0 {
            return;
        }
        let context = &*(args.context as *const QueryContext);
        let rayhit = &mut *(args.rayhit as *mut RTCRayHit);
        let Some(shape) = context.shapes.get(args.geomID as usize) else {
            return;
        };
        let t_max = rayhit.ray.tfar;
        if let Some(t) = shape.intersect_whole(context.ray, t_max)
            && t < t_max
        {
            rayhit.ray.tfar = t;
            rayhit.hit = RTCHit {
                Ng_x: 0.0,
                Ng_y: 0.0,
                Ng_z: 0.0,
                u: 0.0,
                v: 0.0,
                primID: args.primID,
                geomID: args.geomID,
                instID: context.rtc.instID,
            };
        }
    }
}

/// Occlusion callback of an analytic shape: marks the ray occluded (t_far = −∞, Embree's
/// convention) when the shape blocks it.
unsafe extern "C" fn analytic_occluded(args: *const RTCOccludedFunctionNArguments) {
    // SAFETY: as in `analytic_intersect`, for `rtcOccluded1` and `RTCRay`.
    unsafe {
        let args = &*args;
        if args.N != 1 || *args.valid == 0 {
            return;
        }
        let context = &*(args.context as *const QueryContext);
        let ray = &mut *(args.ray as *mut RTCRay);
        let Some(shape) = context.shapes.get(args.geomID as usize) else {
            return;
        };
        if shape.intersect_whole(context.ray, ray.tfar).is_some() {
            ray.tfar = f32::NEG_INFINITY;
        }
    }
}

/// The device's pending error as ours, if any.
fn device_error(device: RTCDevice, doing: &str) -> Result<()> {
    // SAFETY: the device handle is valid (or null, for which Embree reports the thread's error).
    let code = unsafe { rtcGetDeviceError(device) };
    if code == RTCError::NONE {
        Ok(())
    } else {
        Err(Error::usage(format!(
            "Embree failed while {doing}: {code:?}"
        )))
    }
}

/// Copies `items` into a new buffer of the geometry; false if Embree could not allocate it.
///
/// # Safety
/// `geometry` must be a valid geometry handle and `T` the `format`'s layout.
unsafe fn fill_buffer<T: Copy>(
    geometry: RTCGeometry,
    kind: RTCBufferType,
    format: RTCFormat,
    items: impl ExactSizeIterator<Item = T>,
) -> bool {
    let count = items.len();
    // SAFETY: Embree allocates `count` items of `size_of::<T>()` bytes (padded for its 16-byte
    // loads) and returns null on failure; the writes stay within the `count` items.
    unsafe {
        let buffer =
            rtcSetNewGeometryBuffer(geometry, kind, 0, format, std::mem::size_of::<T>(), count)
                as *mut T;
        if buffer.is_null() {
            return false;
        }
        for (i, item) in items.enumerate() {
            buffer.add(i).write(item);
        }
    }
    true
}

impl EmbreeScene {
    /// Builds and commits the Embree scene of the primitives.
    pub fn new(shapes: &[Primitive]) -> Result<EmbreeScene> {
        // SAFETY: a null configuration asks for the defaults.
        let device = unsafe { rtcNewDevice(ptr::null()) };
        if device.is_null() {
            device_error(ptr::null_mut(), "creating a device")?;
            return Err(Error::usage("Embree could not create a device"));
        }
        // SAFETY: the device is valid.
        let scene = unsafe { rtcNewScene(device) };
        // From here on, dropping `result` releases the device and scene on every error path.
        let mut result = EmbreeScene {
            device,
            scene,
            kinds: Vec::with_capacity(shapes.len()),
        };
        device_error(device, "creating a scene")?;
        // The analytic shapes' bounds, read by `analytic_bounds` during the commit below.
        let bounds: Vec<RTCBounds> = shapes
            .iter()
            .map(|shape| {
                let (lo, hi) = shape.bounds();
                RTCBounds {
                    lower_x: lo.x,
                    lower_y: lo.y,
                    lower_z: lo.z,
                    align0: 0.0,
                    upper_x: hi.x,
                    upper_y: hi.y,
                    upper_z: hi.z,
                    align1: 0.0,
                }
            })
            .collect();
        // SAFETY: the scene and device are valid; every geometry is created, filled, committed,
        // attached and released here (the scene keeps its own reference); `bounds` outlives
        // the commit of the scene, after which the bounds callback is never called.
        unsafe {
            rtcSetSceneBuildQuality(scene, RTCBuildQuality::HIGH);
            rtcSetSceneFlags(scene, RTCSceneFlags::NONE);
            for (index, shape) in shapes.iter().enumerate() {
                let geometry = match shape.mesh() {
                    Some(mesh) => {
                        let kept: Vec<u32> = (0..mesh.triangles().len())
                            .filter(|&i| mesh.triangle_area(i) > 0.0)
                            .map(|i| i as u32)
                            .collect();
                        if kept.is_empty() {
                            result.kinds.push(Kind::Absent);
                            continue;
                        }
                        let geometry = rtcNewGeometry(device, RTCGeometryType::TRIANGLE);
                        let filled = fill_buffer(
                            geometry,
                            RTCBufferType::VERTEX,
                            RTCFormat::FLOAT3,
                            mesh.positions().iter().map(|p| [p.x, p.y, p.z]),
                        ) && fill_buffer(
                            geometry,
                            RTCBufferType::INDEX,
                            RTCFormat::UINT3,
                            kept.iter().map(|&i| mesh.triangles()[i as usize]),
                        );
                        if !filled {
                            rtcReleaseGeometry(geometry);
                            device_error(device, "copying a mesh")?;
                            return Err(Error::usage("Embree could not allocate a mesh"));
                        }
                        let all = kept.len() == mesh.triangles().len();
                        result.kinds.push(Kind::Triangles {
                            triangles: (!all).then_some(kept),
                        });
                        geometry
                    }
                    None => {
                        let geometry = rtcNewGeometry(device, RTCGeometryType::USER);
                        rtcSetGeometryUserPrimitiveCount(geometry, 1);
                        rtcSetGeometryUserData(geometry, &bounds[index] as *const _ as *mut c_void);
                        rtcSetGeometryBoundsFunction(
                            geometry,
                            Some(analytic_bounds),
                            ptr::null_mut(),
                        );
                        rtcSetGeometryIntersectFunction(geometry, Some(analytic_intersect));
                        rtcSetGeometryOccludedFunction(geometry, Some(analytic_occluded));
                        result.kinds.push(Kind::Analytic);
                        geometry
                    }
                };
                rtcCommitGeometry(geometry);
                rtcAttachGeometryByID(scene, geometry, index as u32);
                rtcReleaseGeometry(geometry);
                device_error(device, "adding a shape")?;
            }
            rtcCommitScene(scene);
        }
        device_error(device, "building the scene")?;
        Ok(result)
    }
}

impl ExternalRayQueries<Primitive> for EmbreeScene {
    /// The closest hit in (0, t_max] of `ray` among `shapes`, which must be those the scene was
    /// built from. Embree's barycentrics (u, v) weigh the second and third vertex, so the point
    /// is (1 − u − v)·p0 + u·p1 + v·p2.
    fn closest_hit(&self, shapes: &[Primitive], ray: &Ray) -> Option<Hit> {
        let mut context = QueryContext::new(shapes, ray);
        let mut rayhit = RTCRayHit {
            ray: embree_ray(ray),
            hit: RTCHit {
                Ng_x: 0.0,
                Ng_y: 0.0,
                Ng_z: 0.0,
                u: 0.0,
                v: 0.0,
                primID: INVALID_ID,
                geomID: INVALID_ID,
                instID: [INVALID_ID],
            },
        };
        // SAFETY: the scene is committed; the context and the (16-byte aligned) ray live for
        // the call, and the callbacks read the context as the `QueryContext` it is.
        unsafe { rtcIntersect1(self.scene, &mut context.rtc, &mut rayhit) };
        let shape = rayhit.hit.geomID;
        let t = rayhit.ray.tfar;
        match self.kinds.get(shape as usize)? {
            Kind::Triangles { triangles } => {
                let id = rayhit.hit.primID;
                let primitive = match triangles {
                    Some(kept) => *kept.get(id as usize)?,
                    None => id,
                };
                let (u, v) = (rayhit.hit.u, rayhit.hit.v);
                Some(Hit {
                    shape,
                    primitive,
                    triangle: TriangleHit {
                        t,
                        b0: 1.0 - u - v,
                        b1: u,
                        b2: v,
                    },
                })
            }
            Kind::Analytic => Some(Hit {
                shape,
                primitive: 0,
                triangle: TriangleHit {
                    t,
                    b0: 0.0,
                    b1: 0.0,
                    b2: 0.0,
                },
            }),
            Kind::Absent => None,
        }
    }

    /// Whether anything among `shapes` (those the scene was built from) blocks the ray in
    /// (0, t_max].
    fn occluded(&self, shapes: &[Primitive], ray: &Ray) -> bool {
        let mut context = QueryContext::new(shapes, ray);
        let mut embree = embree_ray(ray);
        // SAFETY: as in `closest_hit`.
        unsafe { rtcOccluded1(self.scene, &mut context.rtc, &mut embree) };
        embree.tfar == f32::NEG_INFINITY
    }

    fn name(&self) -> &'static str {
        "Embree"
    }
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, DVec3, Mat3, Vec3};

    use super::*;
    use crate::accel::Accel;
    use prism_core::geometry::{Disk, Geometry, Instance, Shape, Sphere, TriangleMesh};
    use prism_core::math::{AnimatedTransform, Transform};
    use prism_core::sampling::rng::Pcg32;
    use prism_core::sampling::warp::sample_uniform_sphere;
    use prism_mitsuba::factory::shapes::{cube, transform_mesh};

    /// A bumpy latitude–longitude sphere; its pole rows are zero-area triangles.
    fn bumpy_sphere(center: Vec3, radius: f32, rings: u32, segments: u32) -> TriangleMesh {
        let mut positions = Vec::new();
        for i in 0..=rings {
            let theta = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..=segments {
                let phi = std::f32::consts::TAU * j as f32 / segments as f32;
                let r = radius * (1.0 + 0.1 * (5.0 * theta).sin() * (7.0 * phi).cos());
                let d = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                positions.push(center + r * d);
            }
        }
        let mut triangles = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let a = i * (segments + 1) + j;
                let b = a + segments + 1;
                triangles.push([a, b, a + 1]);
                triangles.push([a + 1, b, b + 1]);
            }
        }
        TriangleMesh::new(positions, None, None, triangles, false)
    }

    /// A room (cube), a bumpy mesh sphere, an analytic sphere, a disk and a moving sphere.
    fn shapes() -> Vec<Primitive> {
        let room = Transform::new(DMat4::from_scale(DVec3::new(3.0, 2.0, 4.0))).unwrap();
        let disk = Transform::new(
            DMat4::from_translation(DVec3::new(-1.0, -1.0, 1.0))
                * DMat4::from_rotation_x(0.7)
                * DMat4::from_scale(DVec3::splat(0.8)),
        )
        .unwrap();
        let sphere = |center: Vec3, radius: f32| Sphere {
            center,
            radius,
            rotation: Mat3::IDENTITY,
            flip_normals: false,
        };
        let moving = AnimatedTransform::new(&[
            (0.0, DMat4::from_translation(DVec3::new(1.5, -1.0, -2.0))),
            (1.0, DMat4::from_translation(DVec3::new(1.5, 0.0, -2.0))),
        ])
        .unwrap();
        vec![
            Shape::Mesh(transform_mesh(cube(), &room, true, true)).into(),
            Shape::Mesh(bumpy_sphere(Vec3::new(1.0, 0.5, 1.0), 0.9, 60, 90)).into(),
            Shape::Sphere(sphere(Vec3::new(-1.2, 0.6, -1.0), 0.7)).into(),
            Shape::Disk(Disk::new(disk, false)).into(),
            Primitive::Instance(Instance::new(
                Shape::Sphere(sphere(Vec3::ZERO, 0.4)),
                moving,
            )),
        ]
    }

    /// Rays from random points of the room in random directions at random times.
    fn random_rays(count: usize, seed: u64) -> Vec<Ray> {
        let mut rng = Pcg32::seeded(seed);
        (0..count)
            .map(|_| {
                let mut u = || rng.next_f32();
                let o = Vec3::new(u() * 5.8 - 2.9, u() * 3.8 - 1.9, u() * 7.8 - 3.9);
                let d = sample_uniform_sphere(glam::Vec2::new(u(), u()));
                Ray::new(o, d, f32::INFINITY, u())
            })
            .collect()
    }

    /// Embree and our BVH find the same closest hits on 100 000 random rays: same t within
    /// 1e-4 relative, same shape, and the same triangle unless the ray meets an edge (where
    /// both triangles lie at that t). Hits and misses may differ only for the rare ray through
    /// a vertex or edge that one of the two triangle tests lets slip.
    #[test]
    fn closest_hits_agree_with_the_bvh() {
        let mut geometry = Geometry::new(shapes());
        let rays = random_rays(100_000, 7);
        let ours: Vec<Option<Hit>> = rays.iter().map(|r| geometry.closest_hit(r)).collect();
        Accel::Embree.apply(&mut geometry).unwrap();
        let (mut disagreements, mut other_triangle, mut hits) = (0, 0, 0);
        let mut shapes_hit = [0usize; 5];
        for (ray, ours) in rays.iter().zip(&ours) {
            let theirs = geometry.closest_hit(ray);
            match (ours, theirs) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    shapes_hit[a.shape as usize] += 1;
                    let (ta, tb) = (a.triangle.t, b.triangle.t);
                    assert!(
                        (ta - tb).abs() <= 1e-4 * ta.max(tb),
                        "ray {ray:?}: t {ta} (BVH) against {tb} (Embree)"
                    );
                    assert_eq!(a.shape, b.shape, "ray {ray:?}");
                    if a.primitive != b.primitive {
                        other_triangle += 1;
                    } else {
                        // Barycentrics agree too: Embree's (u, v) are mapped to b1, b2.
                        let (x, y) = (a.triangle, b.triangle);
                        assert!(
                            (x.b0 - y.b0).abs() < 1e-3
                                && (x.b1 - y.b1).abs() < 1e-3
                                && (x.b2 - y.b2).abs() < 1e-3,
                            "ray {ray:?}: barycentrics {x:?} against {y:?}"
                        );
                    }
                }
                (None, None) => {}
                _ => disagreements += 1,
            }
        }
        assert!(shapes_hit.iter().all(|&n| n > 100), "{shapes_hit:?}");
        assert!(hits > 90_000, "{hits} hits");
        assert!(
            disagreements <= 10,
            "{disagreements} hit/miss disagreements"
        );
        assert!(
            other_triangle <= 10,
            "{other_triangle} rays hit another triangle"
        );
    }

    /// Occlusion tests agree on random segments, and the surface interactions agree.
    #[test]
    fn occlusion_and_interactions_agree_with_the_bvh() {
        let mut geometry = Geometry::new(shapes());
        let mut rng = Pcg32::seeded(11);
        let rays: Vec<Ray> = random_rays(20_000, 3)
            .into_iter()
            .map(|ray| Ray {
                t_max: rng.next_f32() * 6.0,
                ..ray
            })
            .collect();
        let occluded: Vec<bool> = rays.iter().map(|r| geometry.occluded(r)).collect();
        let interactions: Vec<_> = rays.iter().map(|r| geometry.intersect(r)).collect();
        Accel::Embree.apply(&mut geometry).unwrap();
        let blocked = occluded.iter().filter(|&&o| o).count();
        assert!(blocked > 5_000 && blocked < 15_000, "{blocked} blocked");
        let mut disagreements = 0;
        for ((ray, &ours), ours_si) in rays.iter().zip(&occluded).zip(&interactions) {
            if geometry.occluded(ray) != ours {
                disagreements += 1;
            }
            if let (Some(a), Some(b)) = (ours_si, geometry.intersect(ray)) {
                assert_eq!(a.shape, b.shape);
                assert!(
                    (a.p - b.p).length() < 1e-3,
                    "{ray:?}: {} against {}",
                    a.p,
                    b.p
                );
                assert!(a.n.dot(b.n) > 0.999, "{ray:?}: {} against {}", a.n, b.n);
            }
        }
        assert!(
            disagreements <= 5,
            "{disagreements} occlusion disagreements"
        );
    }

    #[test]
    fn an_empty_scene_and_a_degenerate_mesh_are_never_hit() {
        let flat = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
            None,
            None,
            vec![[0, 1, 2]],
            false,
        );
        for shapes in [vec![], vec![Shape::Mesh(flat).into()]] {
            let mut geometry = Geometry::new(shapes);
            Accel::Embree.apply(&mut geometry).unwrap();
            assert_eq!(Accel::of(&geometry), Accel::Embree);
            for ray in random_rays(100, 1) {
                assert!(geometry.closest_hit(&ray).is_none() && !geometry.occluded(&ray));
            }
        }
    }
}
