//! Scenes built in code for the closed-form tests (docs/testing.md, closed-form scenes), and
//! statistics of rendered films.

use glam::{DMat4, DVec3, UVec2, Vec2};
use prism_core::bsdf::{Bsdf, Diffuse, Material};
use prism_core::camera::{Camera, CameraModel, PerspectiveCamera};
use prism_core::film::{BoxFilter, CropWindow, Film, Filter, Reconstruction};
use prism_core::geometry::{Geometry, Primitive, Shape};
use prism_core::integrator::{Integrator, PathIntegrator};
use prism_core::light::{AreaLight, Light};
use prism_core::math::special::regularized_gamma_q;
use prism_core::math::transform::look_at;
use prism_core::math::{AnimatedTransform, Transform};
use prism_core::render::{RenderOptions, render};
use prism_core::scene::{FilmSettings, SamplerKind, SamplerSettings, Scene};
use prism_core::spectrum::{Spectrum, WavelengthSampling};
use prism_core::world::{ShapeInfo, World};

/// A shape with a one-sided diffuse material and, optionally, constant emitted radiance.
pub struct Object {
    pub shape: Primitive,
    pub reflectance: f32,
    pub emission: Option<f32>,
}

/// A pinhole camera at `origin` looking at `target` with horizontal field of view `fov`.
pub fn camera(origin: DVec3, target: DVec3, up: DVec3, fov_degrees: f64, size: UVec2) -> Camera {
    Camera::Perspective(PerspectiveCamera {
        to_world: AnimatedTransform::fixed(
            Transform::new(look_at(origin, target, up).unwrap()).unwrap(),
        ),
        film_size: Vec2::new(size.x as f32, size.y as f32),
        tan_half_fov_x: (0.5 * fov_degrees).to_radians().tan() as f32,
        near_clip: 1e-3,
        far_clip: 1e4,
        lens_radius: 0.0,
        focus_distance: 1.0,
        principal_point_offset: Vec2::ZERO,
    })
}

/// A scene from objects and extra (non-area) lights, with a box-filtered film.
pub fn build(
    objects: Vec<Object>,
    extra_lights: Vec<Light>,
    camera: Camera,
    size: UVec2,
    integrator: impl Into<Integrator>,
) -> Scene {
    let mut shapes = Vec::new();
    let mut info = Vec::new();
    let mut materials = Vec::new();
    let mut lights = Vec::new();
    for (i, object) in objects.into_iter().enumerate() {
        materials.push(Material {
            front: Bsdf::Diffuse(Diffuse {
                reflectance: prism_core::texture::Texture::constant(object.reflectance),
            }),
            back: None,
        });
        let light = object.emission.map(|radiance| {
            lights.push(Light::Area(AreaLight::uniform(
                i as u32,
                Spectrum::Constant(radiance),
            )));
            (lights.len() - 1) as u32
        });
        info.push(ShapeInfo {
            material: i as u32,
            light,
        });
        shapes.push(object.shape);
    }
    lights.extend(extra_lights);
    Scene::new(
        World::new(Geometry::new(shapes), info, materials, lights),
        camera,
        FilmSettings {
            size,
            crop: CropWindow {
                offset: UVec2::ZERO,
                size,
            },
            filter: Filter::Box(BoxFilter { radius: 0.5 }),
            reconstruction: Reconstruction::default(),
            wavelength_sampling: WavelengthSampling::default(),
            bands: Vec::new(),
            response: None,
        },
        SamplerSettings {
            kind: SamplerKind::Independent,
            samples_per_pixel: 1,
        },
        integrator.into(),
    )
}

/// The scene of the Mitsuba XML `xml`, files it names resolved beside the (virtual) file
/// `name`.
pub fn scene_from_xml(xml: &str, name: &str) -> prism_core::error::Result<Scene> {
    let root = prism_mitsuba::reader::read_scene_str(xml, std::path::Path::new(name), &[])?;
    Ok(prism_mitsuba::factory::build_scene(&root)?.scene)
}

/// Renders with a fixed seed and no progress bar.
pub fn render_film(scene: &Scene, spp: u32, seed: u64, threads: Option<usize>) -> Film {
    render(scene, &RenderOptions::fixed(spp, seed, threads))
        .unwrap()
        .film
}

/// A pixel's estimate of channel `c` (0 = X, 1 = Y, 2 = Z), as the image holds it (with filter
/// MIS's control variate where samples are shared), and the variance of that estimate, as the
/// image's variance channels hold it ([`prism_core::film::PixelSums::variance_of_mean`]).
pub fn pixel_mean_and_variance(film: &Film, index: usize, c: usize) -> (f64, f64) {
    let p = &film.pixels[index];
    (p.mean()[c], p.variance_of_mean(c))
}

/// The image's mean of channel `c` and its standard error (pixels are independent).
pub fn image_mean_and_standard_error(film: &Film, c: usize) -> (f64, f64) {
    let count = film.pixels.len() as f64;
    let (sum, variance) = (0..film.pixels.len())
        .map(|i| pixel_mean_and_variance(film, i, c))
        .fold((0.0, 0.0), |(s, v), (m, var)| (s + m, v + var));
    (sum / count, variance.sqrt() / count)
}

/// Asserts that a film's mean luminance Y equals `expected` within 4 standard errors (a false
/// alarm has probability 6·10⁻⁵), and that the error is small enough for a 1 % bias to be seen.
pub fn assert_mean_luminance(name: &str, film: &Film, expected: f64) {
    let (mean, se) = image_mean_and_standard_error(film, 1);
    assert!(
        se < 0.0025 * expected,
        "{name}: the standard error {se} is too large to detect a 1 % bias in {expected}"
    );
    assert!(
        (mean - expected).abs() < 4.0 * se,
        "{name}: mean Y {mean} differs from the closed form {expected} by {:.2} standard errors ({se})",
        (mean - expected).abs() / se
    );
}

/// A disk light of radius R = 0.5 and radiance L = 4 facing down from height h = 1 over a diffuse
/// plane of reflectance ρ = 0.5, seen from below the disk (which the camera never sees), with
/// direct lighting only. The irradiance at horizontal distance r from the axis is
/// (π L / 2)(1 − (h² + r² − R²) / √((h² + r² + R²)² − 4 r² R²)) (the parallel coaxial disk form
/// factor), and L_o = ρ E / π; `exact` holds each pixel's average of it over the pixel (32 × 32
/// midpoint quadrature through the camera).
pub struct DiskOverPlane {
    pub scene: Scene,
    pub exact: Vec<f64>,
}

impl DiskOverPlane {
    /// Checks a render `film` of the scene against the exact values: each pixel, by the
    /// variance the film reports for it, in a chi-square test at significance 10⁻³, and the
    /// image's mean within 4 standard errors, which must be below 1 % of the exact mean (so
    /// that the test can tell a wrong image).
    pub fn assert_matches(&self, film: &Film) {
        let (mut statistic, mut pixels) = (0.0, 0.0);
        let (mut difference, mut variance_sum) = (0.0, 0.0);
        for (i, exact) in self.exact.iter().enumerate() {
            let (mean, variance) = pixel_mean_and_variance(film, i, 1);
            assert!(variance > 0.0, "pixel {i} has no spread");
            statistic += (mean - exact).powi(2) / variance;
            difference += mean - exact;
            variance_sum += variance;
            pixels += 1.0;
        }
        let p_value = regularized_gamma_q(pixels / 2.0, statistic / 2.0);
        assert!(
            p_value > 1e-3,
            "chi-square {statistic} over {pixels} pixels: p = {p_value}"
        );
        let (bias, se) = (difference / pixels, variance_sum.sqrt() / pixels);
        let mean_exact = self.exact.iter().sum::<f64>() / pixels;
        assert!(
            se < 0.01 * mean_exact,
            "the standard error {se} is too large"
        );
        assert!(bias.abs() < 4.0 * se, "mean differs by {bias} ± {se}");
    }
}

pub fn disk_light_over_plane(size: UVec2) -> DiskOverPlane {
    use prism_core::geometry::Disk;
    use prism_mitsuba::factory::shapes::{rectangle, transform_mesh};
    let (rho, radiance, radius, height) = (0.5f64, 4.0f64, 0.5f64, 1.0f64);
    let camera = camera(
        DVec3::new(0.0, -1.2, 0.8),
        DVec3::ZERO,
        DVec3::Z,
        50.0,
        size,
    );
    let plane = Transform::new(DMat4::from_scale(DVec3::splat(50.0))).unwrap();
    let disk = Transform::new(
        DMat4::from_translation(DVec3::new(0.0, 0.0, height))
            * DMat4::from_rotation_x(std::f64::consts::PI)
            * DMat4::from_scale(DVec3::splat(radius)),
    )
    .unwrap();
    let scene = build(
        vec![
            Object {
                shape: Shape::Mesh(transform_mesh(rectangle(), &plane, false, true)).into(),
                reflectance: rho as f32,
                emission: None,
            },
            Object {
                shape: Shape::Disk(Disk::new(disk, false)).into(),
                reflectance: 0.0,
                emission: Some(radiance as f32),
            },
        ],
        vec![],
        camera.clone(),
        size,
        PathIntegrator {
            max_depth: 2,
            ..PathIntegrator::default()
        },
    );
    let exitant = |film_position: Vec2| -> f64 {
        let ray = camera
            .generate_ray(film_position, Vec2::splat(0.5), 0.0)
            .ray;
        let t = -ray.o.z / ray.d.z;
        let x = (ray.o + ray.d * t).as_dvec3();
        let r2 = x.x * x.x + x.y * x.y;
        let (h2, big_r2) = (height * height, radius * radius);
        let e = std::f64::consts::PI * radiance / 2.0
            * (1.0 - (h2 + r2 - big_r2) / ((h2 + r2 + big_r2).powi(2) - 4.0 * r2 * big_r2).sqrt());
        rho * e / std::f64::consts::PI
    };
    let quadrature = 32;
    let mut exact = Vec::new();
    for y in 0..size.y {
        for x in 0..size.x {
            let mut sum = 0.0;
            for j in 0..quadrature {
                for i in 0..quadrature {
                    let offset = Vec2::new(
                        (i as f32 + 0.5) / quadrature as f32,
                        (j as f32 + 0.5) / quadrature as f32,
                    );
                    sum += exitant(Vec2::new(x as f32, y as f32) + offset);
                }
            }
            exact.push(sum / f64::from(quadrature * quadrature));
        }
    }
    DiskOverPlane { scene, exact }
}

/// Every channel of two EXR files, compared bit for bit.
pub fn assert_identical_images(a: &std::path::Path, b: &std::path::Path) {
    let (a, b) = (
        prism_core::image::read_exr(a).unwrap(),
        prism_core::image::read_exr(b).unwrap(),
    );
    assert_eq!((a.width, a.height), (b.width, b.height));
    for (name, values) in &a.channels {
        let other = b
            .channel(name)
            .unwrap_or_else(|| panic!("channel {name} missing"));
        let same = values
            .iter()
            .zip(other)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "channel {name} differs");
    }
}
