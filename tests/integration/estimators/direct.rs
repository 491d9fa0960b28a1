//! The `direct` integrator against closed forms: a disk light over a diffuse plane (the coaxial
//! disk form factor) with every mix of light and BSDF samples, which tests the MIS weights with
//! sample counts, and a point light over a plane with several light samples (I cos θ / d²).
//! Every pixel must lie within 5 standard errors of the closed form (Bonferroni over the pixels
//! at about 10⁻⁴) and the pixels' standardised errors together pass a chi-square test at 10⁻³.

use glam::{DMat4, DVec3, UVec2, Vec2};
use prism_core::camera::CameraModel;
use prism_core::film::Film;
use prism_core::geometry::Shape;
use prism_core::integrator::DirectIntegrator;
use prism_core::light::{Light, PointLight};
use prism_core::math::Transform;
use prism_core::math::special::regularized_gamma_q;
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
            (mean - exact).abs() < 5.0 * variance.sqrt(),
            "{name}: pixel {i} has {mean}, the closed form {exact} (σ = {})",
            variance.sqrt()
        );
    }
    let pixels = exact.len() as f64;
    let p_value = regularized_gamma_q(pixels / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-3,
        "{name}: chi-square of the pixel errors {statistic} over {pixels} pixels: p = {p_value}"
    );
}

/// Light samples only, BSDF samples only, one of each, and unequal counts: each mix is an
/// unbiased estimate of the same irradiance.
#[test]
fn disk_light_over_a_diffuse_plane_with_every_mix_of_strategies() {
    for (seed, (emitter_samples, bsdf_samples)) in
        [(1, 1), (1, 0), (0, 1), (3, 2)].into_iter().enumerate()
    {
        let mut setup = disk_light_over_plane(UVec2::new(12, 12));
        setup.scene.integrator = DirectIntegrator {
            emitter_samples,
            bsdf_samples,
            hide_emitters: false,
        }
        .into();
        // BSDF sampling alone finds the small disk rarely: it gets more samples.
        let spp = if emitter_samples == 0 { 8192 } else { 1024 };
        let film = render_film(&setup.scene, spp, 40 + seed as u64, None);
        assert_pixels(
            &format!("disk light, {emitter_samples} light and {bsdf_samples} BSDF samples"),
            &film,
            &setup.exact,
        );
    }
}

/// A point light of intensity I at height h over a diffuse plane ρ: L = ρ I h / (π d³), with
/// four light samples, each weighted 1/4.
#[test]
fn point_light_over_a_plane_with_several_light_samples() {
    let (rho, intensity, height) = (0.5f64, 3.0f64, 1.0f64);
    let position = DVec3::new(0.2, 0.1, height);
    let size = UVec2::new(10, 8);
    let camera = camera(DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, DVec3::Y, 60.0, size);
    let plane = Transform::new(DMat4::from_scale(DVec3::splat(50.0))).unwrap();
    let scene = build(
        vec![Object {
            shape: Shape::Mesh(transform_mesh(rectangle(), &plane, false, true)).into(),
            reflectance: rho as f32,
            emission: None,
        }],
        vec![Light::Point(PointLight {
            position: position.as_vec3(),
            intensity: Spectrum::Constant(intensity as f32),
        })],
        camera.clone(),
        size,
        DirectIntegrator {
            emitter_samples: 4,
            bsdf_samples: 1,
            hide_emitters: false,
        },
    );
    let film = render_film(&scene, 256, 45, None);
    let n = 32;
    let mut exact = Vec::new();
    for y in 0..size.y {
        for x in 0..size.x {
            let mut sum = 0.0;
            for j in 0..n {
                for i in 0..n {
                    let offset =
                        Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    let ray = camera.generate_ray(
                        Vec2::new(x as f32, y as f32) + offset,
                        Vec2::splat(0.5),
                        0.0,
                    );
                    let t = -ray.o.z / ray.d.z;
                    let p = (ray.o + ray.d * t).as_dvec3();
                    let d = (position - p).length();
                    sum += rho * intensity * height / (std::f64::consts::PI * d.powi(3));
                }
            }
            exact.push(sum / f64::from(n * n));
        }
    }
    assert_pixels("point light", &film, &exact);
}
