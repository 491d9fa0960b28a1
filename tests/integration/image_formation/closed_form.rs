//! Image formation against closed forms: filters keep a constant image constant, the thin lens
//! blurs by its circle of confusion, a moving emitter smears over the right length, and N-rooks
//! sampling lowers the error.

use glam::{DMat4, DVec2, DVec3, Mat3, UVec2, Vec2, Vec3};
use prism_core::camera::{Camera, PerspectiveCamera, Shutter};
use prism_core::film::{
    BoxFilter, Film, Filter, GaussianFilter, LanczosFilter, MitchellFilter, TentFilter,
};
use prism_core::geometry::{Disk, Instance, Primitive, Shape, Sphere};
use prism_core::integrator::PathIntegrator;
use prism_core::math::special::regularized_gamma_q;
use prism_core::math::{AnimatedTransform, Transform};
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::sampler::SamplerKind;
use prism_core::sampling::warp;
use prism_core::scene::Scene;

use crate::common::scenes::{
    Object, assert_mean_luminance, build, camera, pixel_mean_and_variance, render_film,
};

/// Pixels per unit of tan(angle) for a film `width` pixels wide with horizontal field of view
/// `fov` degrees.
fn pixels_per_tan(width: u32, fov: f64) -> f64 {
    f64::from(width) / (2.0 * (0.5 * fov).to_radians().tan())
}

/// The chi-square p-value of the pixels' standardised deviations from `expected`.
fn pixel_p_value(film: &Film, expected: impl Fn(usize) -> f64) -> f64 {
    let statistic: f64 = (0..film.pixels.len())
        .map(|i| {
            let (mean, variance) = pixel_mean_and_variance(film, i, 1);
            (mean - expected(i)).powi(2) / variance
        })
        .sum();
    let n = film.pixels.len() as f64;
    regularized_gamma_q(n / 2.0, statistic / 2.0)
}

/// Inside an emitting sphere of radiance 1 that reflects nothing, every pixel sees 1 whatever the
/// filter: negative lobes carry negative weights, and the estimate stays the filtered image.
#[test]
fn a_constant_image_stays_constant_under_every_filter() {
    let size = UVec2::new(12, 12);
    for (seed, filter) in [
        Filter::Box(BoxFilter { radius: 0.5 }),
        Filter::Tent(TentFilter { radius: 1.0 }),
        Filter::Gaussian(GaussianFilter { stddev: 0.5 }),
        Filter::Mitchell(MitchellFilter {
            b: 1.0 / 3.0,
            c: 1.0 / 3.0,
        }),
        Filter::Mitchell(MitchellFilter { b: 0.0, c: 0.5 }),
        Filter::Lanczos(LanczosFilter { lobes: 3 }),
    ]
    .into_iter()
    .enumerate()
    {
        let mut scene = build(
            vec![Object {
                shape: Shape::Sphere(Sphere {
                    center: Vec3::ZERO,
                    radius: 1.0,
                    rotation: Mat3::IDENTITY,
                    flip_normals: true,
                })
                .into(),
                reflectance: 0.0,
                emission: Some(1.0),
            }],
            vec![],
            camera(DVec3::ZERO, DVec3::Z, DVec3::Y, 60.0, size),
            size,
            PathIntegrator::default(),
        );
        scene.film.filter = filter;
        // Lanczos' lobes make its weights the noisiest: more samples keep the test sensitive.
        let spp = if matches!(filter, Filter::Lanczos(_)) {
            4096
        } else {
            1024
        };
        let film = render_film(&scene, spp, seed as u64, None);
        assert_mean_luminance(&format!("{filter:?}"), &film, 1.0);
        let p = pixel_p_value(&film, |_| 1.0);
        assert!(
            p > 1e-3,
            "{filter:?}: pixels deviate from 1 (chi-square p = {p})"
        );
    }
}

/// The intensity-weighted mean of r² over pixel centres (r from `centre`, in pixels) and its
/// standard error (delta method), for the Y channel.
fn second_moment(film: &Film, centre: Vec2, axis: Option<usize>) -> (f64, f64, f64) {
    let width = film.crop.size.x as usize;
    let (mut sum, mut weighted) = (0.0, 0.0);
    let values: Vec<(f64, f64, f64)> = (0..film.pixels.len())
        .map(|i| {
            let c = Vec2::new((i % width) as f32 + 0.5, (i / width) as f32 + 0.5) - centre;
            let r2 = match axis {
                None => c.length_squared(),
                Some(a) => c[a] * c[a],
            };
            let (mean, variance) = pixel_mean_and_variance(film, i, 1);
            (f64::from(r2), mean, variance)
        })
        .collect();
    for &(r2, v, _) in &values {
        sum += v;
        weighted += v * r2;
    }
    let moment = weighted / sum;
    let variance: f64 = values
        .iter()
        .map(|&(r2, _, var)| ((r2 - moment) / sum).powi(2) * var)
        .sum();
    (moment, variance.sqrt(), sum)
}

/// The expected value, and its standard error, of the film's intensity-weighted mean of the
/// squared distance of *pixel centres* from `centre` (the estimator [`second_moment`] computes),
/// for an image whose light lands at film points drawn by `point`: the mean over 10⁷ points of
/// the squared offset of the centre of the pixel each falls in. This is exact where the closed
/// form with a constant pixel-centre correction is not (at the rims of the image).
fn snapped_moment(
    centre: Vec2,
    axis: Option<usize>,
    mut point: impl FnMut(&mut Pcg32) -> DVec2,
) -> (f64, f64) {
    const POINTS: usize = 10_000_000;
    let mut rng = Pcg32::seeded(17);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..POINTS {
        let x = point(&mut rng) + centre.as_dvec2();
        let c = x.floor() + DVec2::splat(0.5) - centre.as_dvec2();
        let r2 = match axis {
            None => c.length_squared(),
            Some(a) => c[a] * c[a],
        };
        sum += r2;
        sum2 += r2 * r2;
    }
    let n = POINTS as f64;
    let mean = sum / n;
    (mean, ((sum2 / n - mean * mean) / n).sqrt())
}

/// A uniform point on the disk of `radius`, centred at the origin.
fn in_disk(rng: &mut Pcg32, radius: f64) -> DVec2 {
    let u = warp::sample_uniform_disk_concentric(Vec2::new(rng.next_f32(), rng.next_f32()));
    u.as_dvec2() * radius
}

/// A uniform point of a disk of `radius` smeared along x over a box of `length`.
fn smeared(rng: &mut Pcg32, radius: f64, length: f64) -> DVec2 {
    in_disk(rng, radius) + DVec2::new((rng.next_f64() - 0.5) * length, 0.0)
}

/// A disk of radius `radius` at depth `depth` facing a camera at the origin looking along +z.
fn facing_disk(radius: f64, depth: f64) -> Shape {
    let to_world = DMat4::from_translation(DVec3::new(0.0, 0.0, depth))
        * DMat4::from_rotation_x(std::f64::consts::PI)
        * DMat4::from_scale(DVec3::splat(radius));
    Shape::Disk(Disk::new(Transform::new(to_world).unwrap(), false))
}

fn thin_lens(size: UVec2, fov: f64, lens_radius: f32, focus_distance: f32) -> Camera {
    let Camera::Perspective(pinhole) = camera(DVec3::ZERO, DVec3::Z, DVec3::Y, fov, size) else {
        unreachable!("common::scenes::camera is perspective")
    };
    Camera::Perspective(PerspectiveCamera {
        lens_radius,
        focus_distance,
        ..pinhole
    })
}

/// The thin lens images a point at depth z as a disk of radius R |1/g − 1/z| in units of
/// tan(angle) (R the aperture radius, g the focus distance): the lecture's depth of field. A
/// small emitting disk is rendered out of focus; its image is the disk's own image convolved
/// with the circle of confusion, so the intensity-weighted mean of r² is (ρ_disk² + ρ_coc²)/2,
/// less about 1/6 px² because pixel centres stand for their pixels; the test compares with the
/// exact value for pixel centres ([`snapped_moment`]).
#[test]
fn defocus_blur_has_the_thin_lens_circle_of_confusion() {
    let size = UVec2::new(48, 48);
    let fov = 20.0;
    let (lens_radius, focus, depth, disk_radius) = (0.2f64, 2.0f64, 4.0f64, 0.04f64);
    let scale = pixels_per_tan(size.x, fov);
    let mut scene = build(
        vec![Object {
            shape: facing_disk(disk_radius, depth).into(),
            reflectance: 0.0,
            emission: Some(1.0),
        }],
        vec![],
        thin_lens(size, fov, lens_radius as f32, focus as f32),
        size,
        PathIntegrator {
            max_depth: 1,
            ..PathIntegrator::default()
        },
    );
    scene.sampler.kind = SamplerKind::NRooks;
    let film = render_film(&scene, 1024, 1, None);
    let coc = lens_radius * (1.0 / focus - 1.0 / depth) * scale;
    let image = disk_radius / depth * scale;
    let centre = Vec2::splat(24.0);
    let (expected, expected_se) =
        snapped_moment(centre, None, |rng| in_disk(rng, image) + in_disk(rng, coc));
    let (moment, se, _) = second_moment(&film, centre, None);
    assert!(
        (moment - expected).abs() < 4.0 * se.hypot(expected_se),
        "mean r² {moment} ± {se} px², thin lens predicts {expected} (circle of confusion radius {coc} px)"
    );
    // In focus the same disk is sharp: only its own image remains.
    let Camera::Perspective(lens) = &mut scene.camera else {
        unreachable!("the scene's camera is a thin lens")
    };
    lens.focus_distance = depth as f32;
    let film = render_film(&scene, 256, 2, None);
    let (moment, se, _) = second_moment(&film, centre, None);
    let (sharp, sharp_se) = snapped_moment(centre, None, |rng| in_disk(rng, image));
    assert!(
        (moment - sharp).abs() < 4.0 * se.hypot(sharp_se),
        "in focus: {moment} ± {se}, a sharp image of the disk predicts {sharp}"
    );
}

/// A disk moving at constant velocity across the camera during the shutter is smeared into a
/// box of length ℓ along the motion: the x-variance of its image is about ρ²/4 + ℓ²/12 (disk and
/// box convolved) less 1/12 px² for the pixel centres (compared with the exact value for pixel
/// centres, [`snapped_moment`]), its mean x is the middle of the path, and along the plateau of
/// the box every column receives the same light.
#[test]
fn a_moving_emitter_smears_into_a_box_of_the_right_length() {
    let size = UVec2::new(48, 16);
    let fov = 20.0;
    let (depth, radius, travel) = (4.0f64, 0.02f64, 0.6f64);
    let scale = pixels_per_tan(size.x, fov);
    let key = |x: f64| {
        DMat4::from_translation(DVec3::new(x, 0.0, depth))
            * DMat4::from_rotation_x(std::f64::consts::PI)
            * DMat4::from_scale(DVec3::splat(radius))
    };
    let motion =
        AnimatedTransform::new(&[(0.0, key(-travel / 2.0)), (1.0, key(travel / 2.0))]).unwrap();
    let disk = Shape::Disk(Disk::new(Transform::IDENTITY, false));
    let mut scene: Scene = build(
        vec![Object {
            shape: Primitive::Instance(Instance::new(disk, motion)),
            reflectance: 0.0,
            emission: Some(1.0),
        }],
        vec![],
        camera(DVec3::ZERO, DVec3::Z, DVec3::Y, fov, size),
        size,
        PathIntegrator {
            max_depth: 1,
            ..PathIntegrator::default()
        },
    );
    scene.shutter = Shutter::new(0.0, 1.0, None);
    scene.sampler.kind = SamplerKind::NRooks;
    let film = render_film(&scene, 1024, 3, None);
    let length = travel / depth * scale;
    let image = radius / depth * scale;
    let centre = Vec2::new(24.0, 8.0);
    let (expected, expected_se) =
        snapped_moment(centre, Some(0), |rng| smeared(rng, image, length));
    let (variance, se, _) = second_moment(&film, centre, Some(0));
    assert!(
        (variance - expected).abs() < 4.0 * se.hypot(expected_se),
        "x-variance {variance} ± {se} px², a box of {length} px predicts {expected}"
    );
    let (mean_x, se_x, _) = {
        // First moment along x, same estimator with r = x.
        let width = size.x as usize;
        let (mut sum, mut weighted) = (0.0, 0.0);
        let values: Vec<(f64, f64, f64)> = (0..film.pixels.len())
            .map(|i| {
                let (m, v) = pixel_mean_and_variance(&film, i, 1);
                ((i % width) as f64 + 0.5 - 24.0, m, v)
            })
            .collect();
        for &(x, m, _) in &values {
            sum += m;
            weighted += m * x;
        }
        let mean = weighted / sum;
        let var: f64 = values
            .iter()
            .map(|&(x, _, v)| ((x - mean) / sum).powi(2) * v)
            .sum();
        (mean, var.sqrt(), sum)
    };
    assert!(
        mean_x.abs() < 4.0 * se_x,
        "the smear is centred at {mean_x} ± {se_x} px, not 0"
    );
    // The plateau: columns fully inside the box (away from its ends by the disk's radius and a
    // pixel) receive equal light.
    let width = size.x as usize;
    let half_plateau = (length / 2.0 - image - 1.0).floor() as i64;
    let columns: Vec<(f64, f64)> = (-half_plateau..half_plateau)
        .map(|dx| {
            let x = (24 + dx) as usize;
            (0..size.y as usize).fold((0.0, 0.0), |(s, v), y| {
                let (m, var) = pixel_mean_and_variance(&film, y * width + x, 1);
                (s + m, v + var)
            })
        })
        .collect();
    assert!(columns.len() >= 4, "the plateau is too short to test");
    let weights: f64 = columns.iter().map(|c| 1.0 / c.1).sum();
    let level = columns.iter().map(|c| c.0 / c.1).sum::<f64>() / weights;
    let statistic: f64 = columns.iter().map(|c| (c.0 - level).powi(2) / c.1).sum();
    let p = regularized_gamma_q((columns.len() - 1) as f64 / 2.0, statistic / 2.0);
    assert!(
        p > 1e-3,
        "the plateau of the smear is not flat: chi-square {statistic}, p = {p}"
    );
}

/// The lecture's stratified primary samples lower the error. An out-of-focus emitter seen
/// directly has all its noise in the primary dimensions (film position, lens position,
/// wavelength); at 16 samples per pixel N-rooks must give a smaller mean squared error against a
/// 4096-sample reference than independent sampling. Each error is averaged over four seeds, and
/// the test asks for a margin of 4 standard errors of the difference (from the seeds' spread).
#[test]
fn nrooks_sampling_has_less_error_than_independent_sampling() {
    let size = UVec2::new(24, 24);
    let mut scene = build(
        vec![Object {
            shape: facing_disk(0.1, 4.0).into(),
            reflectance: 0.0,
            emission: Some(1.0),
        }],
        vec![],
        thin_lens(size, 20.0, 0.1, 2.0),
        size,
        PathIntegrator {
            max_depth: 1,
            ..PathIntegrator::default()
        },
    );
    let reference: Vec<f64> = {
        let film = render_film(&scene, 4096, 1000, None);
        (0..film.pixels.len())
            .map(|i| pixel_mean_and_variance(&film, i, 1).0)
            .collect()
    };
    let mut errors = Vec::new();
    for kind in [SamplerKind::Independent, SamplerKind::NRooks] {
        scene.sampler.kind = kind;
        let per_seed: Vec<f64> = (0..4)
            .map(|seed| {
                let film = render_film(&scene, 16, 40 + seed, None);
                reference
                    .iter()
                    .enumerate()
                    .map(|(i, r)| (pixel_mean_and_variance(&film, i, 1).0 - r).powi(2))
                    .sum::<f64>()
                    / reference.len() as f64
            })
            .collect();
        let mean = per_seed.iter().sum::<f64>() / 4.0;
        let spread = (per_seed.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 3.0 / 4.0).sqrt();
        errors.push((mean, spread));
    }
    let ((independent, se_i), (nrooks, se_n)) = (errors[0], errors[1]);
    assert!(
        independent - nrooks > 4.0 * (se_i * se_i + se_n * se_n).sqrt(),
        "MSE at 16 spp: independent {independent} ± {se_i}, nrooks {nrooks} ± {se_n}"
    );
}

/// A camera moving sideways past a still emitter smears it exactly as the emitter moving the
/// other way past a still camera: same x-variance of the image (see the previous test).
#[test]
fn a_moving_camera_smears_a_still_emitter() {
    let size = UVec2::new(48, 16);
    let fov = 20.0;
    let (depth, radius, travel) = (4.0f64, 0.02f64, 0.6f64);
    let scale = pixels_per_tan(size.x, fov);
    let key = |x: f64| {
        prism_core::math::transform::look_at(
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x, 0.0, 1.0),
            DVec3::Y,
        )
        .unwrap()
    };
    let Camera::Perspective(still) = camera(DVec3::ZERO, DVec3::Z, DVec3::Y, fov, size) else {
        unreachable!("common::scenes::camera is perspective")
    };
    let moving = Camera::Perspective(PerspectiveCamera {
        to_world: AnimatedTransform::new(&[(0.0, key(-travel / 2.0)), (1.0, key(travel / 2.0))])
            .unwrap(),
        ..still
    });
    let mut scene = build(
        vec![Object {
            shape: facing_disk(radius, depth).into(),
            reflectance: 0.0,
            emission: Some(1.0),
        }],
        vec![],
        moving,
        size,
        PathIntegrator {
            max_depth: 1,
            ..PathIntegrator::default()
        },
    );
    scene.shutter = Shutter::new(0.0, 1.0, None);
    scene.sampler.kind = SamplerKind::NRooks;
    let film = render_film(&scene, 1024, 4, None);
    let length = travel / depth * scale;
    let image = radius / depth * scale;
    let centre = Vec2::new(24.0, 8.0);
    let (expected, expected_se) =
        snapped_moment(centre, Some(0), |rng| smeared(rng, image, length));
    let (variance, se, _) = second_moment(&film, centre, Some(0));
    assert!(
        (variance - expected).abs() < 4.0 * se.hypot(expected_se),
        "x-variance {variance} ± {se} px², a box of {length} px predicts {expected}"
    );
}
