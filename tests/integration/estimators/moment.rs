//! The `moment` integrator and the film's extra channels: channel names as Mitsuba writes them,
//! the first moments equal to the image's own sums, the second moments equal to the sums of
//! squares the film keeps for the image's variance, the second moment of a constant environment
//! against its value integrated over the wavelength samples, and extra channels that are
//! bit-identical for any thread count and when a render is resumed.

use glam::{DMat4, DVec3, Mat3, UVec2, Vec3};
use prism_core::film::Film;
use prism_core::film::accumulation::AOV_SUMS_PER_CHANNEL;
use prism_core::geometry::{Shape, Sphere};
use prism_core::integrator::{DirectIntegrator, Integrator, MomentIntegrator, PathIntegrator};
use prism_core::light::{ConstantLight, Light};
use prism_core::math::Transform;
use prism_core::render::resume::InitialState;
use prism_core::render::{RenderOptions, StopRule, render};
use prism_core::scene::Scene;
use prism_core::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use prism_mitsuba::factory::shapes::{cube, transform_mesh};

use crate::common::scenes::{Object, build, camera, render_film};

fn moment_of(integrators: Vec<(&str, Integrator)>) -> Integrator {
    MomentIntegrator {
        integrators: integrators
            .into_iter()
            .map(|(name, integrator)| (name.to_string(), integrator))
            .collect(),
    }
    .into()
}

/// A diffuse room lit by an emitting sphere, seen from inside.
fn room(integrator: Integrator) -> Scene {
    let size = UVec2::new(19, 13);
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

fn two_nested() -> Integrator {
    moment_of(vec![
        ("pt", PathIntegrator::default().into()),
        ("_arg_0", DirectIntegrator::default().into()),
    ])
}

fn channel(film: &Film, name: &str) -> usize {
    film.aov_names
        .iter()
        .position(|n| n == name)
        .unwrap_or_else(|| panic!("no channel {name} in {:?}", film.aov_names))
}

/// `prefix.X`, `prefix.Y`, `prefix.Z`.
fn xyz(prefix: &str) -> Vec<String> {
    ["X", "Y", "Z"].map(|c| format!("{prefix}.{c}")).to_vec()
}

/// Each nested integrator's own channels (prefixed by its name), then its XYZ; then the `m2_`
/// of all of them, as Mitsuba's moment integrator names them.
#[test]
fn channel_names_are_mitsubas() {
    let mut first: Vec<String> = [xyz("pt"), xyz("_arg_0")].concat();
    let mut expected = first.clone();
    expected.extend(first.iter().map(|n| format!("m2_{n}")));
    assert_eq!(two_nested().aov_names(), expected);

    let nested = moment_of(vec![
        ("outer", two_nested()),
        ("dd", DirectIntegrator::default().into()),
    ]);
    first = expected.iter().map(|n| format!("outer.{n}")).collect();
    first.extend([xyz("outer"), xyz("dd")].concat());
    let mut expected = first.clone();
    expected.extend(first.iter().map(|n| format!("m2_{n}")));
    assert_eq!(nested.aov_names(), expected);
}

/// The first nested integrator makes the image, bit for bit as alone; its first-moment channels
/// are the image's sums, and its second moments the sums of squares behind the variance
/// channels (these are kept with 36 fraction bits, the channels with 56, and the square is
/// taken in f32: hence the tolerance).
#[test]
fn moments_are_the_images_sums_and_sums_of_squares() {
    let spp = 16;
    let moment = render_film(&room(two_nested()), spp, 7, Some(2));
    let plain = render_film(&room(PathIntegrator::default().into()), spp, 7, Some(2));
    assert_eq!(moment.pixels, plain.pixels);
    let k = AOV_SUMS_PER_CHANNEL * moment.aov_names.len();
    for (c, axis) in ["X", "Y", "Z"].iter().enumerate() {
        let first = channel(&moment, &format!("pt.{axis}"));
        let second = channel(&moment, &format!("m2_pt.{axis}"));
        let direct = channel(&moment, &format!("_arg_0.{axis}"));
        let mut direct_total = 0.0;
        for (i, p) in moment.pixels.iter().enumerate() {
            assert_eq!(moment.aovs[i * k + first], p.xyz[c], "pixel {i}");
            let squares = p.sum_of_squares(c);
            let m2 = moment.aovs[i * k + second].value();
            assert!(
                (m2 - squares).abs() <= 1e-6 * squares + spp as f64 * 2f64.powi(-36),
                "pixel {i}: m2 {m2}, sum of squares {squares}"
            );
            direct_total += moment.aovs[i * k + direct].value();
        }
        assert!(direct_total > 0.0, "the direct channel {axis} is black");
    }
}

/// A camera inside a constant environment of radiance L: each sample's estimate is the XYZ of
/// L at its four wavelengths, a function Y(u) of the wavelength sample u alone, so the second
/// moment is ∫₀¹ Y(u)² du (a midpoint rule of 2²⁰ points, exact to far below the noise). The
/// image's mean of m2_Y over its pixels (independent, so their spread gives the standard
/// error) must be within 4 standard errors of it, and m1 within 4 of ∫₀¹ Y(u) du.
#[test]
fn second_moment_of_a_constant_environment() {
    let radiance = 0.7;
    let size = UVec2::new(16, 16);
    let scene = build(
        vec![],
        vec![Light::Constant(ConstantLight::new(Spectrum::Constant(
            radiance,
        )))],
        camera(DVec3::ZERO, DVec3::Z, DVec3::Y, 60.0, size),
        size,
        moment_of(vec![("env", PathIntegrator::default().into())]),
    );
    let steps = 1 << 20;
    let (mut m1, mut m2) = (0.0, 0.0);
    for i in 0..steps {
        let u = (i as f32 + 0.5) / steps as f32;
        let lambda = SampledWavelengths::sample(u, scene.film.wavelength_sampling);
        let y = f64::from(lambda.to_xyz(&SampledSpectrum::splat(radiance))[1]);
        m1 += y / steps as f64;
        m2 += y * y / steps as f64;
    }
    let film = render_film(&scene, 64, 3, None);
    for (name, exact) in [("env.Y", m1), ("m2_env.Y", m2)] {
        let values = film.aov(channel(&film, name));
        let n = values.len() as f64;
        let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let variance = values
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        let se = (variance / n).sqrt();
        assert!(se > 0.0 && se < 0.01 * exact, "{name}: standard error {se}");
        assert!(
            (mean - exact).abs() < 4.0 * se,
            "{name}: {mean}, integrated {exact} (σ = {se})"
        );
    }
    assert!(m2 > m1 * m1, "the wavelength samples spread Y");
}

#[test]
fn extra_channels_do_not_depend_on_threads_or_resuming() {
    let scene = room(two_nested());
    let one = render_film(&scene, 8, 42, Some(1));
    let two = render_film(&scene, 8, 42, Some(2));
    assert_eq!(one.aovs, two.aovs);
    assert_eq!(one.pixels, two.pixels);
    let mut first_half = RenderOptions::fixed(8, 42, Some(2));
    first_half.stop = StopRule::samples(4);
    let half = render(&scene, &first_half).unwrap().film;
    let mut second_half = RenderOptions::fixed(8, 42, Some(2));
    second_half.first_sample = 4;
    second_half.initial = Some(InitialState::sums(half.pixels, half.aovs));
    let resumed = render(&scene, &second_half).unwrap().film;
    assert_eq!(resumed.aovs, one.aovs);
    assert_eq!(resumed.pixels, one.pixels);
}
