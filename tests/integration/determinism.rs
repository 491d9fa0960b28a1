//! The same scene, sample count and seed give a bit-identical image whatever the thread count.

use glam::{DMat4, DVec3, Mat3, UVec2, Vec3};
use prism_core::geometry::Shape;
use prism_core::geometry::Sphere;
use prism_core::integrator::PathIntegrator;
use prism_core::math::Transform;
use prism_mitsuba::factory::shapes::{cube, transform_mesh};

use crate::common::scenes::{Object, build, camera, render_film};

#[test]
fn one_and_two_threads_give_identical_films() {
    let size = UVec2::new(37, 23);
    let room = Transform::new(DMat4::from_scale(DVec3::new(2.0, 1.5, 3.0))).unwrap();
    let scene = build(
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
        PathIntegrator::default(),
    );
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
