//! The `direct` integrator against closed forms, with every count of light samples and BSDF
//! samples from 0 to 4 each (but none of either, which the reader refuses), under each kind of
//! light over a diffuse plane ρ: a disk light (the coaxial disk form factor), a point light
//! (ρ I h / (π d³)), a spot light (the same times its falloff) and a constant environment
//! (ρ L). The counts must not change the expected value, so this tests the sample weights and
//! the MIS weights with unequal counts; BSDF samples alone never find a point or a spot, whose
//! images are then black. Every pixel must lie within 5 standard errors of the closed form
//! (Bonferroni over the pixels at about 10⁻⁴) and the pixels' standardised errors together pass
//! a chi-square test at 10⁻⁵ (10⁻³ over the 24 counts of a light).

use glam::{DMat4, DVec3, UVec2, Vec2};
use prism_core::camera::{Camera, CameraModel};
use prism_core::film::Film;
use prism_core::geometry::Shape;
use prism_core::integrator::DirectIntegrator;
use prism_core::light::{ConstantLight, Light, PointLight, SpotLight};
use prism_core::math::Transform;
use prism_core::math::special::regularized_gamma_q;
use prism_core::scene::Scene;
use prism_core::spectrum::Spectrum;
use prism_mitsuba::factory::shapes::{rectangle, transform_mesh};

use crate::common::scenes::{
    Object, build, camera, disk_light_over_plane, pixel_mean_and_variance, render_film,
};

fn assert_pixels(name: &str, film: &Film, exact: &[f64]) {
    let mut statistic = 0.0;
    for (i, exact) in exact.iter().enumerate() {
        let (mean, variance) = pixel_mean_and_variance(film, i, 1);
        assert!(
            variance > 0.0 || mean == *exact,
            "{name}: pixel {i} has no spread"
        );
        statistic += if variance > 0.0 {
            (mean - exact).powi(2) / variance
        } else {
            0.0
        };
        assert!(
            (mean - exact).abs() <= 5.0 * variance.sqrt(),
            "{name}: pixel {i} has {mean}, the closed form {exact} (σ = {})",
            variance.sqrt()
        );
    }
    let pixels = exact.len() as f64;
    let p_value = regularized_gamma_q(pixels / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-5,
        "{name}: chi-square of the pixel errors {statistic} over {pixels} pixels: p = {p_value}"
    );
}

/// Renders `scene` with every count of light and BSDF samples, and compares each image with
/// `exact`, or with black where only BSDF samples look for a `delta` light. BSDF samples alone
/// find a small light rarely: they get `bsdf_only_spp` samples per pixel, the others `spp`.
fn assert_every_count(
    light: &str,
    mut scene: Scene,
    exact: &[f64],
    delta: bool,
    (spp, bsdf_only_spp): (u32, u32),
) {
    let mut seed = 60;
    for emitter_samples in 0..=4 {
        for bsdf_samples in 0..=4 {
            if emitter_samples + bsdf_samples == 0 {
                continue;
            }
            scene.integrator = DirectIntegrator {
                emitter_samples,
                bsdf_samples,
                hide_emitters: false,
            }
            .into();
            seed += 1;
            let samples = if emitter_samples == 0 {
                bsdf_only_spp
            } else {
                spp
            };
            let film = render_film(&scene, samples, seed, None);
            let black = vec![0.0; exact.len()];
            let expected = if delta && emitter_samples == 0 {
                &black
            } else {
                exact
            };
            assert_pixels(
                &format!("{light}, {emitter_samples} light and {bsdf_samples} BSDF samples"),
                &film,
                expected,
            );
        }
    }
}

/// Each pixel's average of `radiance` at the points of the plane z = 0 its rays reach (32 × 32
/// midpoint quadrature through the camera).
fn exact_over_plane(camera: &Camera, size: UVec2, radiance: impl Fn(DVec3) -> f64) -> Vec<f64> {
    let n = 32;
    let mut exact = Vec::new();
    for y in 0..size.y {
        for x in 0..size.x {
            let mut sum = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let offset =
                        Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    let ray = camera
                        .generate_ray(
                            Vec2::new(x as f32, y as f32) + offset,
                            Vec2::splat(0.5),
                            0.0,
                        )
                        .ray;
                    let t = -ray.o.z / ray.d.z;
                    sum += radiance((ray.o + ray.d * t).as_dvec3());
                }
            }
            exact.push(sum / f64::from(n * n));
        }
    }
    exact
}

/// The diffuse plane z = 0 of reflectance `rho` (a square of side 100) under `light`, seen
/// from above.
fn plane_under(rho: f64, light: Light, size: UVec2) -> (Scene, Camera) {
    let camera = camera(DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, DVec3::Y, 60.0, size);
    let plane = Transform::new(DMat4::from_scale(DVec3::splat(50.0))).unwrap();
    let scene = build(
        vec![Object {
            shape: Shape::Mesh(transform_mesh(rectangle(), &plane, false, true)).into(),
            reflectance: rho as f32,
            emission: None,
        }],
        vec![light],
        camera.clone(),
        size,
        DirectIntegrator::default(),
    );
    (scene, camera)
}

#[test]
fn disk_light_with_every_count_of_samples() {
    let setup = disk_light_over_plane(UVec2::new(8, 8));
    assert_every_count("disk light", setup.scene, &setup.exact, false, (512, 8192));
}

/// A point light of intensity I at height h over the plane: L = ρ I h / (π d³).
#[test]
fn point_light_with_every_count_of_samples() {
    let (rho, intensity) = (0.5, 3.0);
    let position = DVec3::new(0.2, 0.1, 1.0);
    let size = UVec2::new(10, 8);
    let light = Light::Point(PointLight {
        position: position.as_vec3(),
        intensity: Spectrum::Constant(intensity as f32),
    });
    let (scene, camera) = plane_under(rho, light, size);
    let exact = exact_over_plane(&camera, size, |p| {
        let d = (position - p).length();
        rho * intensity * position.z / (std::f64::consts::PI * d.powi(3))
    });
    assert_every_count("point light", scene, &exact, true, (256, 256));
}

/// A spot light pointing straight down from height h, full within 20° of its axis and falling
/// linearly in the angle to 0 at 65°: the point light's L times the falloff. The film sees the
/// full beam and the falloff (whose edge it does not reach, where a pixel lit on a sliver would
/// need many samples).
#[test]
fn spot_light_with_every_count_of_samples() {
    let (rho, intensity) = (0.5, 3.0);
    let position = DVec3::new(0.2, 0.1, 1.0);
    let (cutoff, beam) = (65f64.to_radians(), 20f64.to_radians());
    let size = UVec2::new(10, 8);
    let to_world = Transform::new(
        DMat4::from_translation(position) * DMat4::from_rotation_x(std::f64::consts::PI),
    )
    .unwrap();
    let light = Light::Spot(SpotLight::new(
        to_world,
        Spectrum::Constant(intensity as f32),
        cutoff as f32,
        beam as f32,
    ));
    let (scene, camera) = plane_under(rho, light, size);
    let exact = exact_over_plane(&camera, size, |p| {
        let d = (position - p).length();
        let angle = (position.z / d).acos();
        let falloff = ((cutoff - angle) / (cutoff - beam)).clamp(0.0, 1.0);
        falloff * rho * intensity * position.z / (std::f64::consts::PI * d.powi(3))
    });
    assert_every_count("spot light", scene, &exact, true, (256, 256));
}

/// A constant environment of radiance L over the plane, which hides none of it: L_o = ρ L.
#[test]
fn constant_environment_with_every_count_of_samples() {
    let (rho, radiance) = (0.5, 0.8);
    let size = UVec2::new(8, 8);
    let light = Light::Constant(ConstantLight::new(Spectrum::Constant(radiance as f32)));
    let (scene, _) = plane_under(rho, light, size);
    let exact = vec![rho * radiance; (size.x * size.y) as usize];
    assert_every_count("constant environment", scene, &exact, false, (256, 256));
}

/// The warning of a scene combining `direct`'s several emitter samples with delta lights, at
/// the sample count, as `line:column: message`; none for one sample or without delta lights.
#[test]
fn several_emitter_samples_with_delta_lights_warn() {
    let warnings = |integrator: &str, emitters: &str| -> Vec<String> {
        let xml = format!(
            "<scene version=\"3.0.0\">\n{integrator}\n\
             <sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/><integer name=\"height\" value=\"4\"/></film></sensor>\n\
             <shape type=\"rectangle\"><emitter type=\"area\"/></shape>\n{emitters}\n</scene>"
        );
        let root =
            prism_mitsuba::reader::read_scene_str(&xml, std::path::Path::new("direct.xml"), &[])
                .unwrap_or_else(|e| panic!("{e}"));
        let loaded = prism_mitsuba::factory::build_scene(&root).unwrap_or_else(|e| panic!("{e}"));
        (loaded.warnings.iter())
            .map(|w| format!("{}:{}: {}", w.location.line, w.location.column, w.message))
            .collect()
    };
    let point = r#"<emitter type="point"><point name="position" x="0" y="0" z="2"/></emitter>"#;
    let spot = r#"<emitter type="spot"/>"#;
    let four =
        r#"<integrator type="direct"><integer name="emitter_samples" value="4"/></integrator>"#;
    assert_eq!(
        warnings(four, &format!("{spot}{point}{spot}")),
        [
            "2:27: direct with 4 emitter samples in a scene with point, spot lights: Mitsuba 3 \
          counts each sample of a point, spot, projector or directional light with weight 1 \
          instead of 1/4, so its image of them is 4 times too bright; Prism weighs every light \
          sample 1/4"
        ]
    );
    let shading =
        r#"<integrator type="direct"><integer name="shading_samples" value="3"/></integrator>"#;
    let found = warnings(shading, spot);
    assert!(
        found.len() == 1 && found[0].starts_with("2:27: direct with 3 emitter samples"),
        "{found:?}"
    );
    let one =
        r#"<integrator type="direct"><integer name="emitter_samples" value="1"/></integrator>"#;
    assert!(warnings(one, point).is_empty());
    assert!(warnings(four, "").is_empty());
    let path = r#"<integrator type="path"/>"#;
    assert!(warnings(path, point).is_empty());
}
