//! The lecture's estimator and its error: σ²/N convergence, the variance the film reports, and
//! the distribution ray tracer against the path tracer.

use std::path::Path;

use glam::UVec2;
use prism_core::film::Film;
use prism_core::film::stats::variance_of_mean;
use prism_core::integrator::{DistributionIntegrator, Integrator};
use prism_core::math::special::regularized_gamma_q;
use prism_core::scene::Scene;
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::load_scene;
use prism_mitsuba::reader::read_scene_str;

use crate::common::scenes::{disk_light_over_plane, pixel_mean_and_variance, render_film};

/// The standard deviation of a Monte Carlo estimate falls as σ/√N: on the disk-light scene
/// (exact per-pixel answers) the relative squared error of a pixel rendered with N samples has
/// expectation V/N (the estimator is unbiased and its samples independent), so N times it has
/// the same expectation at N = 1, 2, 4, …, 64. Its means over the pixels of four renders each
/// agree in a chi-square test with their standard errors.
#[test]
fn relative_mse_falls_as_one_over_n() {
    let setup = disk_light_over_plane(UVec2::new(16, 16));
    let points: Vec<(f64, f64)> = (0..7)
        .map(|k| {
            let spp = 1u32 << k;
            let scaled: Vec<f64> = (0..4)
                .flat_map(|seed| {
                    let film = render_film(&setup.scene, spp, 100 * k + seed, None);
                    setup
                        .exact
                        .iter()
                        .enumerate()
                        .map(|(i, e)| {
                            let error = pixel_mean_and_variance(&film, i, 1).0 - e;
                            f64::from(spp) * error * error / (e * e + 0.01)
                        })
                        .collect::<Vec<_>>()
                })
                .collect();
            let n = scaled.len() as f64;
            let mean = scaled.iter().sum::<f64>() / n;
            let variance = scaled.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, (variance / n).sqrt())
        })
        .collect();
    let weights: Vec<f64> = points.iter().map(|(_, se)| 1.0 / (se * se)).collect();
    let common = points
        .iter()
        .zip(&weights)
        .map(|((m, _), w)| m * w)
        .sum::<f64>()
        / weights.iter().sum::<f64>();
    let statistic: f64 = points
        .iter()
        .map(|(m, se)| ((m - common) / se).powi(2))
        .sum();
    let p_value = regularized_gamma_q((points.len() - 1) as f64 / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-3,
        "N · relative squared error is not constant in N (p = {p_value}): {points:?}"
    );
}

fn cornell_box(size: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    let defines = [
        ("resx".to_string(), size.to_string()),
        ("resy".to_string(), size.to_string()),
    ];
    load_scene(&path, &defines).unwrap().scene
}

/// The variance the film reports for each pixel's mean (the `variance.*` channels) predicts the
/// spread between two independent renders: E[(a − b)² − var_a − var_b] = 0. Over the pixels of
/// three pairs of renders of the disk-light scene, the mean of that difference is within 4
/// standard errors (from its own scatter) of 0.
#[test]
fn reported_variance_predicts_the_spread_between_independent_renders() {
    let scene = disk_light_over_plane(UVec2::new(48, 48)).scene;
    let mut excess = Vec::new();
    let (mut predicted, mut observed) = (0.0, 0.0);
    for pair in 0..3 {
        let a = render_film(&scene, 32, 2 * pair + 1, None);
        let b = render_film(&scene, 32, 2 * pair + 2, None);
        for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
            let variance = variance_of_mean(pa, 1) + variance_of_mean(pb, 1);
            let spread = (pa.mean()[1] - pb.mean()[1]).powi(2);
            predicted += variance;
            observed += spread;
            excess.push(spread - variance);
        }
    }
    let n = excess.len() as f64;
    let mean = excess.iter().sum::<f64>() / n;
    let se = (excess.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / ((n - 1.0) * n)).sqrt();
    assert!(
        mean.abs() < 4.0 * se,
        "observed − predicted variance per pixel: {mean} ± {se} (sums {observed} and {predicted})"
    );
}

/// Asserts that two films estimate the same image in channel `c` (0 = X, 1 = Y, 2 = Z): the
/// pixels' differences, standardised by their reported variances, pass a chi-square test at
/// significance 10⁻³, and the image means agree within 4 standard errors.
pub(super) fn assert_same_image(name: &str, a: &Film, b: &Film, c: usize) {
    let mut statistic = 0.0;
    let (mut mean_difference, mut variance_sum, mut pixels) = (0.0, 0.0, 0.0);
    for (p, d) in a.pixels.iter().zip(&b.pixels) {
        let variance = variance_of_mean(p, c) + variance_of_mean(d, c);
        let difference = p.mean()[c] - d.mean()[c];
        mean_difference += difference;
        if variance > 0.0 {
            statistic += difference * difference / variance;
            variance_sum += variance;
            pixels += 1.0;
        } else {
            assert_eq!(difference, 0.0, "{name}: a pixel without noise differs");
        }
    }
    let p_value = regularized_gamma_q(pixels / 2.0, statistic / 2.0);
    assert!(
        p_value > 1e-3,
        "{name}, channel {c}: chi-square {statistic} over {pixels} pixels: p = {p_value}"
    );
    let count = a.pixels.len() as f64;
    let se = variance_sum.sqrt() / count;
    assert!(
        (mean_difference / count).abs() < 4.0 * se,
        "{name}, channel {c}: mean differs by {} ± {se}",
        mean_difference / count
    );
}

/// The distribution ray tracer and the path tracer estimate the same image of the Cornell box.
#[test]
fn distribution_and_path_tracers_agree_on_the_cornell_box() {
    let mut scene = cornell_box(24);
    let path = render_film(&scene, 256, 3, None);
    scene.integrator = Integrator::from(DistributionIntegrator::default());
    let distrib = render_film(&scene, 64, 4, None);
    for c in 0..3 {
        assert_same_image("Cornell box", &path, &distrib, c);
    }
}

/// Behind dispersive glass both estimators follow each wavelength in its own direction: a thin
/// white light seen through a prism (Cauchy glass, n = 1.45 at 450 nm, 1.37 at 650 nm) spreads
/// into a spectrum, and the two images agree in X, Y and Z. (An estimator that sends all four
/// wavelengths along the hero's refraction sees the light white: 34 % of its pixels then lie
/// beyond |z| = 3 in Y.)
#[test]
fn distribution_and_path_tracers_agree_behind_dispersive_glass() {
    let prism = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dispersion/prism.obj");
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="perspective">
        <float name="fov" value="14"/>
        <transform name="to_world"><lookat origin="-2, 0.95, 0" target="0, 1.508, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
        <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="48"/><rfilter type="box"/></film>
    </sensor>
    <shape type="obj">
        <string name="filename" value="{}"/>
        <boolean name="face_normals" value="true"/>
        <bsdf type="dielectric">
            <spectrum type="cauchy" name="int_ior"><float name="a" value="1.3"/><float name="b" value="0.03"/></spectrum>
        </bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale x="0.3" y="0.02"/><rotate y="1" angle="-90"/><translate x="2" y="0.95"/></transform>
        <emitter type="area"><rgb name="radiance" value="10"/></emitter>
    </shape>
</scene>"#,
        prism.display()
    );
    let root = read_scene_str(&xml, Path::new("dispersion-test.xml"), &[]).unwrap();
    let mut scene = build_scene(&root).unwrap().scene;
    let path = render_film(&scene, 256, 1, None);
    scene.integrator = Integrator::from(DistributionIntegrator::default());
    let distrib = render_film(&scene, 256, 2, None);
    for c in 0..3 {
        assert_same_image("prism", &path, &distrib, c);
    }
}
