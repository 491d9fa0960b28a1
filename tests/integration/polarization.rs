//! Polarized rendering against Mitsuba 3 and against closed forms, on the scenes of
//! `tests/data/polarization/` (its README says how the references were made): an area light
//! seen through two linear polarizers 60° apart (Malus's law), through two aligned ones and a
//! quarter-wave plate at 45° (circular light), a glass plane seen near Brewster's angle beside
//! a gold sphere, and a `pplastic` plane at the same angle, all through the `stokes`
//! integrator.
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
    let per_render: Vec<[f64; 12]> = (0..renders)
        .map(|i| {
            let film = render_film(scene, spp, 11 + i, None);
            assert_eq!(film.aov_names, CHANNELS, "the stokes integrator's channels");
            std::array::from_fn(|c| {
                let values = film.aov(c);
                values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64
            })
        })
        .collect();
    let n = renders as f64;
    let mean: [f64; 12] = std::array::from_fn(|c| per_render.iter().map(|m| m[c]).sum::<f64>() / n);
    let standard_error = std::array::from_fn(|c| {
        let variance = per_render
            .iter()
            .map(|m| (m[c] - mean[c]).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        (variance / n).sqrt()
    });
    (mean, standard_error)
}

#[test]
fn stokes_vectors_match_mitsuba() {
    let mut failures = Vec::new();
    for r in REFERENCES {
        let scene = load(r.scene, r.defines);
        let (mean, se) = stokes_means(&scene, 1024, 8);
        for (c, channel) in CHANNELS.iter().enumerate() {
            let s0 = r.mean[c % 3].abs();
            let tolerance = 4.0
                * (se[c] * se[c] + r.standard_error[c] * r.standard_error[c]).sqrt()
                + 0.002 * s0;
            let row = format!(
                "{} {:?} {channel}: Prism {:.6} ± {:.1e}, Mitsuba {:.6} ± {:.1e}",
                r.scene, r.defines, mean[c], se[c], r.mean[c], r.standard_error[c]
            );
            if (mean[c] - r.mean[c]).abs() >= tolerance || mean[c].is_nan() {
                failures.push(format!("{row} (tolerance {tolerance:.1e})"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Malus's law through the whole renderer: S₀ through two polarizers θ apart is cos²θ times
/// S₀ through two aligned ones (the ratio does not depend on the colours), and the light that
/// passes is linearly polarized along the second polarizer: S₁ = cos 2θ' S₀, S₂ = sin 2θ' S₀
/// up to the frame's orientation, so S₁² + S₂² = S₀² and S₃ = 0.
#[test]
fn two_polarizers_follow_malus_law() {
    let aligned = stokes_means(&load("polarizers", &[("theta", "0")]), 64, 2).0;
    for degrees in [30.0f64, 60.0, 90.0] {
        let theta = degrees.to_string();
        let (mean, _) = stokes_means(&load("polarizers", &[("theta", &theta)]), 64, 2);
        let expected = degrees.to_radians().cos().powi(2);
        for c in 0..3 {
            let ratio = mean[c] / aligned[c];
            assert!(
                (ratio - expected).abs() < 2e-3,
                "{degrees}° {}: {ratio} against cos²θ = {expected}",
                CHANNELS[c]
            );
            let linear = (mean[3 + c].powi(2) + mean[6 + c].powi(2)).sqrt();
            assert!(
                (linear - mean[c]).abs() <= 2e-3 * aligned[c],
                "{degrees}°: not fully polarized"
            );
            assert!(mean[9 + c].abs() <= 1e-6, "{degrees}°: S3 {}", mean[9 + c]);
        }
    }
}
