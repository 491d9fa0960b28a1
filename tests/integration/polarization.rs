//! Polarized rendering against Mitsuba 3 and against closed forms, on the scenes of
//! `tests/data/polarization/` (its README says how the references were made): an area light
//! seen through two linear polarizers 60° apart (Malus's law), through two aligned ones and a
//! quarter-wave plate at 45° (circular light), a glass plane seen near Brewster's angle beside
//! a gold sphere, a `pplastic` plane at the same angle, a `twosided` polarizer seen from
//! either side behind a plain one, and a `blendbsdf` of a `twosided` polarizer and a diffuse
//! BSDF under a uniform sky, from either side, and a `measured_polarized` plane with a
//! synthetic table (`synthetic.pbsdf`), all through the `stokes` integrator.
//!
//! Each of the twelve channels S0.R … S3.B is compared by its image mean, Prism's from eight
//! renders with different seeds (their spread gives its standard error), with the mean of
//! eight renders of Mitsuba 3.9.1's `scalar_spectral_polarized`: within four standard errors of
//! the difference plus 0.2 % of S₀, the amount by which the two renderers' colours of the flat
//! emission spectrum differ in unpolarized renders too (README).

use std::path::{Path, PathBuf};

use crate::common::scenes::render_film;
use prism_core::scene::Scene;

/// The channels `stokes` writes, in Mitsuba's order.
const CHANNELS: [&str; 12] = [
    "S0.R", "S0.G", "S0.B", "S1.R", "S1.G", "S1.B", "S2.R", "S2.G", "S2.B", "S3.R", "S3.G", "S3.B",
];

/// Mitsuba's image means of the twelve channels for one scene and its parameters, and their
/// standard errors.
struct Reference {
    scene: &'static str,
    defines: &'static [(&'static str, &'static str)],
    mean: [f64; 12],
    standard_error: [f64; 12],
}

/// Mitsuba 3.9.1 `scalar_spectral_polarized`, eight renders of 1024 spp (seeds 1 to 8).
const REFERENCES: &[Reference] = &[
    Reference {
        scene: "polarizers",
        defines: &[],
        mean: [
            0.1507861, 0.1186589, 0.1137796, -0.0753251, -0.0592764, -0.0568377, -0.1306008,
            -0.1027741, -0.0985487, 0.0, 0.0, 0.0,
        ],
        standard_error: [
            2.03e-05, 3.05e-06, 1.20e-04, 1.00e-05, 1.53e-06, 5.98e-05, 1.77e-05, 2.69e-06,
            1.04e-04, 0.0, 0.0, 0.0,
        ],
    },
    Reference {
        scene: "polarizers",
        defines: &[("theta", "0"), ("delta", "90")],
        mean: [
            0.6030792, 0.4745875, 0.4550622, 0.0350536, 0.0275791, 0.0264106, -0.0000196,
            0.0000164, -0.0000873, 0.5897045, 0.4640651, 0.4449863,
        ],
        standard_error: [
            8.00e-05, 1.21e-05, 4.79e-04, 1.51e-05, 8.97e-06, 4.49e-05, 3.18e-05, 2.03e-05,
            3.50e-05, 7.58e-05, 1.36e-05, 4.64e-04,
        ],
    },
    Reference {
        scene: "brewster",
        defines: &[],
        mean: [
            0.6267441, 0.4774109, 0.4246311, 0.0428084, 0.0328932, 0.0298535, 0.0013505, 0.0011605,
            0.0013016, -0.0000243, -0.0000166, -0.0000094,
        ],
        standard_error: [
            3.17e-04, 2.37e-04, 4.01e-04, 3.47e-04, 2.97e-04, 4.01e-04, 6.72e-05, 5.02e-05,
            6.71e-05, 2.55e-05, 1.61e-05, 8.27e-06,
        ],
    },
    Reference {
        scene: "pplastic",
        defines: &[],
        mean: [
            0.2177895, 0.3110890, 0.5293539, 0.0754009, 0.0477179, 0.0266272, -0.0000822,
            -0.0000794, -0.0001025, 0.0, 0.0, 0.0,
        ],
        standard_error: [
            2.38e-04, 4.95e-04, 1.14e-03, 8.22e-05, 9.09e-05, 1.31e-04, 2.31e-05, 2.33e-05,
            4.03e-05, 0.0, 0.0, 0.0,
        ],
    },
    Reference {
        scene: "twosided",
        defines: &[],
        mean: [
            0.1507988, 0.1186561, 0.1137992, -0.0753316, -0.0592747, -0.0568492, -0.1306117,
            -0.1027719, -0.0985647, 0.0000000, 0.0000000, 0.0000000,
        ],
        standard_error: [
            3.13e-05, 2.52e-06, 7.55e-05, 1.62e-05, 1.37e-06, 3.76e-05, 2.68e-05, 2.23e-06,
            6.55e-05, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
    Reference {
        scene: "twosided",
        defines: &[("turn", "180")],
        mean: [
            0.1507839, 0.1186444, 0.1137884, -0.0753785, -0.0593116, -0.0568847, -0.1305854,
            -0.1027512, -0.0985453, 0.0000000, 0.0000000, 0.0000000,
        ],
        standard_error: [
            3.17e-05, 2.47e-06, 7.53e-05, 1.62e-05, 1.38e-06, 3.76e-05, 2.72e-05, 2.09e-06,
            6.52e-05, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
    Reference {
        scene: "blend",
        defines: &[],
        mean: [
            0.5730250, 0.4510178, 0.4329230, 0.2262134, 0.1780489, 0.1708257, -0.3918015,
            -0.3083817, -0.2958674, 0.0000000, 0.0000000, 0.0000000,
        ],
        standard_error: [
            2.62e-04, 2.07e-04, 2.25e-04, 1.52e-04, 1.18e-04, 1.31e-04, 2.63e-04, 2.04e-04,
            2.29e-04, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
    Reference {
        scene: "blend",
        defines: &[("turn", "180")],
        mean: [
            0.5730250, 0.4510178, 0.4329230, 0.2261897, 0.1780297, 0.1708075, -0.3917611,
            -0.3083503, -0.2958368, 0.0000000, 0.0000000, 0.0000000,
        ],
        standard_error: [
            2.62e-04, 2.07e-04, 2.25e-04, 1.51e-04, 1.18e-04, 1.30e-04, 2.63e-04, 2.04e-04,
            2.29e-04, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
    Reference {
        scene: "measured_polarized",
        defines: &[],
        mean: [
            0.4501475, 0.3267578, 0.2859972, 0.0131809, 0.0095663, 0.0083068, -0.0000428,
            -0.0000774, -0.0001053, 0.0000000, 0.0000000, 0.0000000,
        ],
        standard_error: [
            9.64e-04, 6.64e-04, 5.49e-04, 2.55e-04, 1.76e-04, 1.76e-04, 3.79e-04, 2.78e-04,
            3.64e-04, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
];

/// Mitsuba 3.9.1 `scalar_spectral_polarized` with `stokes` around `volpath`, eight renders of
/// 1024 spp (seeds 1 to 8).
const VOLUME_REFERENCES: &[Reference] = &[
    Reference {
        scene: "isotropic_slab",
        defines: &[("theta", "90")],
        mean: [
            0.0029892, 0.0023524, 0.0022566, -0.0029886, -0.0023519, -0.0022561, 0.0, 0.0, 0.0,
            0.0, 0.0, 0.0,
        ],
        standard_error: [
            1.05e-05, 7.40e-06, 5.59e-06, 1.05e-05, 7.40e-06, 5.58e-06, 1.50e-07, 1.10e-07,
            1.53e-07, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
    Reference {
        scene: "isotropic_slab",
        defines: &[("theta", "45")],
        mean: [
            0.1383866, 0.1089034, 0.1043446, 0.0000149, 0.0000116, 0.0000118, -0.1383766,
            -0.1088956, -0.1043371, 0.0, 0.0, 0.0,
        ],
        standard_error: [
            1.42e-04, 1.05e-04, 5.45e-05, 2.80e-06, 1.90e-06, 1.19e-06, 1.42e-04, 1.05e-04,
            5.45e-05, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
    Reference {
        scene: "slab",
        defines: &[("theta", "90")],
        mean: [
            0.0034783, 0.0027377, 0.0026227, -0.0034775, -0.0027371, -0.0026221, 0.0000004,
            0.0000003, 0.0000004, 0.0, 0.0, 0.0,
        ],
        standard_error: [
            9.53e-06, 7.32e-06, 6.01e-06, 9.52e-06, 7.32e-06, 6.01e-06, 2.33e-07, 1.54e-07,
            2.23e-07, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
    Reference {
        scene: "slab",
        defines: &[("theta", "45")],
        mean: [
            0.1884838, 0.1483533, 0.1422703, 0.0000206, 0.0000156, 0.0000137, -0.1884702,
            -0.1483425, -0.1422600, 0.0, 0.0, 0.0,
        ],
        standard_error: [
            1.71e-04, 1.34e-04, 1.76e-04, 2.17e-06, 1.76e-06, 1.80e-06, 1.71e-04, 1.34e-04,
            1.76e-04, 0.00e+00, 0.00e+00, 0.00e+00,
        ],
    },
];

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/polarization")
        .join(format!("{name}.xml"))
}

fn load(name: &str, defines: &[(&str, &str)]) -> Scene {
    let defines: Vec<(String, String)> = defines
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let root = prism_mitsuba::reader::read_scene_file(&scene_path(name), &defines)
        .unwrap_or_else(|e| panic!("{e}"));
    prism_mitsuba::factory::build_scene(&root)
        .unwrap_or_else(|e| panic!("{e}"))
        .scene
}

/// The image means of the twelve Stokes channels over `renders` renders of `spp` samples
/// with seeds 11, 12, …, and their standard errors from the spread of the renders.
fn stokes_means(scene: &Scene, spp: u32, renders: u64) -> ([f64; 12], [f64; 12]) {
    mean_and_standard_error(&stokes_renders(scene, spp, renders))
}

/// The image means of the twelve Stokes channels of `renders` renders of `spp` samples with
/// seeds 11, 12, …
fn stokes_renders(scene: &Scene, spp: u32, renders: u64) -> Vec<[f64; 12]> {
    (0..renders)
        .map(|i| {
            let film = render_film(scene, spp, 11 + i, None);
            assert_eq!(film.aov_names, CHANNELS, "the stokes integrator's channels");
            std::array::from_fn(|c| {
                let values = film.aov(c);
                values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64
            })
        })
        .collect()
}

/// The mean of each column of `rows` and its standard error from their spread.
fn mean_and_standard_error<const N: usize>(rows: &[[f64; N]]) -> ([f64; N], [f64; N]) {
    let n = rows.len() as f64;
    let mean: [f64; N] = std::array::from_fn(|c| rows.iter().map(|m| m[c]).sum::<f64>() / n);
    let standard_error = std::array::from_fn(|c| {
        let variance = rows.iter().map(|m| (m[c] - mean[c]).powi(2)).sum::<f64>() / (n - 1.0);
        (variance / n).sqrt()
    });
    (mean, standard_error)
}

#[test]
fn stokes_vectors_match_mitsuba() {
    assert_match_mitsuba(REFERENCES, &[]);
}

/// The scattering slabs between polarizers through `stokes` around `volpath`, and around
/// `volpathmis` against the same references (Mitsuba's `volpathmis` refuses polarized variants;
/// the two estimators have the same expectation).
#[test]
fn volumetric_stokes_vectors_match_mitsuba() {
    for integrator in ["volpath", "volpathmis"] {
        assert_match_mitsuba(VOLUME_REFERENCES, &[("integrator", integrator)]);
    }
}

/// Each reference's scene with its defines and `defines`, rendered eight times at 1024 spp:
/// every channel's image mean within four standard errors of the difference plus 0.2 % of S₀.
fn assert_match_mitsuba(references: &[Reference], defines: &[(&str, &str)]) {
    let mut failures = Vec::new();
    for r in references {
        let all: Vec<(&str, &str)> = r.defines.iter().chain(defines).copied().collect();
        let scene = load(r.scene, &all);
        let (mean, se) = stokes_means(&scene, 1024, 8);
        for (c, channel) in CHANNELS.iter().enumerate() {
            let s0 = r.mean[c % 3].abs();
            let tolerance = 4.0
                * (se[c] * se[c] + r.standard_error[c] * r.standard_error[c]).sqrt()
                + 0.002 * s0;
            let row = format!(
                "{} {all:?} {channel}: Prism {:.6} ± {:.1e}, Mitsuba {:.6} ± {:.1e}",
                r.scene, mean[c], se[c], r.mean[c], r.standard_error[c]
            );
            if (mean[c] - r.mean[c]).abs() >= tolerance || mean[c].is_nan() {
                failures.push(format!("{row} (tolerance {tolerance:.1e})"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Malus's law times the transmittance of an absorbing medium between the two polarizers, for
/// `volpath` and `volpathmis`: with the second polarizer at θ from the first and the slab of
/// thickness d and extinction σ_t (albedo 0) between them, seen head-on by an orthographic
/// camera, each channel's mean is e^{−σ_t d} cos²θ (1, cos 2θ, −sin 2θ, 0) times S₀ through the
/// aligned polarizers without the medium (the sign of S₂ is that of the sensor's frame, as
/// in the Mitsuba references of `polarizers.xml`). The expected ratios' tolerance is four
/// standard errors of the ratio of the two means.
#[test]
fn malus_law_through_an_absorbing_medium() {
    let (sigma_t, thickness) = (1.0f64, 0.5f64);
    let transmittance = (-sigma_t * thickness).exp();
    for integrator in ["volpath", "volpathmis"] {
        let means = |theta: &str, sigma_t: &str| {
            let defines = [
                ("integrator", integrator),
                ("theta", theta),
                ("sigma_t", sigma_t),
            ];
            stokes_means(&load("absorber", &defines), 256, 8)
        };
        let (clear, clear_se) = means("0", "0");
        for degrees in [0.0f64, 30.0, 60.0, 90.0] {
            let (mean, se) = means(&degrees.to_string(), &sigma_t.to_string());
            let theta = degrees.to_radians();
            let malus = transmittance * theta.cos().powi(2);
            let direction = [1.0, (2.0 * theta).cos(), -(2.0 * theta).sin(), 0.0];
            for (c, channel) in CHANNELS.iter().enumerate() {
                let s0 = clear[c % 3];
                let ratio = mean[c] / s0;
                let expected = malus * direction[c / 3];
                let ratio_se = (se[c] / s0).hypot(ratio * clear_se[c % 3] / s0);
                assert!(
                    (ratio - expected).abs() <= 4.0 * ratio_se + 1e-6,
                    "{integrator}, {degrees}° {channel}: {ratio} ± {ratio_se:.1e} of S₀ \
                     without the medium, expected {expected}"
                );
            }
        }
    }
}

/// Malus's law through the whole renderer: S₀ through two polarizers θ apart is cos²θ times
/// S₀ through two aligned ones (the ratio does not depend on the colours), and the light that
/// passes is linearly polarized along the second polarizer: S₁ = cos 2θ' S₀, S₂ = sin 2θ' S₀
/// up to the frame's orientation, so S₁² + S₂² = S₀² and S₃ = 0.
#[test]
fn two_polarizers_follow_malus_law() {
    assert_malus_law("polarizers", &[]);
}

/// Malus's law through a `twosided` polarizer, seen from its front and from its back: S₀
/// behind a plain polarizer and the two-sided one θ apart is cos²θ times S₀ with the two
/// aligned, and the light that passes is fully linearly polarized.
#[test]
fn a_twosided_polarizer_follows_malus_law_from_both_sides() {
    for turn in ["0", "180"] {
        assert_malus_law("twosided", &[("turn", turn)]);
    }
}

/// Scene `name` with `defines` and its second polarizer at `theta` = 30°, 60° and 90° from the
/// first: S₀ is cos²θ times S₀ at 0°, the light fully linearly polarized, none of it circular.
fn assert_malus_law(name: &str, defines: &[(&str, &str)]) {
    let with_theta = |theta: &str| {
        let mut all = defines.to_vec();
        all.push(("theta", theta));
        stokes_means(&load(name, &all), 64, 2).0
    };
    let aligned = with_theta("0");
    for degrees in [30.0f64, 60.0, 90.0] {
        let mean = with_theta(&degrees.to_string());
        let expected = degrees.to_radians().cos().powi(2);
        for c in 0..3 {
            let ratio = mean[c] / aligned[c];
            assert!(
                (ratio - expected).abs() < 2e-3,
                "{name} {defines:?}, {degrees}° {}: {ratio} against cos²θ = {expected}",
                CHANNELS[c]
            );
            let linear = (mean[3 + c].powi(2) + mean[6 + c].powi(2)).sqrt();
            assert!(
                (linear - mean[c]).abs() <= 2e-3 * aligned[c],
                "{name} {defines:?}, {degrees}°: not fully polarized"
            );
            assert!(
                mean[9 + c].abs() <= 1e-6,
                "{name} {defines:?}, {degrees}°: S3 {}",
                mean[9 + c]
            );
        }
    }
}

/// A sheet blending a polarizer (share 1 − w) and a diffuse BSDF of reflectance ρ (share w)
/// under a uniform sky of radiance L, seen from either side: the polarizer passes ½ (1 − w) L,
/// fully linearly polarized, the diffuse BSDF reflects w ρ L, unpolarized, so the degree of
/// linear polarization √(S₁² + S₂²) / S₀ is ½ (1 − w) / (½ (1 − w) + w ρ), whatever the colour
/// of L; nothing is circular. Each render's ratio gives one value; their spread the tolerance.
#[test]
fn a_blend_of_a_polarizer_and_a_diffuse_bsdf_has_the_closed_form_polarization() {
    let (weight, reflectance) = (0.25, 0.4);
    let polarized = 0.5 * (1.0 - weight);
    let expected = polarized / (polarized + weight * reflectance);
    for turn in ["0", "180"] {
        let renders = stokes_renders(&load("blend", &[("turn", turn)]), 256, 8);
        let degrees: Vec<[f64; 3]> = renders
            .iter()
            .map(|m| std::array::from_fn(|c| (m[3 + c].powi(2) + m[6 + c].powi(2)).sqrt() / m[c]))
            .collect();
        let (mean, se) = mean_and_standard_error(&degrees);
        for c in 0..3 {
            assert!(
                se[c] < 5e-3 && (mean[c] - expected).abs() < 4.0 * se[c] + 1e-4,
                "turned {turn}°, {}: degree of polarization {} ± {:.1e}, expected {expected}",
                CHANNELS[c],
                mean[c],
                se[c]
            );
            for r in &renders {
                assert!(r[9 + c].abs() <= 1e-6, "turned {turn}°: S3 {}", r[9 + c]);
            }
        }
    }
}
