//! Participating media against closed forms (docs/testing.md, closed-form scenes): transmittance
//! through a homogeneous slab, single scattering in a slab lit by a directional light, a closed
//! furnace filled with a non-absorbing medium (L = Lₑ), an emitter inside an absorbing medium; and
//! ratio tracking's transmittance against the exact optical depth of generated grids (also of
//! a density grid times chromatic coefficients, pbrt-v4's grid media).

use glam::{DMat4, DVec3, Mat3, UVec2, Vec3};
use prism_core::bsdf::{Material, Null};
use prism_core::film::Film;
use prism_core::geometry::{Shape, Sphere};
use prism_core::integrator::{Integrator, Tracking, VolPathIntegrator};
use prism_core::light::{DirectionalLight, Light};
use prism_core::math::{Ray, Transform};
use prism_core::medium::{
    GridFilter, GridVolume, HenyeyGreenstein, Heterogeneous, HeterogeneousAbsorbingScattering,
    Homogeneous, Isotropic, Medium, MediumInterface, MediumKind, PhaseFunction, PhaseModel,
    Rayleigh, Sggx, TabulatedPhase, Volume,
};
use prism_core::sampling::rng::Pcg32;
use prism_core::scene::Scene;
use prism_core::spectrum::cie::cie_y;
use prism_core::spectrum::{
    LAMBDA_MAX, LAMBDA_MIN, PiecewiseLinear, SampledWavelengths, Spectrum, WavelengthSampling,
};
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::factory::shapes::{cube, transform_mesh};
use prism_mitsuba::reader::read_scene_str;

use crate::common::scenes::{
    Object, assert_mean_luminance, build, camera, image_mean_and_standard_error,
    pixel_mean_and_variance, render_film, scene_from_xml,
};

/// A box [−s, s] (one scale per axis) with outward normals.
fn boxed(scale: DVec3, offset: DVec3) -> Shape {
    let to_world =
        Transform::new(DMat4::from_translation(offset) * DMat4::from_scale(scale)).unwrap();
    Shape::Mesh(transform_mesh(cube(), &to_world, false, true))
}

fn homogeneous(sigma_t: Spectrum, albedo: f32, phase: PhaseFunction) -> Medium {
    Medium {
        kind: MediumKind::Homogeneous(Homogeneous {
            sigma_t,
            albedo: Spectrum::Constant(albedo),
            scale: 1.0,
        }),
        phase,
        sample_emitters: true,
    }
}

/// Gives object `index` of `scene` the `null` BSDF and `interface`.
fn make_boundary(scene: &mut Scene, index: usize, interface: MediumInterface) {
    let world = &mut scene.world;
    world.materials[index] = Material::new(Null);
    if world.medium_interfaces.is_empty() {
        world.medium_interfaces = vec![MediumInterface::default(); world.shape_info.len()];
    }
    world.medium_interfaces[index] = interface;
}

/// A narrow camera (0.5°) at `origin` looking at `target`: every pixel's ray is within 0.4° of
/// the axis, so path lengths differ from the axis's by less than 3·10⁻⁵ relative.
fn narrow_camera(origin: DVec3, target: DVec3, size: UVec2) -> prism_core::camera::Camera {
    camera(origin, target, DVec3::Y, 0.5, size)
}

/// The three volumetric integrators: `volpath`, `volpathmis`, and `volpathmis` with the hero's
/// densities alone.
fn volumetric_integrators() -> [(&'static str, VolPathIntegrator); 3] {
    let with = |tracking| VolPathIntegrator {
        tracking,
        ..VolPathIntegrator::default()
    };
    [
        ("volpath", with(Tracking::Spectral)),
        ("volpathmis", with(Tracking::HeroMis { spectral_mis: true })),
        (
            "volpathmis (hero densities)",
            with(Tracking::HeroMis {
                spectral_mis: false,
            }),
        ),
    ]
}

/// `volpath` and `volpathmis`, for the chromatic closed forms (the hero's densities alone are
/// unbiased too, but their variance there is what spectral MIS removes: see
/// `spectral_mis_lowers_variance_in_a_chromatic_medium`).
fn chromatic_unbiased() -> [(&'static str, VolPathIntegrator); 2] {
    let [volpath, mis, _] = volumetric_integrators();
    [volpath, mis]
}

/// Luminance Y = ∫ f ȳ dλ / ∫ ȳ dλ of a spectral radiance f (midpoint rule on 0.25 nm cells,
/// where the sampled estimate and the table agree to 10⁻⁵).
fn luminance(f: impl Fn(f64) -> f64) -> f64 {
    let cells = (LAMBDA_MIN as usize..LAMBDA_MAX as usize)
        .flat_map(|nm| (0..4).map(move |k| nm as f64 + (k as f64 + 0.5) / 4.0));
    let (weighted, total) = cells.fold((0.0, 0.0), |(w, t), lambda| {
        let y = f64::from(cie_y(lambda as f32));
        (w + f(lambda) * y, t + y)
    });
    weighted / total
}

/// A strongly chromatic extinction: 6 at 360 nm, 0.3 at 550 nm, 3 at 830 nm.
fn chromatic_sigma_t() -> PiecewiseLinear {
    PiecewiseLinear::new(&[(360.0, 6.0), (550.0, 0.3), (830.0, 3.0)]).unwrap()
}

/// An emitting plane of radiance Lₑ = 2 behind a slab of thickness d = 1.25 of a medium of
/// extinction `sigma_t` and albedo `albedo` bounded by a `null` box, rendered by `integrator`
/// (16 × 16 pixels).
fn slab(
    sigma_t: Spectrum,
    albedo: f32,
    integrator: VolPathIntegrator,
    spp: u32,
    seed: u64,
) -> Film {
    let medium = homogeneous(sigma_t, albedo, PhaseFunction::Isotropic(Isotropic));
    slab_of(medium, integrator, spp, seed)
}

/// The slab of [`slab`] filled with `medium` (the box |z| ≤ 0.625, |x|, |y| ≤ 50).
fn slab_of(medium: Medium, integrator: VolPathIntegrator, spp: u32, seed: u64) -> Film {
    let size = UVec2::new(16, 16);
    let (le, d) = (2.0f32, 1.25f64);
    let mut scene = build(
        vec![
            Object {
                shape: boxed(DVec3::new(50.0, 50.0, d / 2.0), DVec3::ZERO).into(),
                reflectance: 0.0,
                emission: None,
            },
            Object {
                shape: boxed(DVec3::new(50.0, 50.0, 0.5), DVec3::new(0.0, 0.0, 5.0)).into(),
                reflectance: 0.0,
                emission: Some(le),
            },
        ],
        vec![],
        narrow_camera(DVec3::new(0.0, 0.0, -5.0), DVec3::ZERO, size),
        size,
        integrator,
    );
    scene.world.media = vec![medium];
    // The tests' sample counts and margins were sized with this density (under `visible`, which
    // leaves the ends of the spectrum, where this σ_t is large, to few samples, the hero-only
    // estimator's variance is heavy-tailed and its own standard error several times larger).
    scene.film.wavelength_sampling = WavelengthSampling::Balanced;
    make_boundary(
        &mut scene,
        0,
        MediumInterface {
            interior: Some(0),
            exterior: None,
        },
    );
    render_film(&scene, spp, seed, None)
}

/// A purely absorbing slab: L = Lₑ exp(−σ_t(λ) d).
#[test]
fn transmittance_through_a_homogeneous_slab() {
    let (le, sigma_t, d) = (2.0f64, 0.8f32, 1.25f64);
    for (name, integrator) in volumetric_integrators() {
        let film = slab(Spectrum::Constant(sigma_t), 0.0, integrator, 2048, 1);
        let expected = le * (-f64::from(sigma_t) * d).exp();
        assert_mean_luminance(&format!("{name}: slab transmittance"), &film, expected);
    }
}

#[test]
fn transmittance_through_a_chromatic_slab() {
    let (le, d) = (2.0f64, 1.25f64);
    let sigma_t = chromatic_sigma_t();
    let expected = luminance(|lambda| le * (-f64::from(sigma_t.value(lambda as f32)) * d).exp());
    for (name, integrator) in chromatic_unbiased() {
        let film = slab(
            Spectrum::PiecewiseLinear(sigma_t.clone()),
            0.0,
            integrator,
            2048,
            11,
        );
        assert_mean_luminance(&format!("{name}: chromatic slab"), &film, expected);
    }
}

/// The mean over a film's pixels of the variance of one sample's luminance, and the standard
/// error of that mean (from the scatter of the pixels' variances).
fn mean_sample_variance(film: &Film) -> (f64, f64) {
    let variances: Vec<f64> = (0..film.pixels.len())
        .map(|i| {
            let n = film.pixels[i].samples as f64;
            pixel_mean_and_variance(film, i, 1).1 * n
        })
        .collect();
    let count = variances.len() as f64;
    let mean = variances.iter().sum::<f64>() / count;
    let spread = variances.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (count - 1.0);
    (mean, (spread / count).sqrt())
}

/// In a strongly chromatic scattering slab (σ_t from 0.3 to 6, albedo 0.8) in front of an
/// emitter, `volpathmis`'s variance per sample is below `volpath`'s and below that of the hero's
/// densities alone, by more than four standard errors of their difference.
#[test]
fn spectral_mis_lowers_variance_in_a_chromatic_medium() {
    let [volpath, mis, hero] = volumetric_integrators().map(|(name, integrator)| {
        let film = slab(
            Spectrum::PiecewiseLinear(chromatic_sigma_t()),
            0.8,
            integrator,
            512,
            21,
        );
        let (variance, se) = mean_sample_variance(&film);
        eprintln!("{name}: variance per sample {variance} ± {se}");
        (name, variance, se)
    });
    for other in [volpath, hero] {
        let margin = 4.0 * (mis.2 * mis.2 + other.2 * other.2).sqrt();
        assert!(
            mis.1 + margin < other.1,
            "volpathmis's variance {} is not below {}'s {} by 4 standard errors ({margin})",
            mis.1,
            other.0,
            other.1
        );
    }
}

/// Shadow rays cross `null` surfaces, as in Mitsuba's `volpath`: a diffuse plane lit by a
/// directional light through a `null` box (no media) looks the same as without the box (the
/// crossing draws no random numbers, so the images agree to rounding), and as ρ E cos θ / π.
#[test]
fn shadow_rays_pass_through_null_surfaces() {
    let size = UVec2::new(8, 8);
    let (rho, e) = (0.5f64, 3.0f64);
    let direction = DVec3::new(0.3, -0.2, -1.0).normalize();
    let render_with = |null_box: bool, integrator: VolPathIntegrator| {
        let mut objects = vec![Object {
            shape: boxed(DVec3::new(200.0, 200.0, 0.5), DVec3::new(0.0, 0.0, -0.5)).into(),
            reflectance: rho as f32,
            emission: None,
        }];
        if null_box {
            objects.push(Object {
                shape: boxed(DVec3::new(200.0, 200.0, 0.25), DVec3::new(0.0, 0.0, 1.0)).into(),
                reflectance: 0.0,
                emission: None,
            });
        }
        let mut scene = build(
            objects,
            vec![Light::Directional(DirectionalLight::new(
                direction.as_vec3(),
                Spectrum::Constant(e as f32),
            ))],
            narrow_camera(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO, size),
            size,
            integrator,
        );
        if null_box {
            make_boundary(&mut scene, 1, MediumInterface::default());
        }
        image_mean_and_standard_error(&render_film(&scene, 64, 30, None), 1).0
    };
    for (name, integrator) in volumetric_integrators() {
        let through = render_with(true, integrator.clone());
        let open = render_with(false, integrator);
        let expected = rho * e * -direction.z / std::f64::consts::PI;
        assert!(
            (through - open).abs() < 1e-5 * open && (open - expected).abs() < 0.01 * expected,
            "{name}: the plane has luminance {through} behind a null box, {open} without, \
             expected {expected}"
        );
    }
}

/// Single scattering: a slab z ∈ [0, d] of σ_t, σ_s = α σ_t, seen along the unit direction ω_c
/// (cos θ_c = ω_c·z) and lit by a directional light of irradiance E travelling along ω_l
/// (cos θ_l = ω_l·z), both entering through the face z = 0. With `max_depth` 2 the path has
/// one scattering vertex, so (with L = d / cos θ_c the camera ray's length in the slab and
/// k = 1 + cos θ_c / cos θ_l)
///   L_ss = ∫₀ᴸ e^{−σ_t s} σ_s p(−ω_c, −ω_l) E e^{−σ_t s cos θ_c / cos θ_l} ds
///        = σ_s p E (1 − e^{−σ_t L k}) / (σ_t k)
/// at each wavelength. The light's shadow rays leave the slab through its `null` boundary.
fn single_scattering(
    phase: PhaseFunction,
    sigma_t: Spectrum,
    integrator: VolPathIntegrator,
    name: &str,
    seed: u64,
) {
    let size = UVec2::new(16, 16);
    let (albedo, d, e) = (0.7f64, 0.5f64, 3.0f64);
    let omega_c = DVec3::new(0.3, 0.0, 1.0).normalize();
    let omega_l = DVec3::new(-0.5, 0.2, 1.0).normalize();
    let mut scene = build(
        vec![Object {
            shape: boxed(
                DVec3::new(200.0, 200.0, d / 2.0),
                DVec3::new(0.0, 0.0, d / 2.0),
            )
            .into(),
            reflectance: 0.0,
            emission: None,
        }],
        vec![Light::Directional(DirectionalLight::new(
            omega_l.as_vec3(),
            Spectrum::Constant(e as f32),
        ))],
        narrow_camera(-omega_c * 4.0, DVec3::ZERO, size),
        size,
        VolPathIntegrator {
            max_depth: 2,
            ..integrator
        },
    );
    let p = f64::from(phase.eval(-omega_c.as_vec3(), -omega_l.as_vec3()));
    scene.world.media = vec![homogeneous(sigma_t.clone(), albedo as f32, phase)];
    make_boundary(
        &mut scene,
        0,
        MediumInterface {
            interior: Some(0),
            exterior: None,
        },
    );
    let film = render_film(&scene, 2048, seed, None);
    let length = d / omega_c.z;
    let k = 1.0 + omega_c.z / omega_l.z;
    let expected = luminance(|lambda| {
        let sigma_t = f64::from(sigma_t.value(lambda as f32));
        albedo * sigma_t * p * e * (1.0 - (-sigma_t * length * k).exp()) / (sigma_t * k)
    });
    assert_mean_luminance(
        &format!("{name}: single scattering in a slab"),
        &film,
        expected,
    );
}

#[test]
fn single_scattering_in_a_slab_isotropic() {
    for (name, integrator) in volumetric_integrators() {
        single_scattering(
            PhaseFunction::Isotropic(Isotropic),
            Spectrum::Constant(0.6),
            integrator,
            name,
            2,
        );
    }
}

#[test]
fn single_scattering_in_a_slab_henyey_greenstein() {
    single_scattering(
        PhaseFunction::HenyeyGreenstein(HenyeyGreenstein { g: -0.3 }),
        Spectrum::Constant(0.6),
        VolPathIntegrator::default(),
        "volpath",
        3,
    );
}

#[test]
fn single_scattering_in_a_slab_rayleigh() {
    single_scattering(
        PhaseFunction::Rayleigh(Rayleigh),
        Spectrum::Constant(0.6),
        VolPathIntegrator::default(),
        "volpath rayleigh",
        4,
    );
}

#[test]
fn single_scattering_in_a_slab_tabulated() {
    let table = TabulatedPhase::new(&[0.2, 0.3, 0.5, 0.9, 2.0, 6.0]).unwrap();
    single_scattering(
        PhaseFunction::Tabulated(table),
        Spectrum::Constant(0.6),
        VolPathIntegrator::default(),
        "volpath tabphase",
        5,
    );
}

#[test]
fn single_scattering_in_a_chromatic_slab() {
    for (name, integrator) in chromatic_unbiased() {
        single_scattering(
            PhaseFunction::HenyeyGreenstein(HenyeyGreenstein { g: 0.4 }),
            Spectrum::PiecewiseLinear(chromatic_sigma_t()),
            integrator,
            name,
            12,
        );
    }
}

/// A closed sphere of reflectance ρ = 0.5 emitting Lₑ = 1, filled with a medium that scatters all it
/// removes (albedo 1): radiance Lₑ/(1 − ρ) = 2 everywhere solves both the rendering equation on the
/// wall and the transfer equation inside (σ_t L = σ_s ∫ p L), whatever σ_t, its variation
/// with wavelength and the phase function.
fn medium_furnace(
    medium: Medium,
    (name, integrator): (&str, VolPathIntegrator),
    spp: u32,
    seed: u64,
) {
    let size = UVec2::new(8, 8);
    let mut scene = build(
        vec![Object {
            shape: Shape::Sphere(Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
                rotation: Mat3::IDENTITY,
                flip_normals: true,
            })
            .into(),
            reflectance: 0.5,
            emission: Some(1.0),
        }],
        vec![],
        camera(
            DVec3::new(0.1, 0.2, -0.3),
            DVec3::new(0.5, 0.3, 1.0),
            DVec3::Y,
            70.0,
            size,
        ),
        size,
        integrator,
    );
    scene.world.media = vec![medium];
    scene.world.medium_interfaces = vec![MediumInterface {
        interior: Some(0),
        exterior: Some(0),
    }];
    scene.world.camera_medium = Some(0);
    let film = render_film(&scene, spp, seed, None);
    assert_mean_luminance(&format!("{name}: medium furnace"), &film, 2.0);
}

#[test]
fn closed_furnace_with_a_chromatic_non_absorbing_medium() {
    let sigma_t = PiecewiseLinear::new(&[(360.0, 4.0), (550.0, 0.5), (830.0, 2.5)]).unwrap();
    for (k, integrator) in chromatic_unbiased().into_iter().enumerate() {
        medium_furnace(
            homogeneous(
                Spectrum::PiecewiseLinear(sigma_t.clone()),
                1.0,
                PhaseFunction::HenyeyGreenstein(HenyeyGreenstein { g: 0.6 }),
            ),
            integrator,
            2048,
            4 + 10 * k as u64,
        );
    }
}

/// A grid of values in [lo, hi) from a fixed seed.
fn random_grid(resolution: [usize; 3], lo: f32, hi: f32, seed: u64) -> Vec<f32> {
    let mut rng = Pcg32::seeded(seed);
    (0..resolution.iter().product())
        .map(|_| lo + (hi - lo) * rng.next_f32())
        .collect()
}

#[test]
fn closed_furnace_with_a_heterogeneous_non_absorbing_medium() {
    let to_world = Transform::new(
        DMat4::from_translation(DVec3::splat(-0.8)) * DMat4::from_scale(DVec3::splat(1.6)),
    )
    .unwrap();
    let grid = GridVolume::new(
        [6, 5, 7],
        random_grid([6, 5, 7], 0.0, 3.0, 5),
        to_world,
        GridFilter::Trilinear,
    )
    .unwrap();
    for (k, integrator) in volumetric_integrators().into_iter().enumerate() {
        medium_furnace(
            Medium {
                kind: MediumKind::Heterogeneous(Heterogeneous {
                    sigma_t: Volume::Grid(Box::new(grid.clone())),
                    albedo: Volume::Constant(Spectrum::Constant(1.0)),
                    scale: 1.5,
                }),
                phase: PhaseFunction::Isotropic(Isotropic),
                sample_emitters: true,
            },
            integrator,
            2048,
            6 + 10 * k as u64,
        );
    }
}

/// pbrt-v4's grid medium ([`HeterogeneousAbsorbingScattering`]): `density` times `sigma_a` and
/// `sigma_s`, times `scale`, with an isotropic phase function.
fn density_medium(density: Volume, sigma_a: Spectrum, sigma_s: Spectrum, scale: f32) -> Medium {
    Medium {
        kind: MediumKind::HeterogeneousAbsorbingScattering(HeterogeneousAbsorbingScattering {
            density,
            sigma_a,
            sigma_s,
            scale,
        }),
        phase: PhaseFunction::Isotropic(Isotropic),
        sample_emitters: true,
    }
}

/// A grid of one value, `density`, over the cube [−1, 1]³.
fn uniform_density(density: f32) -> Volume {
    let to_world = Transform::new(
        DMat4::from_translation(DVec3::splat(-1.0)) * DMat4::from_scale(DVec3::splat(2.0)),
    )
    .unwrap();
    Volume::Grid(Box::new(
        GridVolume::new([2, 2, 2], vec![density; 8], to_world, GridFilter::Trilinear).unwrap(),
    ))
}

/// A purely absorbing slab of a uniform density grid (0.5) times a chromatic σ_a (times 2): the
/// homogeneous slab's L = Lₑ exp(−σ_t(λ) d) with σ_t = 0.5 · 2 · σ_a(λ), though the grid is ratio
/// tracked, with one majorant for the four wavelengths.
#[test]
fn transmittance_through_a_chromatic_density_grid() {
    let (le, d) = (2.0f64, 1.25f64);
    let sigma_t = chromatic_sigma_t();
    let expected = luminance(|lambda| le * (-f64::from(sigma_t.value(lambda as f32)) * d).exp());
    for (k, (name, integrator)) in chromatic_unbiased().into_iter().enumerate() {
        let medium = density_medium(
            uniform_density(0.5),
            Spectrum::PiecewiseLinear(sigma_t.clone()),
            Spectrum::Constant(0.0),
            2.0,
        );
        let film = slab_of(medium, integrator, 2048, 21 + k as u64);
        assert_mean_luminance(&format!("{name}: chromatic density grid"), &film, expected);
    }
}

/// A density grid times a chromatic σ_s, without absorption, fills the closed furnace of
/// [`medium_furnace`]: L = 2, for `volpath` and `volpathmis` (see [`chromatic_unbiased`]).
#[test]
fn closed_furnace_with_a_chromatic_density_grid() {
    let to_world = Transform::new(
        DMat4::from_translation(DVec3::splat(-0.8)) * DMat4::from_scale(DVec3::splat(1.6)),
    )
    .unwrap();
    let grid = GridVolume::new(
        [5, 6, 4],
        random_grid([5, 6, 4], 0.0, 2.0, 8),
        to_world,
        GridFilter::Trilinear,
    )
    .unwrap();
    let sigma_s = PiecewiseLinear::new(&[(360.0, 3.0), (550.0, 0.4), (830.0, 2.0)]).unwrap();
    for (k, integrator) in chromatic_unbiased().into_iter().enumerate() {
        medium_furnace(
            density_medium(
                Volume::Grid(Box::new(grid.clone())),
                Spectrum::Constant(0.0),
                Spectrum::PiecewiseLinear(sigma_s.clone()),
                1.2,
            ),
            integrator,
            2048,
            31 + 10 * k as u64,
        );
    }
}

/// The XML form of pbrt's grid media: `density` with `sigma_a` and `sigma_s`, not mixed with
/// Mitsuba's `sigma_t` and `albedo`, and all three given.
#[test]
fn a_density_medium_needs_its_three_parameters_alone() {
    let scene = |medium: &str| {
        format!(
            r#"<scene version="3.0.0">
    <integrator type="volpath"/>
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
    <shape type="sphere">
        <bsdf type="null"/>
        <medium type="heterogeneous" name="interior">{medium}</medium>
    </shape>
</scene>"#
        )
    };
    let error = |medium: &str| match scene_from_xml(&scene(medium), "density.xml") {
        Ok(_) => panic!("{medium}: the scene was built"),
        Err(e) => e.to_string(),
    };
    let density = r#"<float name="density" value="2"/>"#;
    let sigma_a = r#"<rgb name="sigma_a" value="0.1, 0.2, 0.3"/>"#;
    let sigma_s = r#"<spectrum name="sigma_s" value="400:1, 700:2"/>"#;
    scene_from_xml(
        &scene(&format!("{density}{sigma_a}{sigma_s}")),
        "density.xml",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let message = error(&format!("{density}{sigma_s}"));
    assert!(message.contains("without \"sigma_a\""), "{message}");
    let message = error(&format!(
        "{density}{sigma_a}{sigma_s}<float name=\"albedo\" value=\"0.5\"/>"
    ));
    assert!(
        message.contains("both density/sigma_a/sigma_s and \"albedo\""),
        "{message}"
    );
}

/// Ratio tracking through a density grid times chromatic σ_a + σ_s: at each of the path's four
/// wavelengths, the mean of 40 000 estimates equals exp(−scale (σ_a(λᵢ) + σ_s(λᵢ)) ∫ d) within
/// four standard errors, though the four share one majorant (the largest of their bounds).
#[test]
fn ratio_tracking_is_unbiased_in_a_chromatic_density_grid() {
    let resolution = [5, 4, 6];
    let grid = GridVolume::new(
        resolution,
        random_grid(resolution, 0.0, 2.0, 12),
        Transform::IDENTITY,
        GridFilter::Trilinear,
    )
    .unwrap();
    let sigma_a = PiecewiseLinear::new(&[(360.0, 2.0), (550.0, 0.2), (830.0, 1.0)]).unwrap();
    let scale = 1.3f32;
    let medium = density_medium(
        Volume::Grid(Box::new(grid.clone())),
        Spectrum::PiecewiseLinear(sigma_a.clone()),
        Spectrum::Constant(0.3),
        scale,
    );
    let lambda = SampledWavelengths::sample(0.37, WavelengthSampling::Uniform);
    let rays = [
        Ray::new(
            Vec3::new(-0.5, 0.3, 0.4),
            Vec3::new(1.0, 0.1, 0.05).normalize(),
            10.0,
            0.0,
        ),
        Ray::new(
            Vec3::new(0.5, 0.5, 0.5),
            Vec3::new(-0.4, 0.5, 0.9).normalize(),
            0.6,
            0.0,
        ),
    ];
    let runs = 40_000;
    for (r, ray) in rays.iter().enumerate() {
        let mut rng = Pcg32::new(77, r as u64);
        let (mut sum, mut sum_sq) = ([0.0f64; 4], [0.0f64; 4]);
        for _ in 0..runs {
            let t = medium.transmittance(ray, ray.t_max, &lambda, || rng.next_f32());
            for i in 0..4 {
                sum[i] += f64::from(t[i]);
                sum_sq[i] += f64::from(t[i]) * f64::from(t[i]);
            }
        }
        for i in 0..4 {
            let sigma_t = f64::from(sigma_a.value(lambda.lambda(i))) + 0.3;
            let exact =
                (-optical_depth(&grid, ray, ray.t_max, f64::from(scale) * sigma_t, true)).exp();
            let mean = sum[i] / runs as f64;
            let se = ((sum_sq[i] / runs as f64 - mean * mean) / (runs as f64 - 1.0)).sqrt();
            assert!(
                exact < 0.99 && se > 0.0,
                "ray {r}, λ {}: the ray must cross the grid (exact {exact})",
                lambda.lambda(i)
            );
            assert!(
                (mean - exact).abs() < 4.0 * se,
                "ray {r}, λ {}: ratio tracking gives {mean}, exact {exact} ({:.2} standard errors)",
                lambda.lambda(i),
                (mean - exact).abs() / se
            );
        }
    }
}

/// A sphere of radius R emitting Lₑ at distance D from the camera, both in an absorbing medium
/// (σ_t = 0.5, albedo 0): L = Lₑ exp(−σ_t (D − R)) along the axis.
#[test]
fn emitter_inside_an_absorbing_medium() {
    let size = UVec2::new(16, 16);
    let (le, sigma_t, distance, radius) = (3.0f32, 0.5f32, 3.0f64, 0.5f32);
    let mut scene = build(
        vec![Object {
            shape: Shape::Sphere(Sphere {
                center: Vec3::new(0.0, 0.0, distance as f32),
                radius,
                rotation: Mat3::IDENTITY,
                flip_normals: false,
            })
            .into(),
            reflectance: 0.0,
            emission: Some(le),
        }],
        vec![],
        narrow_camera(DVec3::ZERO, DVec3::new(0.0, 0.0, 1.0), size),
        size,
        VolPathIntegrator::default(),
    );
    scene.world.media = vec![homogeneous(
        Spectrum::Constant(sigma_t),
        0.0,
        PhaseFunction::Isotropic(Isotropic),
    )];
    scene.world.camera_medium = Some(0);
    let film = render_film(&scene, 2048, 7, None);
    let expected = f64::from(le) * (-f64::from(sigma_t) * (distance - f64::from(radius))).exp();
    assert_mean_luminance("emitter in an absorbing medium", &film, expected);
}

/// The exact optical depth ∫σ_t along `ray` from 0 to `t_max` through `grid` (scaled by
/// `scale`): between consecutive crossings of the planes where the interpolation changes (voxel
/// faces for `nearest`, voxel centres for trilinear) the value along the ray is constant or a
/// cubic in t, so the midpoint rule (constant) or Simpson's rule (cubic) on each piece is exact.
fn optical_depth(grid: &GridVolume, ray: &Ray, t_max: f32, scale: f64, trilinear: bool) -> f64 {
    let Some((t0, t1)) = grid.ray_extent(ray, t_max) else {
        return 0.0;
    };
    let (t0, t1) = (f64::from(t0), f64::from(t1));
    // The grid here is the unit cube placed by the identity.
    let res = grid.resolution();
    let mut breaks = vec![t0, t1];
    for (axis, &n) in res.iter().enumerate() {
        let (o, d) = (f64::from(ray.o[axis]), f64::from(ray.d[axis]));
        for k in 0..=n {
            let plane = if trilinear {
                (k as f64 + 0.5) / n as f64
            } else {
                k as f64 / n as f64
            };
            let t = (plane - o) / d;
            if t > t0 && t < t1 {
                breaks.push(t);
            }
        }
    }
    breaks.sort_by(f64::total_cmp);
    let at = |t: f64| {
        let p = ray.o + ray.d * t as f32;
        f64::from(grid.eval_local(p))
    };
    breaks
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            if trilinear {
                (b - a) / 6.0 * (at(a) + 4.0 * at(0.5 * (a + b)) + at(b))
            } else {
                // Constant on the piece, whose ends lie on voxel faces where the lookup may
                // take the neighbour's value: the midpoint's.
                (b - a) * at(0.5 * (a + b))
            }
        })
        .sum::<f64>()
        * scale
}

/// Ratio tracking's estimate of transmittance through generated grids, averaged over 40 000
/// runs, equals exp(−optical depth) within four standard errors, for both filters and rays
/// that enter, cross and leave the grid.
#[test]
fn ratio_tracking_is_unbiased_on_generated_grids() {
    let rays = [
        Ray::new(
            Vec3::new(-0.5, 0.3, 0.4),
            Vec3::new(1.0, 0.1, 0.05).normalize(),
            f32::INFINITY,
            0.0,
        ),
        Ray::new(
            Vec3::new(0.2, 1.4, 0.7),
            Vec3::new(0.3, -1.0, -0.2).normalize(),
            f32::INFINITY,
            0.0,
        ),
        Ray::new(
            Vec3::new(0.5, 0.5, 0.5),
            Vec3::new(-0.4, 0.5, 0.9).normalize(),
            0.6,
            0.0,
        ),
    ];
    let lambda = prism_core::spectrum::SampledWavelengths::single(550.0);
    let runs = 40_000;
    for (case, filter) in [GridFilter::Nearest, GridFilter::Trilinear]
        .into_iter()
        .enumerate()
    {
        let resolution = [5, 4, 6];
        let grid = GridVolume::new(
            resolution,
            random_grid(resolution, 0.0, 2.0, 10 + case as u64),
            Transform::IDENTITY,
            filter,
        )
        .unwrap();
        let scale = 1.7f32;
        let medium = Medium {
            kind: MediumKind::Heterogeneous(Heterogeneous {
                sigma_t: Volume::Grid(Box::new(grid.clone())),
                albedo: Volume::Constant(Spectrum::Constant(0.5)),
                scale,
            }),
            phase: PhaseFunction::Isotropic(Isotropic),
            sample_emitters: true,
        };
        for (r, ray) in rays.iter().enumerate() {
            let t_max = if ray.t_max.is_finite() {
                ray.t_max
            } else {
                10.0
            };
            let exact = (-optical_depth(
                &grid,
                ray,
                t_max,
                f64::from(scale),
                filter == GridFilter::Trilinear,
            ))
            .exp();
            let mut rng = Pcg32::new(99, (case * 10 + r) as u64);
            let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
            for _ in 0..runs {
                let t = f64::from(medium.transmittance(ray, t_max, &lambda, || rng.next_f32())[0]);
                sum += t;
                sum_sq += t * t;
            }
            let mean = sum / runs as f64;
            let se = ((sum_sq / runs as f64 - mean * mean) / (runs as f64 - 1.0)).sqrt();
            assert!(
                exact < 0.999 && se > 0.0,
                "case {case}, ray {r}: the ray must cross the grid (exact {exact})"
            );
            assert!(
                (mean - exact).abs() < 4.0 * se,
                "{filter:?}, ray {r}: ratio tracking gives {mean}, exact {exact} ({:.2} standard errors)",
                (mean - exact).abs() / se
            );
        }
    }
}

/// Behind dispersive glass a path keeps only its hero wavelength, and `volpathmis` then weights
/// its whole estimate by the hero's densities: in a chromatic fog around a dispersive sphere
/// (Cauchy index) lit by a spherical emitter, `volpathmis` and `volpath` give the same image
/// mean of X, Y and Z within four standard errors of the difference.
#[test]
fn volpathmis_agrees_with_volpath_behind_dispersive_glass() {
    let xml = r#"<scene version="3.0.0">
    <integrator type="volpathmis"/>
    <medium type="homogeneous" id="fog">
        <spectrum name="sigma_t" value="360:0.9, 550:0.05, 830:0.5"/>
        <float name="albedo" value="0.8"/>
    </medium>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, -3" target="0, 0.3, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
        <ref id="fog"/>
    </sensor>
    <shape type="sphere">
        <float name="radius" value="0.7"/>
        <bsdf type="dielectric">
            <spectrum type="cauchy" name="int_ior"><float name="a" value="1.3"/><float name="b" value="0.03"/></spectrum>
        </bsdf>
        <ref name="exterior" id="fog"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="0.4" y="1.6" z="0.8"/>
        <float name="radius" value="0.4"/>
        <emitter type="area"><rgb name="radiance" value="8"/></emitter>
        <ref name="exterior" id="fog"/>
    </shape>
</scene>"#;
    let root = read_scene_str(xml, std::path::Path::new("dispersion-in-fog.xml"), &[]).unwrap();
    let mut scene = build_scene(&root).unwrap().scene;
    assert!(
        matches!(&scene.integrator, Integrator::VolPath(v) if v.tracking == Tracking::HeroMis { spectral_mis: true })
    );
    let mis = render_film(&scene, 2560, 40, None);
    scene.integrator = VolPathIntegrator::default().into();
    let volpath = render_film(&scene, 2560, 41, None);
    for c in 0..3 {
        let (a, se_a) = image_mean_and_standard_error(&mis, c);
        let (b, se_b) = image_mean_and_standard_error(&volpath, c);
        let se = (se_a * se_a + se_b * se_b).sqrt();
        eprintln!("channel {c}: volpathmis {a} ± {se_a}, volpath {b} ± {se_b}");
        assert!(
            se < 0.01 * b,
            "channel {c}: the standard error {se} is too large to see a 4 % bias in {b}"
        );
        assert!(
            (a - b).abs() < 4.0 * se,
            "channel {c}: volpathmis {a}, volpath {b}: {:.2} standard errors",
            (a - b).abs() / se
        );
    }
}

/// A sphere of radius 1 holding a chromatic homogeneous medium with a `null` boundary, lit by
/// two rectangles, one behind it (forward scattering towards the camera) and one beside it;
/// `PHASE` is replaced by the phase function.
const PHASE_SCENE: &str = r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="16"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="35"/>
        <transform name="to_world"><lookat origin="0, 0, -5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
    </sensor>
    <shape type="sphere">
        <float name="radius" value="1"/>
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior">
            <rgb name="sigma_t" value="0.6, 0.8, 1.0"/><float name="scale" value="2.5"/>
            <rgb name="albedo" value="0.9, 0.8, 0.95"/>
            PHASE
        </medium>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.6"/><rotate y="1" angle="180"/><translate x="0.8" y="0.5" z="2.5"/></transform>
        <emitter type="area"><rgb name="radiance" value="6, 5, 4"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate y="1" angle="-60"/><translate x="-2.5" y="-0.5" z="0"/></transform>
        <emitter type="area"><rgb name="radiance" value="3, 4, 5"/></emitter>
    </shape>
</scene>"#;

/// The phase functions Prism adds to Mitsuba's `isotropic` and `hg` give Mitsuba's image: the
/// mean luminance of `PHASE_SCENE` against Mitsuba 3.9.1 `scalar_spectral` at 16,384 spp
/// (seed 21; Y = 0.2126 R + 0.7152 G + 0.0722 B of its mean linear sRGB; its own standard
/// error, from the pixel differences of two such renders, about 0.25 % of the mean). The
/// `tabphase` table is read in the physics convention (its last value is forward scattering):
/// reversed, the same values give an image 23 % darker, far outside the tolerance.
#[test]
fn phase_functions_match_mitsuba() {
    for (phase, mitsuba_y) in [
        (r#"<phase type="isotropic"/>"#, 0.052076f64),
        (r#"<phase type="rayleigh"/>"#, 0.052908),
        (
            r#"<phase type="tabphase"><string name="values" value="0.2, 0.3, 0.5, 0.9, 2.0, 6.0"/></phase>"#,
            0.064254,
        ),
        (
            r#"<phase type="tabphase"><string name="values" value="6.0, 2.0, 0.9, 0.5, 0.3, 0.2"/></phase>"#,
            0.049563,
        ),
    ] {
        let xml = PHASE_SCENE.replace("PHASE", phase);
        let scene = scene_from_xml(&xml, "phase.xml").unwrap();
        let film = render_film(&scene, 1024, 7, None);
        let (mean, se) = image_mean_and_standard_error(&film, 1);
        let tolerance = 4.0 * (se * se + (0.0025 * mitsuba_y).powi(2)).sqrt();
        assert!(
            (mean - mitsuba_y).abs() < tolerance,
            "{phase}: mean Y {mean} ± {se}, Mitsuba {mitsuba_y} (tolerance {tolerance})"
        );
    }
}

/// The SGGX phase function's value and projected area equal Mitsuba 3.9.1's (`eval_pdf` and
/// `projected_area` of its `sggx` with S = 1, 0.35, 0.32, 0.52, 0.44, 0.2 in `scalar_spectral`,
/// for Mitsuba's mi.wi, Prism's wo, along (0.3, 0.2, 0.9)), to single precision.
#[test]
fn sggx_values_match_mitsuba() {
    let sggx = Sggx::new([1.0, 0.35, 0.32, 0.52, 0.44, 0.2]).unwrap();
    let wo = Vec3::new(0.3, 0.2, 0.9).normalize();
    assert!((sggx.projected_area(wo) / 0.8843799 - 1.0).abs() < 1e-5);
    let phase = PhaseFunction::Sggx(sggx);
    for (wi, mitsuba) in [
        (Vec3::new(0.0, 0.0, 1.0), 0.01736229),
        (Vec3::new(0.5, -0.2, 0.3), 0.07881507),
        (Vec3::new(-0.2, 0.1, -0.5), 0.003547097),
        (Vec3::new(0.1, 0.9, -0.2), 0.0118562),
    ] {
        let value = phase.eval(wo, wi.normalize());
        assert!(
            (value / mitsuba - 1.0).abs() < 1e-4,
            "p(wo, {wi}) = {value}, Mitsuba's {mitsuba}"
        );
    }
}

/// A `homogeneous` medium given a `gridvolume` albedo that holds one value everywhere renders
/// the same image, sample for sample, as the medium given that value: the grid's lookups return
/// it exactly, and the extinction, free flights and shadow rays are the homogeneous medium's.
#[test]
fn a_constant_albedo_grid_in_a_homogeneous_medium_is_the_constant() {
    let dir = std::env::temp_dir().join(format!("prism-albedo-grid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut vol = b"VOL\x03".to_vec();
    for v in [1i32, 2, 3, 2, 1] {
        vol.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        vol.extend(v.to_le_bytes());
    }
    for _ in 0..12 {
        vol.extend(0.625f32.to_le_bytes());
    }
    std::fs::write(dir.join("albedo.vol"), vol).unwrap();
    let scene = |albedo: &str| {
        format!(
            r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="8"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, -4, 1" target="0, 0, 0" up="0, 0, 1"/></transform>
        <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="180"/><translate z="2"/></transform>
        <emitter type="area"><rgb name="radiance" value="5"/></emitter>
    </shape>
    <shape type="sphere">
        <bsdf type="null"/>
        <medium type="homogeneous" name="interior"><float name="sigma_t" value="2"/>{albedo}</medium>
    </shape>
</scene>"#
        )
    };
    let film = |albedo: &str| {
        let scene = scene_from_xml(&scene(albedo), dir.join("scene.xml").to_str().unwrap())
            .unwrap_or_else(|e| panic!("{e}"));
        render_film(&scene, 16, 3, Some(1))
    };
    let plain = film(r#"<float name="albedo" value="0.625"/>"#);
    let grid = film(
        r#"<volume type="gridvolume" name="albedo"><string name="filename" value="albedo.vol"/></volume>"#,
    );
    std::fs::remove_dir_all(&dir).unwrap();
    let mut lit = 0;
    for i in 0..plain.pixels.len() {
        for c in 0..3 {
            assert_eq!(
                pixel_mean_and_variance(&plain, i, c),
                pixel_mean_and_variance(&grid, i, c),
                "pixel {i}, channel {c}"
            );
        }
        lit += usize::from(pixel_mean_and_variance(&plain, i, 1).0 > 0.0);
    }
    assert!(lit > 100, "the scene is lit");
}

/// A `heterogeneous` medium is empty outside its extinction volume's box, as in Mitsuba 3: an
/// absorbing sphere of radius 3 (σ_t 0.3) under a constant environment, with σ_t as a plain
/// value (the box is the unit cube, so little is absorbed), as a `constvolume` whose `to_world`
/// box [−3, 3]² × [−1, 2] cuts the sphere, and as a `homogeneous` medium for comparison. The
/// image means of Y are Mitsuba 3.9.1 `scalar_spectral`'s at 4096 spp (16 × 16 pixels).
#[test]
fn a_constvolume_bounds_its_heterogeneous_medium() {
    let scene = |medium: &str| {
        format!(
            r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 10" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><float name="radiance" value="1"/></emitter>
    <shape type="sphere"><float name="radius" value="3"/><bsdf type="null"/>{medium}</shape>
</scene>"#
        )
    };
    for (name, medium, mitsuba_y) in [
        (
            "homogeneous",
            r#"<medium type="homogeneous" name="interior"><float name="sigma_t" value="0.3"/><float name="albedo" value="0"/></medium>"#,
            0.612109f64,
        ),
        (
            "plain sigma_t",
            r#"<medium type="heterogeneous" name="interior"><float name="sigma_t" value="0.3"/><float name="albedo" value="0"/></medium>"#,
            0.994416,
        ),
        (
            "constvolume with to_world",
            r#"<medium type="heterogeneous" name="interior"><volume type="constvolume" name="sigma_t"><float name="value" value="0.3"/><transform name="to_world"><scale value="6, 6, 3"/><translate value="-3, -3, -1"/></transform></volume><float name="albedo" value="0"/></medium>"#,
            0.674913,
        ),
    ] {
        let scene = scene_from_xml(&scene(medium), "box.xml").unwrap_or_else(|e| panic!("{e}"));
        let film = render_film(&scene, 256, 7, None);
        let (mean, se) = image_mean_and_standard_error(&film, 1);
        let tolerance = 4.0 * se * (1.0 + 256.0 / 4096.0f64).sqrt();
        assert!(
            (mean - mitsuba_y).abs() < tolerance,
            "{name}: mean Y {mean} ± {se}, Mitsuba {mitsuba_y} (tolerance {tolerance})"
        );
    }
}
