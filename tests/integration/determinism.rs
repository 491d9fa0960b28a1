//! The same scene, sample count and seed give a bit-identical image whatever the thread count.

use glam::{DMat4, DVec3, Mat3, UVec2, Vec3};
use prism_core::geometry::Shape;
use prism_core::geometry::Sphere;
use prism_core::integrator::distribution::DirectLights;
use prism_core::integrator::{
    DirectIntegrator, DistributionIntegrator, Integrator, PathIntegrator, Tracking,
    VolPathIntegrator,
};
use prism_core::math::Transform;
use prism_mitsuba::factory::shapes::{cube, transform_mesh};

use prism_core::film::PixelSums;
use prism_core::integrator::RayCount;
use prism_core::render::{RenderOptions, SampleEstimator, render};
use prism_core::sampling::sampler::Sampler;
use prism_core::scene::Scene;

use crate::common::scenes::{Object, build, camera, render_film};

/// A room lit by a glowing sphere, seen by a camera whose film is `size`, rendered by
/// `integrator`.
fn lit_room(size: UVec2, integrator: impl Into<Integrator>) -> Scene {
    let room = Transform::new(DMat4::from_scale(DVec3::new(2.0, 1.5, 3.0))).unwrap();
    build(
        vec![
            Object {
                shape: Shape::Mesh(transform_mesh(cube(), &room, true, true)).into(),
                reflectance: 0.6,
                emission: None,
            },
            Object {
                shape: Shape::Sphere(Sphere {
                    center: Vec3::new(0.5, 1.0, 1.5),
                    radius: 0.3,
                    rotation: Mat3::IDENTITY,
                    flip_normals: false,
                })
                .into(),
                reflectance: 0.0,
                emission: Some(5.0),
            },
        ],
        vec![],
        camera(
            DVec3::new(0.0, 0.0, -2.5),
            DVec3::new(0.0, 0.2, 0.0),
            DVec3::Y,
            60.0,
            size,
        ),
        size,
        integrator,
    )
}

#[test]
fn one_and_two_threads_give_identical_films() {
    let scene = lit_room(UVec2::new(37, 23), PathIntegrator::default());
    let one = render_film(&scene, 8, 42, Some(1));
    let two = render_film(&scene, 8, 42, Some(2));
    assert!(
        one.pixels.iter().any(|p| p.sum(1) > 0.0),
        "the image is black"
    );
    assert_eq!(one.pixels, two.pixels);
    let other_seed = render_film(&scene, 8, 43, Some(2));
    assert_ne!(one.pixels, other_seed.pixels);
}

/// Renders `scene` with `spp` samples per pixel and `seed` on two threads, where a stepped
/// estimator's paths run in lanes ([`prism_core::render::LANES`] per worker, each lane taking
/// the next sample when its path ends), and traces the same samples one at a time, as a
/// `--pixel` replay or any other integrator traces them. Returns the two films and the lanes'
/// occupancy.
fn in_lanes_and_one_at_a_time(
    scene: &Scene,
    spp: u32,
    seed: u64,
) -> (Vec<PixelSums>, Vec<PixelSums>, Option<f64>) {
    let output = render(scene, &RenderOptions::fixed(spp, seed, Some(2))).unwrap();
    let estimator = SampleEstimator::new(scene);
    let mut sampler = Sampler::new(scene.sampler.kind, scene.strata(spp), seed);
    let mut count = RayCount::default();
    let mut one_at_a_time = Vec::new();
    let size = scene.film.size;
    for y in 0..size.y {
        for x in 0..size.x {
            let mut sums = PixelSums::default();
            for index in 0..spp {
                let pixel = UVec2::new(x, y);
                let draw = estimator.offset_draw();
                let xyz = estimator.estimate(&mut sampler, pixel, index, draw, &mut count, &mut []);
                sums.add(xyz);
            }
            one_at_a_time.push(sums);
        }
    }
    (output.film.pixels, one_at_a_time, output.lane_occupancy)
}

/// The path tracer's film in lanes is the one its samples give traced one at a time, and the
/// render reports how full the lanes were.
#[test]
fn paths_in_lanes_give_the_film_of_paths_one_at_a_time() {
    let size = UVec2::new(21, 19);
    for path in [
        PathIntegrator::default(),
        PathIntegrator {
            rr_depth: 1,
            ..PathIntegrator::default()
        },
        PathIntegrator {
            max_depth: 0,
            ..PathIntegrator::default()
        },
    ] {
        let scene = lit_room(size, path.clone());
        let (in_lanes, one_at_a_time, occupancy) = in_lanes_and_one_at_a_time(&scene, 5, 9);
        // Paths of max_depth 0 end before their first step.
        match occupancy {
            Some(occupancy) => assert!(
                occupancy > 0.0 && occupancy <= 1.0 && path.max_depth != 0,
                "occupancy {occupancy}"
            ),
            None => assert_eq!(path.max_depth, 0, "the path tracer runs in lanes"),
        }
        assert_eq!(in_lanes, one_at_a_time, "{path:?}");
        let lit = one_at_a_time.iter().any(|p| p.sum(1) > 0.0);
        assert_eq!(lit, path.max_depth != 0, "{path:?}");
    }
}

/// The same for the lecture's distribution ray tracer, whose tree of rays a lane traces one
/// ray per step: with its splitting (bounces and shadow rays by the potential), with every
/// light sampled, and without splitting (a path tracer without MIS).
#[test]
fn distribution_trees_in_lanes_give_the_film_of_trees_one_at_a_time() {
    let size = UVec2::new(13, 11);
    for distrib in [
        DistributionIntegrator::default(),
        DistributionIntegrator {
            lights: DirectLights::All,
            max_depth: 3,
            ..DistributionIntegrator::default()
        },
        DistributionIntegrator {
            bounce_samples: 1,
            shadow_rays: 1,
            ..DistributionIntegrator::default()
        },
    ] {
        let scene = lit_room(size, distrib.clone());
        let (in_lanes, one_at_a_time, occupancy) = in_lanes_and_one_at_a_time(&scene, 3, 5);
        let occupancy = occupancy.expect("distrib runs in lanes");
        assert!(occupancy > 0.0 && occupancy <= 1.0, "occupancy {occupancy}");
        assert_eq!(in_lanes, one_at_a_time, "{distrib:?}");
        assert!(
            one_at_a_time.iter().any(|p| p.sum(1) > 0.0),
            "{distrib:?}: the image is black"
        );
    }
}

/// The same for direct illumination, whose camera sample is one step (its BSDF samples' rays
/// traced within it).
#[test]
fn direct_samples_in_lanes_give_the_film_of_samples_one_at_a_time() {
    for direct in [
        DirectIntegrator::default(),
        DirectIntegrator {
            emitter_samples: 3,
            bsdf_samples: 2,
            hide_emitters: true,
        },
    ] {
        let scene = lit_room(UVec2::new(13, 11), direct.clone());
        let (in_lanes, one_at_a_time, occupancy) = in_lanes_and_one_at_a_time(&scene, 3, 7);
        let occupancy = occupancy.expect("direct runs in lanes");
        assert!(occupancy > 0.0 && occupancy <= 1.0, "occupancy {occupancy}");
        assert_eq!(in_lanes, one_at_a_time, "{direct:?}");
        assert!(
            one_at_a_time.iter().any(|p| p.sum(1) > 0.0),
            "{direct:?}: the image is black"
        );
    }
}

/// The same for the volumetric path tracers (`volpath`, `volpathmis` with and without spectral
/// MIS) on the bundled smoke box: a heterogeneous medium behind `null` boundaries over a floor,
/// at several depths (a real collision, a null crossing and a surface each take a step).
#[test]
fn volumetric_paths_in_lanes_give_the_film_of_paths_one_at_a_time() {
    let path = std::path::Path::new("scenes/media/smoke-box.xml");
    let defines = [("resx", "23"), ("resy", "17")].map(|(k, v)| (k.to_string(), v.to_string()));
    let root = prism_mitsuba::reader::read_scene_file(path, &defines).unwrap();
    let mut scene = prism_mitsuba::factory::build_scene(&root).unwrap().scene;
    for tracking in [
        Tracking::Spectral,
        Tracking::HeroMis { spectral_mis: true },
        Tracking::HeroMis {
            spectral_mis: false,
        },
    ] {
        for max_depth in [-1, 1, 3] {
            let volpath = VolPathIntegrator {
                tracking,
                max_depth,
                rr_depth: 2,
                ..VolPathIntegrator::default()
            };
            scene.integrator = volpath.clone().into();
            let (in_lanes, one_at_a_time, occupancy) = in_lanes_and_one_at_a_time(&scene, 4, 3);
            let occupancy = occupancy.expect("the volumetric path tracers run in lanes");
            assert!(occupancy > 0.0 && occupancy <= 1.0, "occupancy {occupancy}");
            assert_eq!(in_lanes, one_at_a_time, "{volpath:?}");
            assert!(
                one_at_a_time.iter().any(|p| p.sum(1) > 0.0),
                "{volpath:?}: the image is black"
            );
        }
    }
}
