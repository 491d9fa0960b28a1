//! Lights against closed-form answers (docs/testing.md, closed-form scenes): images of diffuse
//! planes and spheres lit by directional, sphere, rectangle, constant and image environment lights,
//! the choice of light not changing the answer, and the flux identities Φ = E[L |cos| / p] over
//! light samples taken from a sphere around each light and over the light's emission samples. Every tolerance comes from the standard
//! error of the estimate being tested.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DMat4, DVec3, Mat3, UVec2, Vec2, Vec3};
use prism_core::camera::{Camera, CameraModel};
use prism_core::film::Film;
use prism_core::geometry::Sphere;
use prism_core::geometry::{Primitive, Shape, ShapeSampling};
use prism_core::image::{Bitmap, Encoding};
use prism_core::integrator::{
    DistributionIntegrator, Integrator, ParticleTracer, PathIntegrator, VolPathIntegrator,
};
use prism_core::light::{
    AreaLight, BoundingSphere, ConstantLight, DirectionalAreaLight, DirectionalLight,
    EmissionQuery, EnvironmentMap, Light, LightQuery, LightSelection, LightSource, PointLight,
    Projector, SpotLight,
};
use prism_core::math::special::regularized_gamma_q;
use prism_core::math::{Ray, Transform};
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::warp::sample_uniform_sphere;
use prism_core::spectrum::{SampledWavelengths, Spectrum};
use prism_core::texture::{BitmapTexture, FilterType, Texture, TextureUse, UvTransform, WrapMode};
use prism_mitsuba::factory::shapes::{rectangle, transform_mesh};

use crate::common::scenes::{
    Object, build, camera, image_mean_and_standard_error, pixel_mean_and_variance, render_film,
};

/// The plane z = 0, 100 × 100, diffuse `rho`, facing +z.
fn floor(rho: f32) -> Object {
    let plane = Transform::new(DMat4::from_scale(DVec3::splat(50.0))).unwrap();
    Object {
        shape: Shape::Mesh(transform_mesh(rectangle(), &plane, false, true)).into(),
        reflectance: rho,
        emission: None,
    }
}

fn sphere(center: Vec3, radius: f32) -> Primitive {
    Primitive::Shape(Shape::Sphere(Sphere {
        center,
        radius,
        rotation: Mat3::IDENTITY,
        flip_normals: false,
    }))
}

/// The average over pixel (x, y)'s footprint of `exact` along the camera rays (32 × 32 points).
fn footprint_average(camera: &Camera, x: u32, y: u32, exact: &impl Fn(&Ray) -> f64) -> f64 {
    let n = 32;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let offset = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            sum += exact(
                &camera
                    .generate_ray(
                        Vec2::new(x as f32, y as f32) + offset,
                        Vec2::splat(0.5),
                        0.0,
                    )
                    .ray,
            );
        }
    }
    sum / f64::from(n * n)
}

/// The point where a ray meets the plane z = 0.
fn on_floor(ray: &Ray) -> DVec3 {
    let t = -ray.o.z / ray.d.z;
    (ray.o + ray.d * t).as_dvec3()
}

/// Compares every pixel's mean luminance with the footprint average of `exact`: each pixel
/// within 5 standard errors (Bonferroni over the pixels at about 10⁻⁴), and the pixels'
/// standardised errors together by a chi-square test (p > 10⁻³). Also checks that the
/// estimates are precise enough for a 1 % bias to show.
fn assert_pixels(name: &str, film: &Film, camera: &Camera, exact: impl Fn(&Ray) -> f64) {
    let size = film.crop.size;
    let mut statistic = 0.0;
    let mut expected_mean = 0.0;
    for y in 0..size.y {
        for x in 0..size.x {
            let exact = footprint_average(camera, x, y, &exact);
            expected_mean += exact;
            let (mean, variance) = pixel_mean_and_variance(film, film.index(x, y), 1);
            statistic += (mean - exact).powi(2) / variance;
            assert!(
                (mean - exact).abs() < 5.0 * variance.sqrt(),
                "{name}: pixel ({x}, {y}) has {mean}, the closed form {exact} (σ = {})",
                variance.sqrt()
            );
        }
    }
    let pixels = f64::from(size.x * size.y);
    let (_, se) = image_mean_and_standard_error(film, 1);
    assert!(
        se < 0.0025 * expected_mean / pixels,
        "{name}: the standard error {se} is too large to detect a 1 % bias"
    );
    let p_value = regularized_gamma_q(pixels / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-3,
        "{name}: chi-square of the pixel errors {statistic} over {pixels} pixels: p = {p_value}"
    );
}

/// A directional light of irradiance E on a diffuse plane: L = ρ E cos θ / π everywhere (the
/// only noise is the wavelengths' in the film's XYZ).
#[test]
fn directional_light_on_a_plane() {
    let (rho, irradiance) = (0.6f32, 3.0f32);
    let direction = Vec3::new(1.0, -0.5, -2.0).normalize();
    let size = UVec2::new(8, 6);
    let camera = camera(DVec3::new(0.5, 0.2, 3.0), DVec3::ZERO, DVec3::Y, 60.0, size);
    let scene = build(
        vec![floor(rho)],
        vec![Light::Directional(DirectionalLight::new(
            direction,
            Spectrum::Constant(irradiance),
        ))],
        camera.clone(),
        size,
        PathIntegrator::default(),
    );
    let film = render_film(&scene, 2048, 31, None);
    let exact = f64::from(rho * irradiance * -direction.z) / PI;
    assert_pixels("directional light", &film, &camera, |_| exact);
}

/// A sphere light of radius R and radiance L at height h > R over a diffuse plane: the sphere
/// is wholly above every point's horizon, so E = π L (R/d)² cos θ with d the distance to its
/// centre and cos θ = h/d. The camera sits between the sphere and the plane, looking down.
#[test]
fn sphere_light_above_a_plane() {
    let (rho, radiance, radius, height) = (0.5f64, 5.0f64, 0.5f64, 2.0f64);
    let center = DVec3::new(0.2, -0.1, height);
    let size = UVec2::new(12, 10);
    let camera = camera(DVec3::new(0.0, 0.0, 1.2), DVec3::ZERO, DVec3::Y, 70.0, size);
    let scene = build(
        vec![
            floor(rho as f32),
            Object {
                shape: sphere(center.as_vec3(), radius as f32),
                reflectance: 0.0,
                emission: Some(radiance as f32),
            },
        ],
        vec![],
        camera.clone(),
        size,
        PathIntegrator::default(),
    );
    let film = render_film(&scene, 512, 32, None);
    assert_pixels("sphere light", &film, &camera, |ray| {
        let x = on_floor(ray);
        let d = (center - x).length();
        let e = PI * radiance * (radius / d).powi(2) * (height / d);
        rho * e / PI
    });
}

/// A `directionalarea` square of side 1 and radiance L, tilted by 45° and facing down, over a
/// diffuse plane, through the particle tracer (the only estimator that renders it) with direct
/// light only: the beam lights the square's oblique projection along its normal n with
/// E = L |n_z| and leaves every other point dark, so a pixel's exact value is ρ L |n_z| / π
/// times the share of its footprint in the projection. Dark pixels must be exactly 0; the
/// others pass the chi-square test of `assert_pixels`.
#[test]
fn directional_area_light_on_a_plane() {
    let (rho, radiance) = (0.5f64, 2.0f64);
    let to_world = DMat4::from_translation(DVec3::new(0.0, -1.5, 1.5))
        * DMat4::from_rotation_x(-0.75 * PI)
        * DMat4::from_scale(DVec3::splat(0.5));
    let center = to_world.transform_point3(DVec3::ZERO);
    let (u, v) = (
        to_world.transform_vector3(DVec3::X),
        to_world.transform_vector3(DVec3::Y),
    );
    let n = u.cross(v).normalize();
    let panel = Shape::Mesh(transform_mesh(
        rectangle(),
        &Transform::new(to_world).unwrap(),
        false,
        true,
    ));
    let size = UVec2::new(16, 12);
    let camera = camera(
        DVec3::new(0.4, -0.3, 2.2),
        DVec3::ZERO,
        DVec3::Y,
        70.0,
        size,
    );
    let scene = build(
        vec![
            floor(rho as f32),
            Object {
                shape: panel.into(),
                reflectance: 0.0,
                emission: None,
            },
        ],
        vec![Light::DirectionalArea(DirectionalAreaLight::new(
            1,
            Texture::constant(radiance as f32),
        ))],
        camera.clone(),
        size,
        ParticleTracer {
            max_depth: 2,
            ..ParticleTracer::default()
        },
    );
    let lit = |ray: &Ray| {
        let x = on_floor(ray);
        let t = (x - center).dot(n);
        let p = x - t * n - center;
        let inside =
            t > 0.0 && p.dot(u).abs() <= u.length_squared() && p.dot(v).abs() <= v.length_squared();
        if inside {
            rho * radiance * n.z.abs() / PI
        } else {
            0.0
        }
    };
    let film = render_film(&scene, 1024, 33, None);
    let (mut statistic, mut lit_pixels, mut expected_sum) = (0.0, 0.0, 0.0);
    for y in 0..size.y {
        for x in 0..size.x {
            let exact = footprint_average(&camera, x, y, &lit);
            let (mean, variance) = pixel_mean_and_variance(&film, film.index(x, y), 1);
            if exact == 0.0 {
                assert!(
                    mean == 0.0,
                    "pixel ({x}, {y}) is outside the beam but has {mean}"
                );
                continue;
            }
            assert!(variance > 0.0, "pixel ({x}, {y}) in the beam has no spread");
            statistic += (mean - exact).powi(2) / variance;
            lit_pixels += 1.0;
            expected_sum += exact;
        }
    }
    assert!(
        lit_pixels > 20.0,
        "only {lit_pixels} pixels are in the beam"
    );
    let (_, se) = image_mean_and_standard_error(&film, 1);
    let pixels = f64::from(size.x * size.y);
    assert!(
        se < 0.0025 * expected_sum / pixels,
        "the standard error {se} is too large to detect a 1 % bias"
    );
    let p_value = regularized_gamma_q(lit_pixels / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-3,
        "chi-square of the pixel errors {statistic} over {lit_pixels} pixels: p = {p_value}"
    );
}

/// Lambert's formula for a polygon light of radiance L seen from x with normal n:
/// E = (L/2) |Σᵢ Θᵢ (n · Γᵢ)|, Θᵢ the angle the edge (pᵢ, pᵢ₊₁) subtends at x and Γᵢ the unit
/// normal of the plane through x and the edge.
fn lambert_polygon(x: DVec3, n: DVec3, vertices: &[DVec3], radiance: f64) -> f64 {
    let mut sum = 0.0;
    for i in 0..vertices.len() {
        let a = (vertices[i] - x).normalize();
        let b = (vertices[(i + 1) % vertices.len()] - x).normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * radiance * sum.abs()
}

/// A 1 × 0.6 rectangle light facing down at height 1 over a diffuse plane; the irradiance by
/// Lambert's polygon formula. Light and BSDF samples both find the rectangle (MIS), the light
/// samples by solid angle and, in a second render, by area.
#[test]
fn rectangle_light_by_lamberts_formula() {
    let (rho, radiance) = (0.5f64, 4.0f64);
    // Mitsuba's rectangle [−1, 1]², turned to face −z, scaled to 1 × 0.6, lifted to z = 1.
    let to_world = DMat4::from_translation(DVec3::new(0.3, 0.0, 1.0))
        * DMat4::from_rotation_x(PI)
        * DMat4::from_scale(DVec3::new(0.5, 0.3, 1.0));
    let light = transform_mesh(rectangle(), &Transform::new(to_world).unwrap(), false, true);
    let vertices: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| to_world.transform_point3(DVec3::new(x, y, 0.0)))
        .collect();
    let size = UVec2::new(12, 10);
    let camera = camera(
        DVec3::new(0.0, -0.3, 0.8),
        DVec3::ZERO,
        DVec3::Y,
        80.0,
        size,
    );
    let scene = build(
        vec![
            floor(rho as f32),
            Object {
                shape: Shape::Mesh(light).into(),
                reflectance: 0.0,
                emission: Some(radiance as f32),
            },
        ],
        vec![],
        camera.clone(),
        size,
        PathIntegrator::default(),
    );
    // Both ways of sampling the rectangle: by the solid angle it subtends (the default) and
    // by area (the lecture's, `sampling="area"`).
    let mut scene = scene;
    for (sampling, seed) in [(ShapeSampling::SolidAngle, 33), (ShapeSampling::Area, 34)] {
        for light in &mut scene.world.lights {
            if let Light::Area(area) = light {
                area.sampling = sampling;
            }
        }
        let film = render_film(&scene, 512, seed, None);
        assert_pixels(
            &format!("rectangle light, {sampling:?}"),
            &film,
            &camera,
            |ray| rho / PI * lambert_polygon(on_floor(ray), DVec3::Z, &vertices, radiance),
        );
    }
}

/// The rectangle light of [`rectangle_light_by_lamberts_formula`] with a 2 × 2 texture of
/// nearest texels as its radiance: each texel covers a quarter of the rectangle, a polygon of
/// constant radiance, so the irradiance is the sum of Lambert's formula over the quarters. The
/// light is sampled by its texture through the uv map and found by BSDF samples, both weighted
/// by the mixture's density (MIS).
#[test]
fn textured_rectangle_light_by_lamberts_formula() {
    let rho = 0.5f64;
    // Row-major, row 0 at v < ½; one black texel.
    let texels = [6.0f32, 1.0, 0.0, 3.0];
    let to_world = DMat4::from_translation(DVec3::new(0.3, 0.0, 1.0))
        * DMat4::from_rotation_x(PI)
        * DMat4::from_scale(DVec3::new(0.5, 0.3, 1.0));
    let light = transform_mesh(rectangle(), &Transform::new(to_world).unwrap(), false, true);
    // Texel (i, j) covers u ∈ [i/2, (i+1)/2], v ∈ [j/2, (j+1)/2]: local x ∈ [i − 1, i], y alike.
    let quarters: Vec<(f64, Vec<DVec3>)> = (0..4)
        .map(|t| {
            let (i, j) = ((t % 2) as f64, (t / 2) as f64);
            let corners = [(i - 1.0, j - 1.0), (i, j - 1.0), (i, j), (i - 1.0, j)];
            let vertices = corners
                .iter()
                .map(|&(x, y)| to_world.transform_point3(DVec3::new(x, y, 0.0)))
                .collect();
            (f64::from(texels[t]), vertices)
        })
        .collect();
    let size = UVec2::new(12, 10);
    let camera = camera(
        DVec3::new(0.0, -0.3, 0.8),
        DVec3::ZERO,
        DVec3::Y,
        80.0,
        size,
    );
    let mut scene = build(
        vec![
            floor(rho as f32),
            Object {
                shape: Shape::Mesh(light).into(),
                reflectance: 0.0,
                emission: Some(1.0),
            },
        ],
        vec![],
        camera.clone(),
        size,
        PathIntegrator::default(),
    );
    let bitmap = Bitmap {
        width: 2,
        height: 2,
        channels: 1,
        data: texels.to_vec(),
        encoding: Encoding::Linear,
    };
    let texture = Texture::Bitmap(Arc::new(BitmapTexture::new(
        &bitmap,
        TextureUse::Emission,
        FilterType::Nearest,
        WrapMode::Clamp,
        UvTransform::IDENTITY,
    )));
    scene.world.lights[0] = Light::Area(AreaLight::new(1, texture));
    let film = render_film(&scene, 512, 34, None);
    assert_pixels("textured rectangle light", &film, &camera, |ray| {
        let x = on_floor(ray);
        rho / PI
            * quarters
                .iter()
                .map(|(radiance, vertices)| lambert_polygon(x, DVec3::Z, vertices, *radiance))
                .sum::<f64>()
    });
}

/// A diffuse sphere that fills the view, in a constant environment of radiance L: every point
/// sees the whole environment above its horizon, so its radiance is ρL (a convex object
/// reflects no light onto itself).
#[test]
fn diffuse_sphere_in_a_constant_environment() {
    let (rho, radiance) = (0.6f32, 1.5f32);
    let size = UVec2::new(10, 10);
    // At distance 3 the unit sphere subtends 19.5°; the image's corners are 14° off the axis.
    let camera = camera(DVec3::new(0.0, 0.0, 3.0), DVec3::ZERO, DVec3::Y, 20.0, size);
    for (name, integrator, seed) in both_integrators(34) {
        let scene = build(
            vec![Object {
                shape: sphere(Vec3::ZERO, 1.0),
                reflectance: rho,
                emission: None,
            }],
            vec![Light::Constant(ConstantLight::new(Spectrum::Constant(
                radiance,
            )))],
            camera.clone(),
            size,
            integrator,
        );
        let film = render_film(&scene, 1024, seed, None);
        assert_pixels(
            &format!("sphere in a constant environment ({name})"),
            &film,
            &camera,
            |_| f64::from(rho * radiance),
        );
    }
}

/// The path tracer and the lecture's distribution ray tracer, which must agree on every
/// closed form, each with its own seed.
fn both_integrators(seed: u64) -> [(&'static str, Integrator, u64); 2] {
    [
        ("path", PathIntegrator::default().into(), seed),
        (
            "distrib",
            DistributionIntegrator::default().into(),
            seed + 1000,
        ),
    ]
}

/// Row values (pole to pole) of a grey environment map that varies only with θ.
const ROWS: [f32; 7] = [8.0, 3.0, 1.0, 0.5, 0.2, 0.1, 0.05];

/// A grey lat-long map with the rows [`ROWS`], 8 pixels wide.
fn rows_map() -> Bitmap {
    let width = 8;
    let data = ROWS
        .iter()
        .flat_map(|&v| std::iter::repeat_n([v; 3], width))
        .flatten()
        .collect();
    Bitmap {
        width,
        height: ROWS.len(),
        channels: 3,
        data,
        encoding: Encoding::Linear,
    }
}

/// The map's radiance at polar angle θ: linear between rows at θ = π j/(H − 1) (Mitsuba's
/// pixel nodes), times `scale`.
fn rows_radiance(theta: f64, scale: f64) -> f64 {
    let y = theta / PI * (ROWS.len() - 1) as f64;
    let j = (y as usize).min(ROWS.len() - 2);
    let f = y - j as f64;
    scale * (f64::from(ROWS[j]) * (1.0 - f) + f64::from(ROWS[j + 1]) * f)
}

/// A diffuse plane under an environment map that varies with θ only, its +y (Mitsuba's "up")
/// turned to the plane's normal +z: E = 2π ∫₀^{π/2} L(θ) cos θ sin θ dθ, and the plane's
/// radiance is ρE/π everywhere. Exercises the map's orientation, its lookup between pixel
/// nodes, importance sampling of the bright zenith, and MIS with BSDF samples that escape.
#[test]
fn diffuse_plane_under_an_environment_map() {
    let (rho, scale) = (0.5f64, 1.5f64);
    let to_world = Transform::new(DMat4::from_rotation_x(PI / 2.0)).unwrap();
    let size = UVec2::new(8, 6);
    let camera = camera(
        DVec3::new(0.3, -0.4, 2.0),
        DVec3::ZERO,
        DVec3::Y,
        50.0,
        size,
    );
    let rows_map_scene = |integrator: Integrator| {
        build(
            vec![floor(rho as f32)],
            vec![Light::Envmap(EnvironmentMap::new(
                rows_map(),
                scale as f32,
                to_world,
            ))],
            camera.clone(),
            size,
            integrator,
        )
    };
    let steps = 100_000;
    let irradiance: f64 = (0..steps)
        .map(|i| {
            let theta = (i as f64 + 0.5) / steps as f64 * PI / 2.0;
            rows_radiance(theta, scale) * theta.cos() * theta.sin()
        })
        .sum::<f64>()
        * 2.0
        * PI
        * (PI / 2.0)
        / steps as f64;
    for (name, integrator, seed) in both_integrators(35) {
        let film = render_film(&rows_map_scene(integrator), 4096, seed, None);
        assert_pixels(
            &format!("plane under an environment map ({name})"),
            &film,
            &camera,
            |_| rho * irradiance / PI,
        );
    }
}

/// Light selection must not change the answer (docs/testing.md, closed-form scenes): a point light
/// and a sphere light over a plane, rendered with selection by importance (by the path and the
/// volumetric path tracers), by power and uniformly, with equal and unequal `sampling_weight`s,
/// against the sum of their closed forms; a point light of weight 0 is never sampled and so adds
/// nothing (as in Mitsuba).
#[test]
fn light_selection_does_not_change_the_answer() {
    let (rho, intensity, radiance, radius) = (0.5f64, 3.0f64, 20.0f64, 0.2f64);
    let point = DVec3::new(-0.6, 0.3, 1.0);
    let center = DVec3::new(0.5, 0.0, 1.5);
    let size = UVec2::new(10, 8);
    let camera = camera(DVec3::new(0.0, 0.0, 0.9), DVec3::ZERO, DVec3::Y, 80.0, size);
    for (selection, (name, integrator), weights, spp, seed) in [
        (LightSelection::Power, [1.0, 1.0], 2048, 36u64),
        (LightSelection::Uniform, [1.0, 1.0], 2048, 37),
        (LightSelection::Power, [0.5, 2.0], 8192, 38),
        (LightSelection::Uniform, [0.5, 2.0], 8192, 39),
        (LightSelection::Uniform, [1.0, 0.0], 2048, 40),
        (LightSelection::Exhaustive, [1.0, 1.0], 2048, 41),
        (LightSelection::Exhaustive, [0.5, 2.0], 8192, 42),
        (LightSelection::Exhaustive, [1.0, 0.0], 2048, 43),
    ]
    .into_iter()
    .map(|(selection, weights, spp, seed)| {
        let path: Integrator = PathIntegrator {
            light_selection: selection,
            ..PathIntegrator::default()
        }
        .into();
        (selection, ("path", path), weights, spp, seed)
    })
    .chain(
        [([1.0, 1.0], 2048, 44), ([0.5, 2.0], 8192, 45)].map(|(weights, spp, seed)| {
            let volpath: Integrator = VolPathIntegrator::default().into();
            (
                LightSelection::Exhaustive,
                ("volpath", volpath),
                weights,
                spp,
                seed,
            )
        }),
    ) {
        let mut scene = build(
            vec![
                floor(rho as f32),
                Object {
                    shape: sphere(center.as_vec3(), radius as f32),
                    reflectance: 0.0,
                    emission: Some(radiance as f32),
                },
            ],
            vec![Light::Point(PointLight {
                position: point.as_vec3(),
                intensity: Spectrum::Constant(intensity as f32),
            })],
            camera.clone(),
            size,
            integrator.clone(),
        );
        assert!(matches!(scene.world.lights[0], Light::Area(_)));
        scene.world.light_sampling_weights = weights.to_vec();
        let film = render_film(&scene, spp, seed, None);
        assert_pixels(
            &format!("two lights, {name} {selection:?}, sampling weights {weights:?}"),
            &film,
            &camera,
            |ray| {
                let x = on_floor(ray);
                let (dp, dc) = ((point - x).length(), (center - x).length());
                let e_point = if weights[1] > 0.0 {
                    intensity * point.z / dp.powi(3)
                } else {
                    0.0
                };
                let e_sphere = PI * radiance * (radius / dc).powi(2) * (center.z / dc);
                rho * (e_point + e_sphere) / PI
            },
        );
    }
}

/// Estimates the flux through the sphere `s` from light samples taken at uniform points x on
/// it: Φ = ∫_S ∫ L(x, ω) |cos(ω, n_x)| dω dA, counting light that crosses S outwards (lights
/// inside S, `outward` = true) or inwards (lights at infinity). Returns (mean, standard error).
fn flux_through_sphere(
    light: &Light,
    shapes: &[Primitive],
    s: BoundingSphere,
    outward: bool,
    seed: u64,
) -> (f64, f64) {
    let n = 2_000_000;
    let area = 4.0 * PI * f64::from(s.radius).powi(2);
    let lambda = SampledWavelengths::single(550.0);
    let mut rng = Pcg32::seeded(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let normal = sample_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
        let x = s.center + normal * s.radius;
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let value = match light.sample_incident(LightQuery {
            shapes,
            reference: x,
            time: 0.0,
            u_choice: rng.next_f32(),
            u,
            lambda: &lambda,
        }) {
            Some(ls) => {
                let cos = f64::from(ls.wi.dot(normal));
                let crosses = if outward { cos < 0.0 } else { cos > 0.0 };
                if crosses {
                    f64::from(ls.radiance[0]) * cos.abs() / f64::from(ls.pdf) * area
                } else {
                    0.0
                }
            }
            None => 0.0,
        };
        sum += value;
        sum2 += value * value;
    }
    let mean = sum / f64::from(n);
    let variance = (sum2 / f64::from(n) - mean * mean) / f64::from(n - 1);
    (mean, variance.sqrt())
}

/// Estimates the flux the light emits from its emission samples (the particle tracer's):
/// Φ = E[L_e |cos θ| / (p_A p_ω)]. Returns (mean, standard error).
fn flux_from_emission(light: &Light, shapes: &[Primitive], seed: u64) -> (f64, f64) {
    let n = 2_000_000;
    let lambda = SampledWavelengths::single(550.0);
    let mut rng = Pcg32::seeded(seed);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let value = light
            .sample_emission(EmissionQuery {
                shapes,
                time: 0.0,
                u_choice: rng.next_f32(),
                u_position: Vec2::new(rng.next_f32(), rng.next_f32()),
                u_direction: Vec2::new(rng.next_f32(), rng.next_f32()),
                lambda: &lambda,
            })
            .map_or(0.0, |e| f64::from(e.weight[0]));
        sum += value;
        sum2 += value * value;
    }
    let mean = sum / f64::from(n);
    // Rounding can leave a constant weight's variance slightly below zero.
    let variance = ((sum2 / f64::from(n) - mean * mean) / f64::from(n - 1)).max(0.0);
    (mean, variance.sqrt())
}

/// Asserts that the estimate (mean, standard error) of Φ from `strategy` equals the closed form
/// within 4 standard errors, with the error small enough for a 1 % bias to show.
fn assert_estimate(name: &str, strategy: &str, (mean, se): (f64, f64), closed_form: f64) {
    assert!(
        se < 0.0025 * closed_form,
        "{name}: standard error {se} of Φ = {closed_form} from {strategy}"
    );
    // A constant weight (a point light's) has no spread: its f32 rounding is the tolerance.
    assert!(
        (mean - closed_form).abs() < 4.0 * se + 1e-6 * closed_form,
        "{name}: Φ from {strategy} is {mean}, the closed form {closed_form} ({:.1} standard errors)",
        (mean - closed_form).abs() / se
    );
}

/// Asserts Φ estimated from the light's emission samples equals the closed form, and that the
/// light reports it.
fn assert_emitted_flux(
    name: &str,
    light: &Light,
    shapes: &[Primitive],
    closed_form: f64,
    seed: u64,
) {
    let estimate = flux_from_emission(light, shapes, seed);
    assert_estimate(name, "emission samples", estimate, closed_form);
    let reported = f64::from(light.power(shapes));
    assert!(
        (reported / closed_form - 1.0).abs() < 1e-3,
        "{name}: the light reports Φ = {reported}, the closed form is {closed_form}"
    );
}

/// Asserts Φ estimated from light samples, and from emission samples, equals the closed form,
/// and that the light reports it.
fn assert_flux(
    name: &str,
    light: &Light,
    shapes: &[Primitive],
    s: BoundingSphere,
    outward: bool,
    closed_form: f64,
    seed: u64,
) {
    let estimate = flux_through_sphere(light, shapes, s, outward, seed);
    assert_estimate(name, "light samples", estimate, closed_form);
    assert_emitted_flux(name, light, shapes, closed_form, seed);
}

/// Φ identities for lights in a finite region: point 4πI, spot 2πI(1 − (sin c − sin β)/(c − β)),
/// projector π · scale · E · 4 tan²(fov/2) / aspect, sphere and rectangle area lights πAL
/// (one-sided), a sphere's directional area light AL.
#[test]
fn flux_of_point_spot_and_area_lights() {
    let around = BoundingSphere {
        center: Vec3::new(0.1, 0.2, -0.1),
        radius: 3.0,
    };
    let point = Light::Point(PointLight {
        position: Vec3::new(0.3, -0.2, 0.4),
        intensity: Spectrum::Constant(2.0),
    });
    assert_flux("point", &point, &[], around, true, 4.0 * PI * 2.0, 41);

    let (cutoff, beam) = (60f64.to_radians(), 25f64.to_radians());
    let spot = Light::Spot(SpotLight::new(
        Transform::new(
            DMat4::from_translation(DVec3::new(0.2, 0.0, 0.1)) * DMat4::from_rotation_x(0.8),
        )
        .unwrap(),
        Spectrum::Constant(3.0),
        cutoff as f32,
        beam as f32,
    ));
    let spot_flux = 2.0 * PI * 3.0 * (1.0 - (cutoff.sin() - beam.sin()) / (cutoff - beam));
    assert_flux("spot", &spot, &[], around, true, spot_flux, 42);

    // A projector of constant irradiance E = 0.8 times 1.5, fov_x 50 degrees, aspect 1.5:
    // Φ = π · 1.5 · 0.8 · 4 tan²(25°) / 1.5.
    let (fov, aspect) = (50f64.to_radians(), 1.5);
    let projector = Light::Projector(Projector::new(
        Transform::new(DMat4::from_rotation_y(0.3)).unwrap(),
        Texture::constant(0.8),
        1.5,
        fov as f32,
        aspect as f32,
    ));
    let t = (0.5 * fov).tan();
    let projector_flux = PI * 1.5 * 0.8 * 4.0 * t * t / aspect;
    assert_emitted_flux("projector", &projector, &[], projector_flux, 48);

    let area = Light::Area(AreaLight::uniform(0, Spectrum::Constant(1.5)));
    let ball = [sphere(Vec3::new(0.0, 0.3, 0.2), 0.7)];
    assert_flux(
        "sphere light",
        &area,
        &ball,
        around,
        true,
        PI * 4.0 * PI * 0.49 * 1.5,
        43,
    );
    let beams = Light::DirectionalArea(DirectionalAreaLight::new(0, Texture::constant(1.5)));
    assert_emitted_flux(
        "directional area light",
        &beams,
        &ball,
        4.0 * PI * 0.49 * 1.5,
        45,
    );
    let to_world =
        Transform::new(DMat4::from_rotation_y(0.4) * DMat4::from_scale(DVec3::new(0.8, 0.5, 1.0)))
            .unwrap();
    let panel = [Shape::Mesh(transform_mesh(rectangle(), &to_world, false, true)).into()];
    assert_flux(
        "rectangle light",
        &area,
        &panel,
        around,
        true,
        PI * 1.6 * 1.5,
        44,
    );
}

/// Φ identities for lights at infinity, through the scene's bounding sphere: directional πR²E,
/// constant 4π²R²L, and an environment map πR² ∫ L dω (the integral by quadrature of the map's
/// own radiance, which its reported power, from its sampling cells, equals for a grey map).
#[test]
fn flux_of_lights_at_infinity() {
    let bounds = BoundingSphere {
        center: Vec3::new(1.0, 0.0, -0.5),
        radius: 2.0,
    };
    let r2 = 4.0;
    let mut directional = Light::Directional(DirectionalLight::new(
        Vec3::new(0.3, -1.0, 0.2).normalize(),
        Spectrum::Constant(2.5),
    ));
    directional.set_scene_bounds(bounds);
    assert_flux(
        "directional",
        &directional,
        &[],
        bounds,
        false,
        PI * r2 * 2.5,
        45,
    );

    let mut constant = Light::Constant(ConstantLight::new(Spectrum::Constant(0.7)));
    constant.set_scene_bounds(bounds);
    assert_flux(
        "constant",
        &constant,
        &[],
        bounds,
        false,
        4.0 * PI * PI * r2 * 0.7,
        46,
    );

    let scale = 1.5;
    let mut map = Light::Envmap(EnvironmentMap::new(
        rows_map(),
        scale as f32,
        Transform::new(DMat4::from_rotation_z(0.5)).unwrap(),
    ));
    map.set_scene_bounds(bounds);
    let steps = 100_000;
    let integral: f64 = (0..steps)
        .map(|i| {
            let theta = (i as f64 + 0.5) / steps as f64 * PI;
            rows_radiance(theta, scale) * theta.sin()
        })
        .sum::<f64>()
        * 2.0
        * PI
        * PI
        / steps as f64;
    let closed_form = PI * r2 * integral;
    // The map's grey is D65 of that luminance: at 550 nm the samples carry D65(550).
    let d65 = f64::from(prism_core::spectrum::cie::d65_normalized(550.0));
    for (strategy, (mean, se)) in [
        (
            "light samples",
            flux_through_sphere(&map, &[], bounds, false, 47),
        ),
        ("emission samples", flux_from_emission(&map, &[], 47)),
    ] {
        assert_estimate(
            "environment map",
            strategy,
            (mean / d65, se / d65),
            closed_form,
        );
    }
    let reported = f64::from(map.power(&[]));
    assert!(
        (reported / closed_form - 1.0).abs() < 1e-4,
        "{reported} vs {closed_form}"
    );
}
