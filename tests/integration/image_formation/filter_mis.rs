//! Filter MIS, the default reconstruction ([`prism_core::film::reconstruction`]): unbiased for
//! filters with and without negative lobes against the closed form of a filtered straight edge,
//! with honest per-pixel variances; and bit-identical across thread counts, crop windows,
//! passes and merged sample ranges.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};

use prism_core::film::{
    Film, Filter, GaussianFilter, Kernel, MitchellFilter, PixelSums, TentFilter,
};
use prism_core::integrator::{GuidedPathIntegrator, Integrator};
use prism_core::math::quadrature::simpson;
use prism_core::render::resume::InitialState;
use prism_core::render::{RenderOptions, StopRule, render};
use prism_core::scene::Scene;
use prism_mitsuba::load_scene;

/// An orthographic view of a plane emitting 1 (a constant spectrum, Y = 1) for x < 0 against a
/// constant sky of 0.25: the edge runs down the middle of the film, through the centre of
/// column 5 of 11, with the bright side on the left.
const EDGE_SCENE: &str = r#"<scene version="3.0.0">
    <default name="filter" value="tent"/>
    <default name="reconstruction" value="filter_mis"/>
    <default name="width" value="11"/>
    <integrator type="path"><integer name="max_depth" value="1"/></integrator>
    <sensor type="orthographic">
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="$width"/><integer name="height" value="4"/>
            <string name="reconstruction" value="$reconstruction"/>
            <rfilter type="$filter"/>
        </film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale x="50" y="50"/><translate x="-50"/></transform>
        <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
    </shape>
    <emitter type="constant"><spectrum name="radiance" value="0.25"/></emitter>
</scene>
"#;

fn edge_scene(defines: &[(&str, &str)]) -> Scene {
    // One directory per call: the tests run in parallel.
    static CALLS: AtomicU32 = AtomicU32::new(0);
    let call = CALLS.fetch_add(1, Ordering::Relaxed);
    let dir: PathBuf =
        std::env::temp_dir().join(format!("prism-filter-mis-{}-{call}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("edge.xml");
    std::fs::write(&path, EDGE_SCENE).unwrap();
    let defines: Vec<(String, String)> = defines
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let loaded = load_scene(&path, &defines);
    let _ = std::fs::remove_dir_all(&dir);
    loaded.unwrap_or_else(|e| panic!("{e}")).scene
}

/// The expected Y of column `column`: 0.25 + 0.75 F(5.5 − c), with c the column's centre and
/// F(t) = ∫_{−r}^{t} k / ∫ k (Simpson's rule on 4096 intervals).
fn edge_value(filter: Filter, column: u32) -> f64 {
    let r = f64::from(filter.radius());
    let integral = |to: f64| {
        simpson(
            |x| f64::from(filter.eval(x as f32)),
            -r,
            to.clamp(-r, r),
            4096,
        )
    };
    let t = 5.5 - (f64::from(column) + 0.5);
    0.25 + 0.75 * integral(t) / integral(r)
}

/// The filters of the test and their names in a scene.
fn filters() -> [(&'static str, Filter); 3] {
    [
        ("tent", Filter::Tent(TentFilter { radius: 1.0 })),
        ("gaussian", Filter::Gaussian(GaussianFilter { stddev: 0.5 })),
        (
            "mitchell",
            Filter::Mitchell(MitchellFilter {
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            }),
        ),
    ]
}

/// z-scores of the luminance of every pixel against the filtered edge, with each pixel's own
/// estimated variance.
fn edge_z_scores(filter_name: &str, filter: Filter, reconstruction: &str, seed: u64) -> Vec<f64> {
    let scene = edge_scene(&[("filter", filter_name), ("reconstruction", reconstruction)]);
    assert_eq!(scene.film.filter, filter);
    let film = render(&scene, &RenderOptions::fixed(1024, seed, None))
        .unwrap()
        .film;
    let mut z = Vec::new();
    for y in 0..4 {
        for x in 0..11 {
            let p = &film.pixels[film.index(x, y)];
            let sigma = p.variance_of_mean(1).sqrt();
            assert!(
                sigma > 0.0,
                "{filter_name} {reconstruction} ({x}, {y}): no variance"
            );
            z.push((p.mean()[1] - edge_value(filter, x)) / sigma);
        }
    }
    z
}

/// Both reconstructions are unbiased for the tent, the Gaussian and Mitchell–Netravali's cubic
/// (negative lobes): every pixel of the filtered edge is within 4.5 of its standard errors of
/// the closed form; and the standard errors are honest: over all pixels and two seeds the
/// z-scores have mean square 1 (within 0.5–1.7: neighbouring pixels share samples, so the 264
/// scores are not independent).
#[test]
fn a_filtered_edge_is_unbiased_with_honest_errors() {
    for reconstruction in ["filter_mis", "pixel"] {
        let mut squares = Vec::new();
        for (name, filter) in filters() {
            for seed in [3, 4] {
                let z = edge_z_scores(name, filter, reconstruction, seed);
                let worst = z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(
                    worst < 4.5,
                    "{name} {reconstruction} seed {seed}: |z| up to {worst}: {z:?}"
                );
                squares.extend(z.iter().map(|v| v * v));
            }
        }
        let mean_square = squares.iter().sum::<f64>() / squares.len() as f64;
        assert!(
            (0.5..1.7).contains(&mean_square),
            "{reconstruction}: mean z² {mean_square}"
        );
    }
}

/// `guided_path` keeps the one-pixel estimator under a film that shares samples (filter MIS
/// for the other integrators): its samples must be drawn from the filter, not within the
/// pixel's square as filter MIS draws them, or it would render the box-filtered edge. Every
/// pixel of the Gaussian-filtered edge within 4.5 standard errors of the closed form.
#[test]
fn guided_path_renders_the_filtered_edge() {
    let (name, filter) = ("gaussian", Filter::Gaussian(GaussianFilter { stddev: 0.5 }));
    let mut scene = edge_scene(&[("filter", name)]);
    assert!(scene.film.reconstruction.shares_samples(scene.film.filter));
    assert_eq!(scene.film.filter, filter);
    scene.integrator = Integrator::Guided(GuidedPathIntegrator {
        max_depth: 1,
        ..GuidedPathIntegrator::default()
    });
    let film = render(&scene, &RenderOptions::fixed(1024, 3, None))
        .unwrap()
        .film;
    for y in 0..4 {
        for x in 0..11 {
            let p = &film.pixels[film.index(x, y)];
            let z = (p.mean()[1] - edge_value(filter, x)) / p.variance_of_mean(1).sqrt();
            assert!(z.abs() < 4.5, "({x}, {y}): z = {z}");
        }
    }
}

/// Filter MIS is much less noisy than the one-pixel estimator across the edge, and no noisier
/// on its flat sides: the mean variance of the pixels' luminance, at equal samples. (Measured:
/// across the edge 0.51×, 0.15× and 0.07× for the tent, the Gaussian and Mitchell's cubic; on
/// the flat sides, the film's border columns, 0.75×, 0.55× and 0.003×: the one-pixel estimator's negative weights are noise
/// even where the image is constant.)
#[test]
fn filter_mis_is_quieter_than_one_pixel_estimates() {
    for (name, _) in filters() {
        let variance = |reconstruction| {
            let scene = edge_scene(&[("filter", name), ("reconstruction", reconstruction)]);
            let film = render(&scene, &RenderOptions::fixed(256, 9, None))
                .unwrap()
                .film;
            let mut columns = [0.0f64; 11];
            for y in 0..4 {
                for (x, c) in columns.iter_mut().enumerate() {
                    *c += film.pixels[film.index(x as u32, y)].variance_of_mean(1) / 4.0;
                }
            }
            columns
        };
        let (shared, pixel) = (variance("filter_mis"), variance("pixel"));
        let edge: f64 = (4..7).map(|x| shared[x] / pixel[x]).sum::<f64>() / 3.0;
        assert!(
            edge < 0.7,
            "{name}: variance at the edge {edge} of the one-pixel estimator's"
        );
        let flat: f64 = [0, 10].iter().map(|&x| shared[x] / pixel[x]).sum::<f64>() / 2.0;
        assert!(
            flat < 1.0,
            "{name}: variance on the flat sides {flat} of the one-pixel estimator's"
        );
    }
}

fn pixel_sums(film: &Film) -> Vec<PixelSums> {
    film.pixels.clone()
}

/// The same pixels, bit for bit, whatever the number of threads and the crop window, and when
/// the samples are taken in several passes.
#[test]
fn threads_crops_and_passes_do_not_change_a_pixel() {
    for (name, _) in filters() {
        let scene = edge_scene(&[("filter", name), ("width", "40")]);
        let one = render(&scene, &RenderOptions::fixed(24, 5, Some(1)))
            .unwrap()
            .film;
        let two = render(&scene, &RenderOptions::fixed(24, 5, Some(2)))
            .unwrap()
            .film;
        assert_eq!(pixel_sums(&one), pixel_sums(&two), "{name}: threads");
        assert_eq!(one.aovs, two.aovs);

        let mut cropped = edge_scene(&[("filter", name), ("width", "40")]);
        cropped.film.crop = prism_core::film::CropWindow {
            offset: glam::UVec2::new(17, 1),
            size: glam::UVec2::new(6, 2),
        };
        let crop = render(&cropped, &RenderOptions::fixed(24, 5, Some(2)))
            .unwrap()
            .film;
        for y in 0..2 {
            for x in 0..6 {
                assert_eq!(
                    crop.pixels[crop.index(x, y)],
                    one.pixels[one.index(17 + x, 1 + y)],
                    "{name}: crop pixel ({x}, {y})"
                );
            }
        }

        // Samples 0..24 in passes of 5, 11 and 8 (the control variate's halves are 0..12 and
        // 12..24), resumed each time from the sums before.
        let mut initial = None;
        let mut first = 0;
        for end in [5, 16, 24] {
            let mut options = RenderOptions::fixed(24, 5, Some(2));
            options.first_sample = first;
            options.stop = StopRule::samples(end);
            options.initial = initial.take();
            let film = render(&scene, &options).unwrap().film;
            initial = Some(InitialState::sums(film.pixels, film.aovs));
            first = end;
        }
        assert_eq!(initial.unwrap().pixels, one.pixels, "{name}: passes");
    }
}

/// Renders of disjoint sample ranges merge into exactly the render of all of them.
#[test]
fn merged_sample_ranges_are_the_whole_render() {
    let scene = edge_scene(&[("filter", "gaussian")]);
    let whole = render(&scene, &RenderOptions::fixed(16, 8, Some(2)))
        .unwrap()
        .film;
    let mut merged: Option<Film> = None;
    for range in [0..3, 3..10, 10..16] {
        let mut options = RenderOptions::fixed(16, 8, Some(2));
        options.first_sample = range.start;
        options.stop = StopRule::samples(range.end);
        let part = render(&scene, &options).unwrap().film;
        match &mut merged {
            None => merged = Some(part),
            Some(m) => {
                for (a, b) in m.pixels.iter_mut().zip(&part.pixels) {
                    a.merge(b);
                }
            }
        }
    }
    assert_eq!(merged.unwrap().pixels, whole.pixels);
}
