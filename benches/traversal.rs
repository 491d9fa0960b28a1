//! Ray traversal through the scene's BVH ([`prism_core::geometry::Geometry`]): closest-hit queries
//! (`intersect`, which also builds the surface interaction) and shadow queries (`occluded`, any
//! hit) per second, and the time to build the hierarchy.
//!
//! Two scenes: the bundled Cornell box (a few dozen triangles, where the cost is the fixed cost
//! of a query) and the generated scene of 1,024,000 triangles (a displaced sphere in a room, see
//! [`prism::bench::generated`]), where traversal dominates. Each gets three fixed, seeded sets of
//! 2¹⁶ rays, made once outside the timed loop:
//! - `camera_intersect`: camera rays through a jittered 256 × 256 grid in scanline order, the
//!   coherent case;
//! - `bounce_intersect`: from the surfaces those camera rays hit, a cosine-distributed direction
//!   about the normal on the camera's side, as the path tracer's diffuse bounces leave them:
//!   incoherent rays from points spread over the scene;
//! - `shadow_occluded`: from the same points to a point on a light chosen by power (the
//!   integrator's next-event estimation rays), finite segments.
//!
//! The bounce rays are also traced without the surface interaction, one at a time
//! (`bounce_closest_hit`) and [`MAX_INTERLEAVED`] at a time with their traversals interleaved,
//! as the path tracer's lanes trace them (`bounce_closest_hits_lanes`;
//! [`prism_core::geometry::Aggregate::closest_hits`]).
//!
//! Criterion reports the throughput in rays (elements) per second. The large scene is written
//! (once; it is kept in `target/bench-scenes`) and loaded only when one of its benchmarks runs,
//! so `cargo bench --bench traversal -- cornell` is quick.

mod common;

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::LazyLock;
use std::time::Duration;

use criterion::{BatchSize, Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use glam::{UVec2, Vec2};
use prism_core::camera::CameraModel;
use prism_core::geometry::Geometry;
use prism_core::geometry::bvh::MAX_INTERLEAVED;
use prism_core::light::{LightQuery, LightSource, Receiver};
use prism_core::math::{Frame, Ray};
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::warp::sample_cosine_hemisphere;
use prism_core::scene::Scene;
use prism_core::spectrum::{SampledWavelengths, WavelengthSampling};
use prism_mitsuba::load_scene;

/// Rays per set: GRID² (2¹⁶) camera rays, and as many bounce and shadow rays.
const GRID: u32 = 256;

/// A loaded scene and its fixed ray sets.
struct Fixture {
    scene: Scene,
    camera: Vec<Ray>,
    bounce: Vec<Ray>,
    shadow: Vec<Ray>,
}

impl Fixture {
    /// Loads the scene at `path` and traces its camera rays to place the bounce and shadow rays.
    fn load(path: &Path) -> Fixture {
        let scene = load_scene(path, &[])
            .unwrap_or_else(|e| panic!("{e}"))
            .scene;
        let mut rng = Pcg32::seeded(7);
        let u2 = |rng: &mut Pcg32| Vec2::new(rng.next_f32(), rng.next_f32());
        let film = scene.film.size.as_vec2();
        let camera: Vec<Ray> = (0..GRID * GRID)
            .map(|i| {
                let cell = UVec2::new(i % GRID, i / GRID).as_vec2();
                let position = (cell + u2(&mut rng)) / GRID as f32 * film;
                scene.camera.generate_ray(position, u2(&mut rng), 0.0).ray
            })
            .collect();
        // Bounce and shadow rays from the camera rays' hits, going round the camera rays again
        // (with new random numbers) until both sets are full.
        let (mut bounce, mut shadow) = (Vec::new(), Vec::new());
        let wanted = camera.len();
        let integrator = scene.integrator.prepare(&scene.world);
        let light_sampler = integrator.light_sampler();
        for ray in camera.iter().cycle().take(16 * wanted) {
            if bounce.len() == wanted && shadow.len() == wanted {
                break;
            }
            let Some(si) = scene.world.geometry.intersect(ray) else {
                continue;
            };
            if bounce.len() < wanted {
                let n = if si.shading.n.dot(ray.d) < 0.0 {
                    si.shading.n
                } else {
                    -si.shading.n
                };
                let local = sample_cosine_hemisphere(u2(&mut rng));
                bounce.push(si.spawn_ray(Frame::from_normal(n).to_world(local)));
            }
            let lambda = SampledWavelengths::sample(rng.next_f32(), WavelengthSampling::CieSum);
            let (u_light, u_choice) = (rng.next_f32(), rng.next_f32());
            if shadow.len() < wanted
                && let Some((light, _)) =
                    light_sampler.sample(u_light, &Receiver::surface(si.p, si.shading.n))
                && let Some(ls) = scene.world.lights[light].sample_incident(LightQuery {
                    shapes: &scene.world.geometry.primitives,
                    reference: si.p,
                    time: si.time,
                    u_choice,
                    u: u2(&mut rng),
                    lambda: &lambda,
                })
            {
                shadow.push(si.spawn_ray_to(ls.p, ls.n));
            }
        }
        assert!(
            bounce.len() == wanted && shadow.len() == wanted,
            "{}: too few camera rays hit the scene or see a light",
            path.display()
        );
        Fixture {
            scene,
            camera,
            bounce,
            shadow,
        }
    }
}

/// The scene file of the generated million-triangle scene, written on first use.
fn million_triangle_scene() -> PathBuf {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench-scenes");
    prism::bench::generated::write_million_triangle_scene(&folder).unwrap_or_else(|e| panic!("{e}"))
}

static CORNELL_BOX: LazyLock<Fixture> = LazyLock::new(|| {
    Fixture::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml"))
});
static MILLION_TRIANGLES: LazyLock<Fixture> =
    LazyLock::new(|| Fixture::load(&million_triangle_scene()));

const SCENES: [(&str, &LazyLock<Fixture>); 2] = [
    ("cornell-box", &CORNELL_BOX),
    ("million-triangles", &MILLION_TRIANGLES),
];

/// Closest-hit queries over `rays`; returns the number of hits, so nothing is optimised away.
fn intersect_all(geometry: &Geometry, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|ray| black_box(geometry.intersect(ray)).is_some())
        .count()
}

/// Shadow queries over `rays`; returns the number of blocked ones.
fn occluded_all(geometry: &Geometry, rays: &[Ray]) -> usize {
    rays.iter().filter(|ray| geometry.occluded(ray)).count()
}

/// Closest-hit queries over `rays`, without the surface interaction; returns the number of hits.
fn closest_hit_all(geometry: &Geometry, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|ray| black_box(geometry.closest_hit(ray)).is_some())
        .count()
}

/// [`closest_hit_all`] with [`MAX_INTERLEAVED`] rays at a time, their traversals interleaved.
fn closest_hits_interleaved(geometry: &Geometry, rays: &[Ray]) -> usize {
    let mut hits = [None; MAX_INTERLEAVED];
    let mut count = 0;
    for group in rays.chunks(MAX_INTERLEAVED) {
        let group: [Option<&Ray>; MAX_INTERLEAVED] = std::array::from_fn(|i| group.get(i));
        geometry.closest_hits(&group, &mut hits);
        count += black_box(&hits).iter().flatten().count();
    }
    count
}

/// One of a fixture's ray sets.
type RaySet = fn(&Fixture) -> &[Ray];
/// A query over a ray set.
type Query = fn(&Geometry, &[Ray]) -> usize;

fn traversal(c: &mut Criterion) {
    for (name, fixture) in SCENES {
        let mut group = c.benchmark_group(format!("traversal/{name}"));
        // One iteration traces 2¹⁶ rays, tens of milliseconds on the large scene: few samples of
        // the same iteration count.
        group.sample_size(10).sampling_mode(SamplingMode::Flat);
        group.throughput(Throughput::Elements(u64::from(GRID * GRID)));
        let cases: [(&str, RaySet, Query); 5] = [
            ("camera_intersect", |f| &f.camera, intersect_all),
            ("bounce_intersect", |f| &f.bounce, intersect_all),
            ("shadow_occluded", |f| &f.shadow, occluded_all),
            ("bounce_closest_hit", |f| &f.bounce, closest_hit_all),
            (
                "bounce_closest_hits_lanes",
                |f| &f.bounce,
                closest_hits_interleaved,
            ),
        ];
        for (id, rays_of, query) in cases {
            group.bench_function(id, |b| {
                let fixture: &Fixture = fixture;
                let rays = rays_of(fixture);
                b.iter(|| query(&fixture.scene.world.geometry, rays));
            });
        }
        group.finish();
    }
}

/// Building the hierarchy over the scene's shapes, from a copy of them made outside the timed
/// part: the time per build. The million-triangle build takes about a second, so the group
/// takes the fewest samples Criterion allows, one build each, in ten seconds.
fn bvh_build(c: &mut Criterion) {
    let mut group = c.benchmark_group("bvh_build");
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(10));
    for (name, fixture) in SCENES {
        group.bench_function(name, |b| {
            let fixture: &Fixture = fixture;
            let shapes = &fixture.scene.world.geometry.primitives;
            b.iter_batched(|| shapes.clone(), Geometry::new, BatchSize::PerIteration);
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = common::criterion();
    targets = traversal, bvh_build
}
criterion_main!(benches);
