//! Both integrators — the path tracer and the lecture's distribution ray tracer — against
//! closed-form answers (docs/testing.md, closed-form scenes): furnaces, a point light and a disk
//! light over a plane. Every tolerance comes from the standard error of the estimate being tested.

use glam::{DMat4, DVec3, Mat3, UVec2, Vec2, Vec3};
use prism_core::camera::CameraModel;
use prism_core::geometry::Shape;
use prism_core::geometry::Sphere;
use prism_core::integrator::{DistributionIntegrator, Integrator, PathIntegrator};
use prism_core::light::{Light, PointLight};
use prism_core::math::Transform;
use prism_core::math::special::regularized_gamma_q;
use prism_core::spectrum::{Spectrum, WavelengthSampling};
use prism_mitsuba::factory::shapes::{cube, rectangle, transform_mesh};

use crate::common::scenes::{
    Object, assert_mean_luminance, build, camera, disk_light_over_plane, pixel_mean_and_variance,
    render_film,
};

/// The inside of a unit sphere: normals point inwards, so the inner face is the front.
pub(super) fn inner_sphere() -> Shape {
    Shape::Sphere(Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
        rotation: Mat3::IDENTITY,
        flip_normals: true,
    })
}

/// The inside of a 2 × 3 × 4 box.
pub(super) fn inner_box() -> Shape {
    let to_world = Transform::new(DMat4::from_scale(DVec3::new(1.0, 1.5, 2.0))).unwrap();
    Shape::Mesh(transform_mesh(cube(), &to_world, true, true))
}

/// Renders a closed room whose every surface has reflectance rho and emits le: the radiance
/// everywhere is le / (1 − rho) (the Neumann series of the rendering equation).
fn furnace(
    shape: Shape,
    rho: f32,
    le: f32,
    integrator: impl Into<Integrator>,
    spp: u32,
    seed: u64,
) -> prism_core::film::Film {
    render_film(&furnace_scene(shape, rho, le, integrator), spp, seed, None)
}

/// The scene of [`furnace`].
pub(super) fn furnace_scene(
    shape: Shape,
    rho: f32,
    le: f32,
    integrator: impl Into<Integrator>,
) -> prism_core::scene::Scene {
    let size = UVec2::new(8, 8);
    let camera = camera(
        DVec3::new(0.1, 0.2, -0.3),
        DVec3::new(0.5, 0.3, 1.0),
        DVec3::Y,
        70.0,
        size,
    );
    build(
        vec![Object {
            shape: shape.into(),
            reflectance: rho,
            emission: Some(le),
        }],
        vec![],
        camera,
        size,
        integrator,
    )
}

/// Both integrators with their defaults, and the samples per pixel each needs.
fn integrators() -> [(Integrator, u32); 2] {
    [
        (PathIntegrator::default().into(), 2048),
        (DistributionIntegrator::default().into(), 512),
    ]
}

#[test]
fn closed_sphere_furnace_gives_le_over_one_minus_rho() {
    for (integrator, spp) in integrators() {
        let name = format!("sphere furnace, rho 0.5, {integrator:?}");
        let film = furnace(inner_sphere(), 0.5, 1.0, integrator, spp, 1);
        assert_mean_luminance(&name, &film, 2.0);
    }
}

/// The furnace's answer holds for every wavelength density a film may choose.
#[test]
fn closed_sphere_furnace_with_every_wavelength_density() {
    for (density, seed) in WavelengthSampling::ALL.into_iter().zip(20..) {
        let mut scene = furnace_scene(inner_sphere(), 0.5, 1.0, PathIntegrator::default());
        scene.film.wavelength_sampling = density;
        let film = render_film(&scene, 1024, seed, None);
        assert_mean_luminance(&format!("sphere furnace, {density:?}"), &film, 2.0);
    }
}

/// An emitter of `sampling_weight` 0 is never chosen for direct light; the path tracer then finds
/// it by scattering alone, whose multiple importance sampling weight becomes 1, and the
/// answer stays Lₑ/(1 − ρ).
#[test]
fn an_emitter_of_sampling_weight_zero_is_found_by_scattering() {
    let mut scene = furnace_scene(inner_sphere(), 0.5, 1.0, PathIntegrator::default());
    scene.world.light_sampling_weights = vec![0.0];
    let film = render_film(&scene, 2048, 3, None);
    assert_mean_luminance("sphere furnace, sampling weight 0", &film, 2.0);
}

/// The path tracer only: in a box lit by its own walls, a point near an edge sees emitting points
/// arbitrarily close on the next wall, and light sampling alone (the distribution ray tracer's
/// direct part, without MIS) has infinite variance there: its error estimate would mean nothing.
/// The sphere, where cos θ cos θ' / d² is constant, tests it instead.
#[test]
fn closed_box_furnace_gives_le_over_one_minus_rho() {
    let film = furnace(inner_box(), 0.7, 0.6, PathIntegrator::default(), 2048, 2);
    assert_mean_luminance("box furnace, rho 0.7", &film, 0.6 / 0.3);
}

#[test]
fn distribution_ray_tracer_in_a_bright_sphere_furnace() {
    let film = furnace(
        inner_sphere(),
        0.8,
        1.0,
        DistributionIntegrator::default(),
        512,
        12,
    );
    assert_mean_luminance("sphere furnace, rho 0.8, distrib", &film, 5.0);
}

/// The distribution ray tracer with every light sampled and much splitting, and with its Russian
/// roulette starting at once: the same answer.
#[test]
fn distribution_estimator_variants_keep_the_furnace_answer() {
    use prism_core::integrator::distribution::DirectLights;
    let variants = [
        DistributionIntegrator {
            lights: DirectLights::All,
            bounce_samples: 8,
            shadow_rays: 8,
            ..DistributionIntegrator::default()
        },
        DistributionIntegrator {
            rr_threshold: 0.6,
            ..DistributionIntegrator::default()
        },
    ];
    for (seed, integrator) in variants.into_iter().enumerate() {
        let name = format!("sphere furnace, {integrator:?}");
        let film = furnace(inner_sphere(), 0.6, 1.0, integrator, 512, 20 + seed as u64);
        assert_mean_luminance(&name, &film, 2.5);
    }
}

#[test]
fn russian_roulette_from_the_first_bounce_keeps_the_mean() {
    let integrator = PathIntegrator {
        rr_depth: 1,
        ..PathIntegrator::default()
    };
    let film = furnace(inner_sphere(), 0.8, 1.0, integrator, 4096, 3);
    assert_mean_luminance("sphere furnace, rho 0.8, roulette from depth 1", &film, 5.0);
}

#[test]
fn hidden_emitters_remove_exactly_the_directly_seen_emission() {
    let integrator = PathIntegrator {
        hide_emitters: true,
        ..PathIntegrator::default()
    };
    let film = furnace(inner_box(), 0.5, 1.0, integrator, 2048, 4);
    assert_mean_luminance("box furnace without the directly seen emission", &film, 1.0);
}

/// With max_depth = k only paths of fewer than k bounces count: L = le (1 + rho + ... + rho^(k-1)),
/// Mitsuba's convention (1: emitters only, 2: direct lighting).
#[test]
fn max_depth_truncates_the_neumann_series_as_mitsuba_counts_it() {
    for (k, seed) in [(1, 5u64), (2, 6), (3, 7)] {
        let path = PathIntegrator {
            max_depth: k,
            ..PathIntegrator::default()
        };
        let film = furnace(inner_sphere(), 0.5, 1.0, path, 1024, seed);
        let expected: f64 = (0..k).map(|j| 0.5f64.powi(j)).sum();
        assert_mean_luminance(
            &format!("sphere furnace, path, max_depth {k}"),
            &film,
            expected,
        );
        let distrib = DistributionIntegrator {
            max_depth: k,
            ..DistributionIntegrator::default()
        };
        let film = furnace(inner_sphere(), 0.5, 1.0, distrib, 256, seed + 10);
        assert_mean_luminance(
            &format!("sphere furnace, distrib, max_depth {k}"),
            &film,
            expected,
        );
    }
}

/// Russian roulette on (from the first bounce) and off (it never starts before the depth limit)
/// give the same mean, within the standard error of their difference, and both the closed form
/// le (1 + rho + ... + rho^(k-1)) of the truncated series.
#[test]
fn russian_roulette_on_and_off_give_the_same_mean() {
    let k = 8;
    let expected: f64 = (0..k).map(|j| 0.7f64.powi(j)).sum();
    let mut results = Vec::new();
    for (rr_depth, seed) in [(1, 30u64), (100, 31)] {
        let integrator = PathIntegrator {
            max_depth: k,
            rr_depth,
            ..PathIntegrator::default()
        };
        let film = furnace(inner_box(), 0.7, 1.0, integrator, 2048, seed);
        assert_mean_luminance(&format!("roulette from depth {rr_depth}"), &film, expected);
        results.push(crate::common::scenes::image_mean_and_standard_error(
            &film, 1,
        ));
    }
    let ((on, se_on), (off, se_off)) = (results[0], results[1]);
    assert!(
        (on - off).abs() < 4.0 * (se_on * se_on + se_off * se_off).sqrt(),
        "roulette on {on} ± {se_on}, off {off} ± {se_off}"
    );
}

/// A point light of intensity I at height h over a diffuse plane of reflectance rho:
/// L(x) = rho I cos θ / (π d²) with d the distance to the light and cos θ = h / d. Each pixel's
/// estimate is compared with the average of L over the pixel's footprint (fine quadrature), and
/// the pixels' standardised errors together with a chi-square test.
#[test]
fn point_light_over_a_diffuse_plane() {
    for (seed, integrator) in [
        Integrator::from(PathIntegrator::default()),
        DistributionIntegrator::default().into(),
    ]
    .into_iter()
    .enumerate()
    {
        point_light_over_a_diffuse_plane_with(integrator, 8 + seed as u64);
    }
}

fn point_light_over_a_diffuse_plane_with(integrator: Integrator, seed: u64) {
    let (rho, intensity, height) = (0.6f32, 10.0f32, 1.0f32);
    let light_position = Vec3::new(0.3, -0.2, height);
    let size = UVec2::new(16, 12);
    let camera = camera(DVec3::new(0.0, 0.0, 3.0), DVec3::ZERO, DVec3::Y, 60.0, size);
    let plane = Transform::new(DMat4::from_scale(DVec3::splat(50.0))).unwrap();
    let scene = build(
        vec![Object {
            shape: Shape::Mesh(transform_mesh(rectangle(), &plane, false, true)).into(),
            reflectance: rho,
            emission: None,
        }],
        vec![Light::Point(PointLight {
            position: light_position,
            intensity: Spectrum::Constant(intensity),
        })],
        camera.clone(),
        size,
        integrator,
    );
    let film = render_film(&scene, 256, seed, None);

    let radiance = |film_position: Vec2| -> f64 {
        let ray = camera
            .generate_ray(film_position, Vec2::splat(0.5), 0.0)
            .ray;
        let t = -ray.o.z / ray.d.z;
        let x = (ray.o + ray.d * t).as_dvec3();
        let to_light = light_position.as_dvec3() - x;
        let d = to_light.length();
        f64::from(rho * intensity) * (f64::from(height) / d) / (std::f64::consts::PI * d * d)
    };
    let quadrature = 32;
    let mut statistic = 0.0;
    for y in 0..size.y {
        for x in 0..size.x {
            let mut exact = 0.0;
            for j in 0..quadrature {
                for i in 0..quadrature {
                    let offset = Vec2::new(
                        (i as f32 + 0.5) / quadrature as f32,
                        (j as f32 + 0.5) / quadrature as f32,
                    );
                    exact += radiance(Vec2::new(x as f32, y as f32) + offset);
                }
            }
            exact /= f64::from(quadrature * quadrature);
            let (mean, variance) = pixel_mean_and_variance(&film, film.index(x, y), 1);
            statistic += (mean - exact).powi(2) / variance;
            // Each pixel on its own: 5 standard errors (Bonferroni over 192 pixels at 1e-4).
            assert!(
                (mean - exact).abs() < 5.0 * variance.sqrt(),
                "pixel ({x}, {y}): {mean} vs {exact}"
            );
        }
    }
    let pixels = f64::from(size.x * size.y);
    let p_value = regularized_gamma_q(pixels / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-3,
        "chi-square of the pixel errors {statistic} over {pixels} pixels: p = {p_value}"
    );
}

/// A disk light over a diffuse plane (see [`crate::common::scenes::disk_light_over_plane`]): both light
/// sampling and BSDF sampling find the disk, so this checks their MIS combination.
#[test]
fn disk_light_over_a_diffuse_plane() {
    for (seed, integrator) in [
        Integrator::from(PathIntegrator {
            max_depth: 2,
            ..PathIntegrator::default()
        }),
        DistributionIntegrator {
            max_depth: 2,
            ..DistributionIntegrator::default()
        }
        .into(),
    ]
    .into_iter()
    .enumerate()
    {
        disk_light_over_a_diffuse_plane_with(integrator, 9 + seed as u64);
    }
}

fn disk_light_over_a_diffuse_plane_with(integrator: Integrator, seed: u64) {
    let mut setup = disk_light_over_plane(UVec2::new(12, 12));
    setup.scene.integrator = integrator;
    let film = render_film(&setup.scene, 1024, seed, None);
    let mut statistic = 0.0;
    for (i, exact) in setup.exact.iter().enumerate() {
        let (mean, variance) = pixel_mean_and_variance(&film, i, 1);
        statistic += (mean - exact).powi(2) / variance;
        assert!(
            (mean - exact).abs() < 5.0 * variance.sqrt(),
            "pixel {i}: {mean} vs {exact}"
        );
    }
    let pixels = setup.exact.len() as f64;
    let p_value = regularized_gamma_q(pixels / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-3,
        "chi-square {statistic} over {pixels} pixels: p = {p_value}"
    );
}
