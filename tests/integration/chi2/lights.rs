//! Chi-square tests (docs/testing.md) of the lights' sampling routines: sphere lights by visible
//! cone in its small-angle and near regimes, rectangle lights by solid angle and other
//! triangle-mesh lights by area as seen from a point, environment maps by luminance · sin θ, and
//! the choice of a light by power or uniformly. Each test works in coordinates where the density is
//! continuous within every cell.

use std::f64::consts::PI;

use glam::{DMat4, DVec3, Mat3, UVec2, Vec2, Vec3};
use prism_core::geometry::ShapeGeometry;
use prism_core::geometry::Sphere;
use prism_core::geometry::{Shape, ShapeSampling};
use prism_core::image::{Bitmap, Encoding};
use prism_core::integrator::PathIntegrator;
use prism_core::light::{
    AreaLight, ConstantLight, DirectionalLight, EnvironmentMap, EqualAreaEnvmap, Light, LightQuery,
    LightSelection, LightSource, PointLight, Receiver, SpotLight,
};
use prism_core::math::{Frame, Transform};
use prism_core::sampling::chi2::{
    Cells, Suite, chi2_discrete, chi2_from_counts, chi2_rectangle, simpson_2d,
};
use prism_core::sampling::rng::Pcg32;
use prism_core::spectrum::{SampledWavelengths, Spectrum};
use prism_mitsuba::factory::shapes::{rectangle, transform_mesh};

use crate::common::scenes::{Object, build, camera};

/// The chi-square tests of this module, one name per statistic: the suite of Šidák's correction.
const SUITE: Suite = Suite::new(&[
    "sphere cone, small angle",
    "sphere cone, close",
    "rectangle light, oblique",
    "rectangle light, grazing",
    "parallelogram light",
    "rectangle light by area",
    "environment map",
    "equal-area environment map",
    "light selection Power",
    "light selection Uniform",
    "exhaustive selection at receiver 0",
    "exhaustive selection at receiver 1",
    "exhaustive selection at receiver 2",
    "exhaustive selection at receiver 3",
]);
const SAMPLES: usize = 1_000_000;

fn u2(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(rng.next_f32(), rng.next_f32())
}

/// Cone sampling of a sphere of radius 1 whose centre is `distance` from the reference, along
/// +z. Tested in (t, φ) with t = (1 − cos θ)/(1 − cos θmax), uniform on [0, 1) × [0, 2π) for
/// directions uniform in the cone; 1 − cos θ is computed as |w − axis|²/2 in double precision,
/// so even a cone of a few milliradians is resolved. The claimed pdf must also equal
/// 1/(2π(1 − cos θmax)) to 10⁻⁴, which the coordinates' normalisation cannot see.
fn cone_chi2(distance: f32, seed: u64, name: &str) {
    let s = Sphere {
        center: Vec3::new(0.0, 0.0, distance),
        radius: 1.0,
        rotation: Mat3::IDENTITY,
        flip_normals: false,
    };
    let sin2_max = 1.0 / f64::from(distance).powi(2);
    let one_minus_cos_max = sin2_max / (1.0 + (1.0 - sin2_max).sqrt());
    let expected_pdf = 1.0 / (2.0 * PI * one_minus_cos_max);
    let outcome = chi2_rectangle(
        SAMPLES,
        Cells {
            x: (0.0, 1.0),
            y: (0.0, 2.0 * PI),
            nx: 30,
            ny: 60,
        },
        seed,
        |rng| {
            let sample = s.sample_from(Vec3::ZERO, 0.5, u2(rng), ShapeSampling::SolidAngle)?;
            assert!(
                (f64::from(sample.pdf) / expected_pdf - 1.0).abs() < 1e-4,
                "{name}: pdf {} instead of {expected_pdf}",
                sample.pdf
            );
            let claimed = s.pdf_from(Vec3::ZERO, sample.p, sample.n, ShapeSampling::SolidAngle);
            assert_eq!(
                claimed, sample.pdf,
                "{name}: pdf_from disagrees with the sample"
            );
            let w = sample.p.as_dvec3().normalize();
            let t = 0.5 * (w - DVec3::Z).length_squared() / one_minus_cos_max;
            let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
            Some((t.min(1.0 - 1e-12), phi))
        },
        |_, _| 1.0 / (2.0 * PI),
    )
    .unwrap();
    SUITE.assert_passes(name, &outcome);
}

/// θmax ≈ 0.57°: sin²θmax = 10⁻⁴, where 1 − √(1 − sin²θmax) in single precision keeps only a
/// few digits (the small-angle regime).
#[test]
fn sphere_cone_sampling_in_the_small_angle_regime() {
    cone_chi2(100.0, 21, "sphere cone, small angle");
}

/// θmax ≈ 72°: the reference nearly touches the sphere, the cone is almost a hemisphere.
#[test]
fn sphere_cone_sampling_close_to_the_sphere() {
    cone_chi2(1.05, 22, "sphere cone, close");
}

/// The rectangle light x ∈ [−0.7, 1.3], y ∈ [−0.4, 0.8] at z = 2 (Mitsuba's `rectangle`,
/// scaled and moved; `shear` slants it into a parallelogram with the same area, 2.4).
fn rectangle_light(shear: f64) -> Vec<prism_core::geometry::Primitive> {
    let slant = DMat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, shear, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    let to_world = Transform::new(
        DMat4::from_translation(DVec3::new(0.3, 0.2, 2.0))
            * slant
            * DMat4::from_scale(DVec3::new(1.0, 0.6, 1.0)),
    )
    .unwrap();
    vec![Shape::Mesh(transform_mesh(rectangle(), &to_world, true, true)).into()]
}

/// A rectangle light seen from `reference`: its samples, in the rectangle's (x, y), must have
/// the density of directions uniform in the solid angle S it subtends, cos θ / (d² S), with S
/// integrated here by Simpson's rule (independently of the sampler's closed form), and the
/// claimed pdf must be 1/S to 10⁻⁴.
fn rectangle_light_chi2(reference: Vec3, seed: u64, name: &str) {
    let shapes = rectangle_light(0.0);
    let light = Light::Area(AreaLight::uniform(0, Spectrum::Constant(1.0)));
    let lambda = SampledWavelengths::single(550.0);
    let r = reference.as_dvec3();
    let h = 2.0 - r.z;
    let directional = move |x: f64, y: f64| {
        let d2 = (x - r.x).powi(2) + (y - r.y).powi(2) + h * h;
        h.abs() / (d2 * d2.sqrt())
    };
    let solid_angle = simpson_2d(directional, (-0.7, 1.3), (-0.4, 0.8), 800);
    let outcome = chi2_rectangle(
        SAMPLES,
        Cells {
            x: (-0.7, 1.3),
            y: (-0.4, 0.8),
            nx: 40,
            ny: 24,
        },
        seed,
        |rng| {
            let ls = light.sample_incident(LightQuery {
                shapes: &shapes,
                reference,
                time: 0.0,
                u_choice: rng.next_f32(),
                u: u2(rng),
                lambda: &lambda,
            })?;
            let claimed = f64::from(ls.pdf) * solid_angle;
            assert!((claimed - 1.0).abs() < 1e-4, "{name}: pdf × S = {claimed}");
            assert!((f64::from(ls.p.z) - 2.0).abs() < 1e-5, "{name}: {}", ls.p);
            // Points on an edge may round to just outside it.
            let (x, y) = (f64::from(ls.p.x), f64::from(ls.p.y));
            assert!(x > -0.7 - 1e-5 && x < 1.3 + 1e-5 && y > -0.4 - 1e-5 && y < 0.8 + 1e-5);
            Some((x.clamp(-0.7, 1.3 - 1e-9), y.clamp(-0.4, 0.8 - 1e-9)))
        },
        |x, y| directional(x, y) / solid_angle,
    )
    .unwrap();
    SUITE.assert_passes(name, &outcome);
}

/// Seen obliquely from 1.5 below: the density varies 3× over the rectangle.
#[test]
fn rectangle_light_sampling_is_uniform_in_solid_angle() {
    rectangle_light_chi2(Vec3::new(-0.7, 0.4, 0.5), 23, "rectangle light, oblique");
}

/// Seen from just below the plane, beside an edge: the density varies a thousandfold, the case
/// area sampling is noisiest for (a wall next to a ceiling light).
#[test]
fn rectangle_light_sampling_close_to_the_plane() {
    rectangle_light_chi2(Vec3::new(-0.9, 0.0, 1.9), 24, "rectangle light, grazing");
}

/// A light that is not a rectangle (a parallelogram) is sampled by area.
#[test]
fn parallelogram_light_sampling_is_uniform_in_area() {
    by_area_chi2(0.5, ShapeSampling::SolidAngle, 25, "parallelogram light");
}

/// A rectangle light with `sampling="area"` (the lecture's) is sampled by area too.
#[test]
fn rectangle_light_sampling_by_area_is_uniform_in_area() {
    by_area_chi2(0.0, ShapeSampling::Area, 26, "rectangle light by area");
}

/// The light of [`rectangle_light`] slanted by `shear` and sampled by `sampling` must be sampled
/// uniformly by area: its samples, in its own coordinates (s, t) ∈ [0, 1]², uniform, and the
/// claimed solid-angle pdf times cos/d² 1/area at every point.
fn by_area_chi2(shear: f64, sampling: ShapeSampling, seed: u64, name: &str) {
    let shapes = rectangle_light(shear);
    let light = Light::Area(AreaLight::uniform(0, Spectrum::Constant(1.0)).sampled_by(sampling));
    let reference = Vec3::new(-0.7, 0.4, 0.5);
    let lambda = SampledWavelengths::single(550.0);
    // The corners (−1, −1), (1, −1), (−1, 1) of the unit rectangle, scaled, slanted and moved.
    let corner = DVec3::new(0.3 - 1.0 - 0.6 * shear, 0.2 - 0.6, 2.0);
    let (e1, e2) = (DVec3::new(2.0, 0.0, 0.0), DVec3::new(1.2 * shear, 1.2, 0.0));
    let outcome = chi2_rectangle(
        SAMPLES,
        Cells {
            x: (0.0, 1.0),
            y: (0.0, 1.0),
            nx: 30,
            ny: 20,
        },
        seed,
        |rng| {
            let ls = light.sample_incident(LightQuery {
                shapes: &shapes,
                reference,
                time: 0.0,
                u_choice: rng.next_f32(),
                u: u2(rng),
                lambda: &lambda,
            })?;
            let d = ls.p - reference;
            let cos = d.normalize().dot(Vec3::Z).abs();
            let area_pdf = f64::from(ls.pdf * cos / d.length_squared());
            assert!((area_pdf * 2.4 - 1.0).abs() < 1e-3, "area pdf {area_pdf}");
            let w = ls.p.as_dvec3() - corner;
            let t = w.y / e2.y;
            let s = (w.x - t * e2.x) / e1.x;
            Some((s.clamp(0.0, 1.0 - 1e-12), t.clamp(0.0, 1.0 - 1e-12)))
        },
        |_, _| 1.0,
    )
    .unwrap();
    SUITE.assert_passes(name, &outcome);
}

/// A linear greyscale bitmap from a function of the pixel.
fn grey_bitmap(width: usize, height: usize, f: impl Fn(usize, usize) -> f32) -> Bitmap {
    let data = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .flat_map(|(x, y)| [f(x, y); 3])
        .collect();
    Bitmap {
        width,
        height,
        channels: 3,
        data,
        encoding: Encoding::Linear,
    }
}

/// Environment map sampling against its claimed density. The sampler draws a cell of the
/// (s, v) grid (s = u − ½/W, v = θ/π) ∝ luminance · sin θ, then a uniform point in it, so its
/// density in (s, v) is constant per cell; the claimed solid-angle pdf times the Jacobian
/// 2π² sin θ must be that density. Bins split every cell 3 × 3 and are integrated by the
/// midpoint rule on 4 × 4 interior points, never on a cell's edge. The map is rotated, has
/// empty and bright cells, and its poles differ from its equator.
#[test]
fn environment_map_sampling_follows_luminance_times_sin_theta() {
    let (width, height) = (12usize, 7usize);
    let bitmap = grey_bitmap(width, height, |x, y| {
        if (x, y) == (7, 2) {
            40.0
        } else if x == 3 {
            0.0
        } else {
            0.2 + 0.1 * ((x * 7 + y * 3) % 5) as f32
        }
    });
    let rotation = DMat4::from_rotation_y(0.7) * DMat4::from_rotation_x(-0.4);
    let light = Light::Envmap(EnvironmentMap::new(
        bitmap,
        2.0,
        Transform::new(rotation).unwrap(),
    ));
    let to_local = rotation.inverse();
    let lambda = SampledWavelengths::single(550.0);
    let half_texel = 0.5 / width as f64;
    let (split, nodes) = (3usize, 4usize);
    let (nx, ny) = (width * split, (height - 1) * split);
    let (dx, dy) = (1.0 / nx as f64, 1.0 / ny as f64);
    // The claimed density in (s, v).
    let density = |s: f64, v: f64| {
        let (theta, phi) = (PI * v, 2.0 * PI * (s + half_texel));
        let local = DVec3::new(
            phi.sin() * theta.sin(),
            theta.cos(),
            -phi.cos() * theta.sin(),
        );
        let world = rotation.transform_vector3(local).as_vec3();
        f64::from(light.environment_pdf(world)) * 2.0 * PI * PI * theta.sin()
    };
    let mut expected = vec![0.0; nx * ny];
    for (cell, e) in expected.iter_mut().enumerate() {
        let (x0, y0) = ((cell % nx) as f64 * dx, (cell / nx) as f64 * dy);
        let mut sum = 0.0;
        for j in 0..nodes {
            for i in 0..nodes {
                let s = x0 + (i as f64 + 0.5) / nodes as f64 * dx;
                let v = y0 + (j as f64 + 0.5) / nodes as f64 * dy;
                sum += density(s, v);
            }
        }
        *e = sum / (nodes * nodes) as f64 * dx * dy * SAMPLES as f64;
    }
    let total: f64 = expected.iter().sum::<f64>() / SAMPLES as f64;
    assert!(
        (total - 1.0).abs() < 1e-3,
        "the claimed density integrates to {total}"
    );

    let mut observed = vec![0.0; nx * ny];
    let mut rng = Pcg32::seeded(24);
    for _ in 0..SAMPLES {
        let ls = light
            .sample_incident(LightQuery {
                shapes: &[],
                reference: Vec3::ZERO,
                time: 0.0,
                u_choice: 0.5,
                u: u2(&mut rng),
                lambda: &lambda,
            })
            .expect("an environment sample failed");
        assert!(
            (ls.pdf / light.environment_pdf(ls.wi) - 1.0).abs() < 1e-3,
            "the sample's pdf {} differs from the light's pdf {} ({:?})",
            ls.pdf,
            light.environment_pdf(ls.wi),
            ls.wi
        );
        let local = to_local.transform_vector3(ls.wi.as_dvec3()).normalize();
        let u = local.x.atan2(-local.z) / (2.0 * PI);
        let s = (u - half_texel).rem_euclid(1.0);
        let v = local.y.clamp(-1.0, 1.0).acos() / PI;
        let bin = ((v / dy) as usize).min(ny - 1) * nx + ((s / dx) as usize).min(nx - 1);
        observed[bin] += 1.0;
    }
    let outcome = chi2_from_counts(&observed, &expected).unwrap();
    SUITE.assert_passes("environment map", &outcome);
}

/// The equal-area map's sampling against its claimed density, in the coordinates (u, v) of its
/// square, where the sampler draws a pixel ∝ luminance and a uniform point in it: the claimed
/// solid-angle pdf times the Jacobian 4π must be constant on each pixel and match the counts.
/// Bins split every pixel 2 × 2 and take the density at their centres. The map is rotated and
/// has empty and bright pixels.
#[test]
fn equal_area_map_sampling_follows_luminance() {
    use prism_core::light::equal_area_envmap::{
        equal_area_sphere_to_square, equal_area_square_to_sphere,
    };
    let n = 16usize;
    let bitmap = grey_bitmap(n, n, |x, y| {
        if (x, y) == (11, 4) {
            40.0
        } else if x == 3 {
            0.0
        } else {
            0.2 + 0.1 * ((x * 7 + y * 3) % 5) as f32
        }
    });
    let rotation = DMat4::from_rotation_y(0.7) * DMat4::from_rotation_x(-0.4);
    let light = Light::EqualAreaEnvmap(EqualAreaEnvmap::new(
        bitmap,
        2.0,
        Transform::new(rotation).unwrap(),
    ));
    let to_local = rotation.inverse();
    let lambda = SampledWavelengths::single(550.0);
    let bins = 2 * n;
    let width = 1.0 / bins as f64;
    let mut expected = vec![0.0; bins * bins];
    for (cell, e) in expected.iter_mut().enumerate() {
        let centre = Vec2::new(
            (((cell % bins) as f64 + 0.5) * width) as f32,
            (((cell / bins) as f64 + 0.5) * width) as f32,
        );
        let world = rotation
            .transform_vector3(equal_area_square_to_sphere(centre).as_dvec3())
            .as_vec3();
        let density = f64::from(light.environment_pdf(world)) * 4.0 * PI;
        *e = density * width * width * SAMPLES as f64;
    }
    let total: f64 = expected.iter().sum::<f64>() / SAMPLES as f64;
    assert!(
        (total - 1.0).abs() < 1e-3,
        "the claimed density integrates to {total}"
    );
    let mut observed = vec![0.0; bins * bins];
    let mut rng = Pcg32::seeded(25);
    for _ in 0..SAMPLES {
        let ls = light
            .sample_incident(LightQuery {
                shapes: &[],
                reference: Vec3::ZERO,
                time: 0.0,
                u_choice: 0.5,
                u: u2(&mut rng),
                lambda: &lambda,
            })
            .expect("an environment sample failed");
        assert_eq!(ls.pdf, light.environment_pdf(ls.wi));
        let local = to_local.transform_vector3(ls.wi.as_dvec3()).normalize();
        let p = equal_area_sphere_to_square(local.as_vec3());
        let bin = ((f64::from(p.y) / width) as usize).min(bins - 1) * bins
            + ((f64::from(p.x) / width) as usize).min(bins - 1);
        observed[bin] += 1.0;
    }
    let outcome = chi2_from_counts(&observed, &expected).unwrap();
    SUITE.assert_passes("equal-area environment map", &outcome);
}

/// A scene with one light of every kind; returns it and the lights' closed-form powers.
fn every_kind_of_light(selection: LightSelection) -> (prism_core::scene::Scene, Vec<f64>) {
    let size = UVec2::new(4, 4);
    let camera = camera(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 40.0, size);
    // A floor of 4 × 4 and a sphere light of radius 0.5 with radiance 3 above it.
    let floor = Transform::new(DMat4::from_scale(DVec3::new(2.0, 2.0, 1.0))).unwrap();
    let objects = vec![
        Object {
            shape: Shape::Mesh(transform_mesh(rectangle(), &floor, false, true)).into(),
            reflectance: 0.5,
            emission: Some(0.25),
        },
        Object {
            shape: Shape::Sphere(Sphere {
                center: Vec3::new(0.0, 0.0, 1.0),
                radius: 0.5,
                rotation: Mat3::IDENTITY,
                flip_normals: false,
            })
            .into(),
            reflectance: 0.0,
            emission: Some(3.0),
        },
    ];
    let (cutoff, beam) = (30f64.to_radians(), 10f64.to_radians());
    let lights = vec![
        Light::Point(PointLight {
            position: Vec3::new(0.0, 1.0, 1.0),
            intensity: Spectrum::Constant(2.0),
        }),
        Light::Spot(SpotLight::new(
            Transform::IDENTITY,
            Spectrum::Constant(5.0),
            cutoff as f32,
            beam as f32,
        )),
        Light::Directional(DirectionalLight::new(-Vec3::Z, Spectrum::Constant(0.1))),
        Light::Constant(ConstantLight::new(Spectrum::Constant(0.02))),
    ];
    let scene = build(
        objects,
        lights,
        camera,
        size,
        PathIntegrator {
            light_selection: selection,
            ..PathIntegrator::default()
        },
    );
    // The bounding box is [−2, 2]² × [0, 1.5]: radius √(4 + 4 + 0.75²) (+ 10⁻⁴ relative).
    let r2 = (8.0 + 0.75f64 * 0.75) * (1.0f64 + 1e-4).powi(2);
    let powers = vec![
        PI * 16.0 * 0.25,
        PI * 4.0 * PI * 0.25 * 3.0,
        4.0 * PI * 2.0,
        2.0 * PI * 5.0 * (1.0 - (cutoff.sin() - beam.sin()) / (cutoff - beam)),
        PI * r2 * 0.1,
        4.0 * PI * PI * r2 * 0.02,
    ];
    (scene, powers)
}

fn selection_chi2(selection: LightSelection, seed: u64) {
    let (scene, powers) = every_kind_of_light(selection);
    let integrator = scene.integrator.prepare(&scene.world);
    let light_sampler = integrator.light_sampler();
    let total: f64 = powers.iter().sum();
    let probabilities: Vec<f64> = match selection {
        LightSelection::Power => powers.iter().map(|p| p / total).collect(),
        LightSelection::Uniform => vec![1.0 / powers.len() as f64; powers.len()],
        LightSelection::Exhaustive => unreachable!("tested by exhaustive_selection_*"),
    };
    let receiver = Receiver::surface(Vec3::new(0.3, -0.2, 0.0), Vec3::Z);
    for (i, p) in probabilities.iter().enumerate() {
        let reported = f64::from(light_sampler.pmf(i, &receiver));
        assert!(
            (reported / p - 1.0).abs() < 1e-4,
            "{selection:?}: light {i} has pmf {reported}, not {p}"
        );
    }
    let outcome = chi2_discrete(SAMPLES, &probabilities, seed, |rng| {
        let (index, pmf) = light_sampler.sample(rng.next_f32(), &receiver).unwrap();
        assert_eq!(
            pmf,
            light_sampler.pmf(index, &receiver),
            "the pmf returned with a sample is the reported pmf"
        );
        index
    })
    .unwrap();
    SUITE.assert_passes(&format!("light selection {selection:?}"), &outcome);
}

/// The closed form of the exhaustive selection at `receiver`: the two lights at infinity (the
/// directional and the constant one, the last two) together with probability 2/3 (pbrt-v4's
/// N_∞/(N_∞ + 1)), between them by power, the others by Φ min(1, (|n·(c − p)| + r)/d) / max(d², r²) of the boxes of `every_kind_of_light`.
fn exhaustive_probabilities(powers: &[f64], receiver: &Receiver) -> Vec<f64> {
    let (p, n) = (receiver.p.as_dvec3(), receiver.n.map(|n| n.as_dvec3()));
    // Centres and squared radii: the floor [−2, 2]² × {0}, the sphere, the point, the spot.
    let places = [
        (DVec3::ZERO, 8.0),
        (DVec3::new(0.0, 0.0, 1.0), 0.75),
        (DVec3::new(0.0, 1.0, 1.0), 0.0),
        (DVec3::ZERO, 0.0),
    ];
    let importance: Vec<f64> = places
        .iter()
        .zip(powers)
        .map(|(&(c, r2), &power)| {
            let d2: f64 = (c - p).length_squared().max(r2);
            let cosine = match n {
                Some(n) => ((n.dot(c - p).abs() + r2.sqrt()) / d2.sqrt()).min(1.0),
                None => 1.0,
            };
            power * cosine / d2
        })
        .collect();
    let infinite_share = 2.0 / 3.0;
    let infinite_power = powers[4] + powers[5];
    let finite: f64 = importance.iter().sum();
    importance
        .iter()
        .map(|i| (1.0 - infinite_share) * i / finite)
        .chain(
            powers[4..]
                .iter()
                .map(|p| infinite_share * p / infinite_power),
        )
        .collect()
}

/// Choosing by importance: at receivers on and off surfaces, each light's reported pmf is the
/// closed form, the pmfs sum to one, and sampled lights follow them.
#[test]
fn exhaustive_selection_weighs_lights_by_importance_at_the_receiver() {
    let (scene, powers) = every_kind_of_light(LightSelection::Exhaustive);
    let integrator = scene.integrator.prepare(&scene.world);
    let light_sampler = integrator.light_sampler();
    let receivers = [
        Receiver::surface(Vec3::new(0.3, -0.2, 0.05), Vec3::Z),
        Receiver::surface(Vec3::new(1.5, 0.5, 0.8), Vec3::new(-0.6, 0.0, 0.8)),
        Receiver::point(Vec3::new(-1.0, 3.0, 2.0)),
        Receiver::surface(Vec3::new(0.0, 0.2, 1.0), Vec3::new(0.0, 0.6, 0.8)),
    ];
    for (k, receiver) in receivers.iter().enumerate() {
        let probabilities = exhaustive_probabilities(&powers, receiver);
        let mut sum = 0.0;
        for (i, p) in probabilities.iter().enumerate() {
            let reported = f64::from(light_sampler.pmf(i, receiver));
            sum += reported;
            assert!(
                (reported / p - 1.0).abs() < 1e-4,
                "receiver {k}: light {i} has pmf {reported}, not {p}"
            );
        }
        assert!(
            (sum - 1.0).abs() < 1e-5,
            "receiver {k}: the pmfs sum to {sum}"
        );
        let outcome = chi2_discrete(SAMPLES, &probabilities, 40 + k as u64, |rng| {
            let (index, pmf) = light_sampler.sample(rng.next_f32(), receiver).unwrap();
            assert_eq!(
                pmf,
                light_sampler.pmf(index, receiver),
                "the pmf returned with a sample is the reported pmf"
            );
            index
        })
        .unwrap();
        SUITE.assert_passes(&format!("exhaustive selection at receiver {k}"), &outcome);
    }
}

/// The importance never rules out a light that can light the receiver: wherever a light sample
/// arrives with radiance and a non-zero cosine, the light has a positive probability.
#[test]
fn exhaustive_selection_keeps_every_light_that_can_give_light() {
    let (scene, _) = every_kind_of_light(LightSelection::Exhaustive);
    let integrator = scene.integrator.prepare(&scene.world);
    let light_sampler = integrator.light_sampler();
    let lambda = SampledWavelengths::sample(0.3, Default::default());
    let mut rng = Pcg32::seeded(41);
    let mut checked = 0;
    for _ in 0..2000 {
        let p = Vec3::new(
            4.0 * rng.next_f32() - 2.0,
            4.0 * rng.next_f32() - 2.0,
            2.0 * rng.next_f32() - 0.5,
        );
        let n = prism_core::sampling::warp::sample_uniform_sphere(u2(&mut rng));
        let receiver = Receiver::surface(p, n);
        for (i, light) in scene.world.lights.iter().enumerate() {
            let Some(ls) = light.sample_incident(LightQuery {
                shapes: &scene.world.geometry.primitives,
                reference: p,
                time: 0.0,
                u_choice: rng.next_f32(),
                u: u2(&mut rng),
                lambda: &lambda,
            }) else {
                continue;
            };
            if ls.radiance.is_black() || ls.wi.dot(n) == 0.0 {
                continue;
            }
            checked += 1;
            assert!(
                light_sampler.pmf(i, &receiver) > 0.0,
                "light {i} lights {p:?} (normal {n:?}) but has probability 0"
            );
        }
    }
    assert!(checked > 5000, "only {checked} samples arrived");
}

/// Lights of every kind in one scene are chosen in proportion to their closed-form powers:
/// area πAL, sphere area π·4πR²·L, point 4πI, spot 2πI(1 − (sin c − sin β)/(c − β)),
/// directional πR²E and constant environment 4π²R²L with R the scene's bounding radius.
#[test]
fn light_selection_by_power_uses_each_lights_power() {
    selection_chi2(LightSelection::Power, 25);
}

#[test]
fn uniform_light_selection_picks_every_light_alike() {
    selection_chi2(LightSelection::Uniform, 26);
}

/// The spot light's direction: `to_world` turns its +z axis; only directions within the
/// cutoff receive light, with the falloff's profile.
#[test]
fn spot_light_points_along_its_transformed_axis() {
    let to_world = Transform::new(DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2)).unwrap();
    let spot = SpotLight::new(
        to_world,
        Spectrum::Constant(1.0),
        20f32.to_radians(),
        10f32.to_radians(),
    );
    let lambda = SampledWavelengths::single(550.0);
    // +z rotated by 90° about x is −y: a point 1 below the light is on the axis.
    let below = spot
        .sample_incident(LightQuery {
            shapes: &[],
            reference: Vec3::new(0.0, -1.0, 0.0),
            time: 0.0,
            u_choice: 0.5,
            u: Vec2::ZERO,
            lambda: &lambda,
        })
        .unwrap();
    assert_eq!(below.radiance[0], 1.0);
    // 15° off the axis: halfway down the ramp.
    let off = Frame::from_normal(-Vec3::Y).to_world(Vec3::new(
        15f32.to_radians().sin(),
        0.0,
        15f32.to_radians().cos(),
    ));
    let half = spot
        .sample_incident(LightQuery {
            shapes: &[],
            reference: off * 2.0,
            time: 0.0,
            u_choice: 0.5,
            u: Vec2::ZERO,
            lambda: &lambda,
        })
        .unwrap();
    assert!(
        (half.radiance[0] * 4.0 - 0.5).abs() < 1e-4,
        "{}",
        half.radiance[0]
    );
    assert!(
        spot.sample_incident(LightQuery {
            shapes: &[],
            reference: Vec3::new(0.0, 1.0, 0.0),
            time: 0.0,
            u_choice: 0.5,
            u: Vec2::ZERO,
            lambda: &lambda
        })
        .is_none()
    );
}
