//! Lights that project an image: the `projector`'s irradiance on a plane facing it and its flux
//! against their closed forms, and the `spot` light's projected texture. Both are Dirac deltas
//! in position, so each light sample is exact and the tests compare numbers, not statistics.

use std::f32::consts::PI;
use std::sync::Arc;

use glam::{DMat4, DVec3, Vec2, Vec3};
use prism_core::image::{Bitmap, Encoding};
use prism_core::light::{Light, LightQuery, LightSource, Projector, SpotLight};
use prism_core::math::Transform;
use prism_core::spectrum::{SampledWavelengths, Spectrum};
use prism_core::texture::{BitmapTexture, FilterType, Texture, TextureUse, UvTransform, WrapMode};

/// A 4 × 2 grey image (row-major, row 0 at v < ½) of nearest texels, one of them black and one
/// brighter than 1.
const WIDTH: usize = 4;
const HEIGHT: usize = 2;
const TEXELS: [f32; 8] = [0.2, 0.9, 0.5, 0.0, 3.0, 0.7, 0.1, 0.4];

fn image() -> Texture {
    let bitmap = Bitmap {
        width: WIDTH,
        height: HEIGHT,
        channels: 1,
        data: TEXELS.to_vec(),
        encoding: Encoding::Linear,
    };
    Texture::Bitmap(Arc::new(BitmapTexture::new(
        &bitmap,
        TextureUse::Emission,
        FilterType::Nearest,
        WrapMode::Clamp,
        UvTransform::IDENTITY,
    )))
}

/// The centre of texel (i, j) in texture coordinates.
fn texel_centre(i: usize, j: usize) -> Vec2 {
    Vec2::new(
        (i as f32 + 0.5) / WIDTH as f32,
        (j as f32 + 0.5) / HEIGHT as f32,
    )
}

fn assert_close(value: f32, expected: f32, what: &str) {
    assert!(
        (value - expected).abs() <= 1e-4 * expected.abs().max(1e-3),
        "{what}: {value} instead of {expected}"
    );
}

const LAMBDA: f32 = 550.0;

/// A projector at the origin looking along +z, with a field of view of 60° across the image's
/// width and the image's aspect ratio 2. On the plane z = z₀ facing it, the irradiance is
/// π · scale · E(u, v) / z₀² with (u, v) = (½ − x / (2 z₀ t), ½ − a y / (2 z₀ t)),
/// t = tan 30°: checked at every texel's centre, on two planes; points beyond the image and
/// behind the projector receive nothing.
#[test]
fn projector_irradiance_on_a_plane_matches_the_closed_form() {
    let scale = 2.0;
    let fov = 60f32.to_radians();
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let projector = Light::Projector(Projector::new(
        Transform::IDENTITY,
        image(),
        scale,
        fov,
        aspect,
    ));
    let t = (0.5 * fov).tan();
    let lambda = SampledWavelengths::single(LAMBDA);
    for z0 in [1.0f32, 2.5] {
        for j in 0..HEIGHT {
            for i in 0..WIDTH {
                let uv = texel_centre(i, j);
                let p = Vec3::new(
                    (0.5 - uv.x) * 2.0 * z0 * t,
                    (0.5 - uv.y) * 2.0 * z0 * t / aspect,
                    z0,
                );
                let expected = PI * scale * TEXELS[j * WIDTH + i] / (z0 * z0);
                let received = projector
                    .sample_incident(LightQuery {
                        shapes: &[],
                        reference: p,
                        time: 0.0,
                        u_choice: 0.5,
                        u: Vec2::splat(0.5),
                        lambda: &lambda,
                    })
                    .map_or(0.0, |ls| {
                        assert!(ls.is_delta && ls.p == Vec3::ZERO);
                        // The plane's normal is −z.
                        ls.radiance[0] * ls.wi.dot(-Vec3::Z).abs()
                    });
                assert_close(received, expected, &format!("texel ({i}, {j}) at z = {z0}"));
            }
        }
    }
    for p in [
        Vec3::new(1.2 * t, 0.0, 1.0),
        Vec3::new(0.0, 0.6 * t, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
    ] {
        assert!(
            projector
                .sample_incident(LightQuery {
                    shapes: &[],
                    reference: p,
                    time: 0.0,
                    u_choice: 0.5,
                    u: Vec2::splat(0.5),
                    lambda: &lambda
                })
                .is_none(),
            "{p} lies outside the projected image"
        );
    }
}

/// The flux through the plane z = 1 (the irradiance integrated over the image's rectangle
/// there, [−t, t] × [−t/a, t/a], by the midpoint rule on a grid aligned with the texels, exact
/// for nearest texels) is π · scale · mean(E) · 4t²/a, the power the light sampler uses.
#[test]
fn projector_power_is_its_flux() {
    let (scale, fov, aspect) = (0.7f32, 40f32.to_radians(), 2.0f32);
    let projector = Projector::new(Transform::IDENTITY, image(), scale, fov, aspect);
    let t = (0.5 * fov).tan();
    let lambda = SampledWavelengths::single(LAMBDA);
    let (nx, ny) = (WIDTH * 16, HEIGHT * 16);
    let (width, height) = (2.0 * t, 2.0 * t / aspect);
    let cell_area = f64::from(width * height) / (nx * ny) as f64;
    let flux: f64 = (0..nx * ny)
        .map(|cell| {
            let x = -t + width * ((cell % nx) as f32 + 0.5) / nx as f32;
            let y = -t / aspect + height * ((cell / nx) as f32 + 0.5) / ny as f32;
            let ls = projector.sample_incident(LightQuery {
                shapes: &[],
                reference: Vec3::new(x, y, 1.0),
                time: 0.0,
                u_choice: 0.5,
                u: Vec2::ZERO,
                lambda: &lambda,
            });
            ls.map_or(0.0, |ls| f64::from(ls.radiance[0] * ls.wi.z.abs()))
        })
        .sum::<f64>()
        * cell_area;
    assert!(
        (f64::from(projector.power(&[])) / flux - 1.0).abs() < 1e-3,
        "power {} against the flux {flux}",
        projector.power(&[])
    );
}

/// A spot light with a texture, turned by its transform: in direction (x, y, z) of its frame
/// the intensity is I · falloff · E(½ + x / (2 z tan c), ½ + y / (2 z tan c)), checked at
/// texel centres within the beam (full intensity) and at one in the falloff ramp.
#[test]
fn spot_light_projects_its_texture() {
    let (cutoff, beam) = (35f32.to_radians(), 30f32.to_radians());
    let to_world = Transform::new(
        DMat4::from_translation(DVec3::new(0.5, -0.2, 1.0))
            * DMat4::from_rotation_x(0.6)
            * DMat4::from_rotation_z(0.3),
    )
    .unwrap();
    let spot =
        SpotLight::new(to_world, Spectrum::Constant(2.0), cutoff, beam).with_texture(image());
    let light = Light::Spot(spot.clone());
    let lambda = SampledWavelengths::single(LAMBDA);
    let k = cutoff.tan();
    let mut checked = 0;
    for j in 0..HEIGHT {
        for i in 0..WIDTH {
            let uv = texel_centre(i, j);
            // The direction of the light's frame that sees uv, at z = 1.
            let local = Vec3::new((uv.x - 0.5) * 2.0 * k, (uv.y - 0.5) * 2.0 * k, 1.0);
            let falloff = spot.falloff(local);
            if falloff == 0.0 {
                continue;
            }
            let distance = 1.7;
            let reference =
                to_world.point(Vec3::ZERO) + to_world.vector(local).normalize() * distance;
            let expected = 2.0 * falloff * TEXELS[j * WIDTH + i];
            let intensity = light
                .sample_incident(LightQuery {
                    shapes: &[],
                    reference,
                    time: 0.0,
                    u_choice: 0.5,
                    u: Vec2::splat(0.5),
                    lambda: &lambda,
                })
                .map_or(0.0, |ls| ls.radiance[0] * distance * distance);
            assert_close(intensity, expected, &format!("texel ({i}, {j})"));
            checked += 1;
        }
    }
    assert!(checked >= 4, "only {checked} texels lie within the cone");
}
