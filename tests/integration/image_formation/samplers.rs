//! The `ldsampler` and `orthogonal` samplers: the structure that defines them (the (0, 2)-net
//! of the low-discrepancy points, the orthogonal arrays' stratification of every pair or
//! triple of dimensions), chi-square tests of the uniformity of their points, an unbiased
//! estimate of an integral with a closed form, and the scene reader's top-level `<sampler>`
//! referenced by id.

use std::path::Path;

use glam::UVec2;
use prism_core::sampling::chi2::{Cells, assert_passes, chi2_rectangle};
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::sampler::{Sampler, SamplerKind};
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::reader::read_scene_str;

const SAMPLES: usize = 1_000_000;

const LOW_DISCREPANCY: SamplerKind = SamplerKind::LowDiscrepancy;
const ORTHOGONAL: SamplerKind = SamplerKind::Orthogonal {
    strength: 2,
    jitter: true,
};
const ORTHOGONAL_3: SamplerKind = SamplerKind::Orthogonal {
    strength: 3,
    jitter: true,
};

/// The first `dimensions` numbers of every sample of `pixel`: the camera sample's six, then
/// further `next_1d`s.
fn pixel_samples(
    kind: SamplerKind,
    requested: u32,
    pixel: UVec2,
    dimensions: usize,
) -> Vec<Vec<f32>> {
    let mut sampler = Sampler::new(kind, requested, 11);
    (0..sampler.sample_count())
        .map(|i| {
            sampler.start_pixel_sample(pixel, i);
            let c = sampler.camera_sample();
            let mut v = vec![c.wavelength, c.time, c.film.x, c.film.y, c.lens.x, c.lens.y];
            while v.len() < dimensions {
                v.push(sampler.next_1d());
            }
            v
        })
        .collect()
}

/// Asserts that the points' coordinates `dims` put exactly one point in each of the
/// `cells[0] × cells[1] × …` cells of the unit cube.
fn assert_one_per_cell(points: &[Vec<f32>], dims: &[usize], cells: &[u32], what: &str) {
    let total: u32 = cells.iter().product();
    let mut counts = vec![0u32; total as usize];
    for p in points {
        let mut index = 0u32;
        for (&d, &c) in dims.iter().zip(cells) {
            assert!((0.0..1.0).contains(&p[d]), "{what}: {}", p[d]);
            index = index * c + ((p[d] * c as f32) as u32).min(c - 1);
        }
        counts[index as usize] += 1;
    }
    assert!(
        counts.iter().all(|&c| c == 1),
        "{what}: dims {dims:?} cells {cells:?}: {counts:?}"
    );
}

#[test]
fn sample_counts_are_rounded_as_mitsuba_does() {
    for (requested, expected) in [(1, 4), (4, 4), (5, 16), (16, 16), (17, 64), (100, 256)] {
        assert_eq!(
            LOW_DISCREPANCY.sample_count(requested),
            expected,
            "ldsampler {requested}"
        );
    }
    for (requested, expected) in [(1, 4), (4, 4), (5, 9), (10, 25), (26, 49), (64, 121)] {
        assert_eq!(
            ORTHOGONAL.sample_count(requested),
            expected,
            "orthogonal {requested}"
        );
    }
    // Strength 3 over a prime p ≥ 3: 27, then 125.
    assert_eq!(ORTHOGONAL_3.sample_count(8), 27);
    assert_eq!(ORTHOGONAL_3.sample_count(28), 125);
}

/// The low-discrepancy points: every 1-D dimension has one point in each of N strata, and every
/// 2-D dimension is a (0, 2)-net: one point in each elementary interval 2^-a × 2^-b,
/// a + b = log₂ N.
#[test]
fn low_discrepancy_points_form_nets() {
    for n in [4u32, 16, 64, 256] {
        for pixel in [UVec2::new(0, 0), UVec2::new(91, 7)] {
            let points = pixel_samples(LOW_DISCREPANCY, n, pixel, 6);
            for d in [0, 1] {
                assert_one_per_cell(&points, &[d], &[n], "ldsampler 1-D");
            }
            let m = n.trailing_zeros();
            for (x, y) in [(2, 3), (4, 5)] {
                for a in 0..=m {
                    assert_one_per_cell(&points, &[x, y], &[1 << a, 1 << (m - a)], "ldsampler 2-D");
                }
            }
        }
    }
}

/// Orthogonal arrays of strength 2 over p levels: every dimension is stratified into N = p²
/// strata, and each pair among the first p + 1 dimensions into the p × p grid. Strength 3:
/// each triple among the first p dimensions into the p³ grid, each dimension into N strata.
#[test]
fn orthogonal_arrays_stratify_every_pair_and_triple() {
    for (p, jitter) in [(3u32, true), (5, true), (7, false)] {
        let kind = SamplerKind::Orthogonal {
            strength: 2,
            jitter,
        };
        let points = pixel_samples(kind, p * p, UVec2::new(4, 9), (p + 1) as usize);
        assert_eq!(points.len(), (p * p) as usize);
        for j in 0..=p as usize {
            assert_one_per_cell(&points, &[j], &[p * p], "orthogonal 1-D");
            for k in j + 1..=p as usize {
                assert_one_per_cell(&points, &[j, k], &[p, p], "orthogonal pair");
            }
        }
    }
    for p in [3u32, 5] {
        let points = pixel_samples(ORTHOGONAL_3, p * p * p, UVec2::new(2, 2), p as usize);
        assert_eq!(points.len(), (p * p * p) as usize);
        for j in 0..p as usize {
            assert_one_per_cell(&points, &[j], &[p * p * p], "strength 3, 1-D");
            for k in j + 1..p as usize {
                for l in k + 1..p as usize {
                    assert_one_per_cell(&points, &[j, k, l], &[p, p, p], "strength 3 triple");
                }
            }
        }
    }
}

/// A point of a random sample of a random pixel: its coordinates `x` and `y`.
fn random_point(
    kind: SamplerKind,
    requested: u32,
    x: usize,
    y: usize,
    rng: &mut Pcg32,
) -> (f64, f64) {
    let mut sampler = Sampler::new(kind, requested, 3);
    let pixel = UVec2::new(rng.next_bounded(1 << 16), rng.next_bounded(1 << 16));
    sampler.start_pixel_sample(pixel, rng.next_bounded(sampler.sample_count()));
    let c = sampler.camera_sample();
    let mut v = vec![c.wavelength, c.time, c.film.x, c.film.y, c.lens.x, c.lens.y];
    while v.len() <= x.max(y) {
        v.push(sampler.next_1d());
    }
    (f64::from(v[x]), f64::from(v[y]))
}

/// Each point, of a random sample of a random pixel, is uniform on the unit square: 10⁶
/// points on 40 × 40 cells for the film dimensions and for two later ones.
#[test]
fn points_are_uniform() {
    let cases = [
        ("ldsampler film", LOW_DISCREPANCY, 64, 2, 3),
        ("ldsampler dimensions 8, 9", LOW_DISCREPANCY, 16, 8, 9),
        ("orthogonal film", ORTHOGONAL, 49, 2, 3),
        ("orthogonal dimensions 7, 10", ORTHOGONAL, 25, 7, 10),
        ("orthogonal strength 3, film", ORTHOGONAL_3, 27, 2, 3),
        (
            "orthogonal strength 3, dimensions 1, 9",
            ORTHOGONAL_3,
            125,
            1,
            9,
        ),
    ];
    for (name, kind, requested, x, y) in cases {
        let outcome = chi2_rectangle(
            SAMPLES,
            Cells {
                x: (0.0, 1.0),
                y: (0.0, 1.0),
                nx: 40,
                ny: 40,
            },
            17,
            |rng| Some(random_point(kind, requested, x, y, rng)),
            |_, _| 1.0,
        )
        .unwrap();
        assert_passes(name, &outcome, cases.len());
    }
}

/// Each pixel's mean of f(x, y, z, w) = x² + 3 y z w over its N samples (film, then two later
/// dimensions) is an unbiased estimate of ∫ f = 1/3 + 3/8: over 4096 pixels the mean of the
/// pixel means lies within 4 standard errors (from their spread) of it.
#[test]
fn pixel_estimates_are_unbiased() {
    let exact = 1.0 / 3.0 + 3.0 / 8.0;
    for (kind, requested) in [(LOW_DISCREPANCY, 16), (ORTHOGONAL, 25), (ORTHOGONAL_3, 27)] {
        let mut sampler = Sampler::new(kind, requested, 5);
        let n = sampler.sample_count();
        let pixels = 4096u32;
        let means: Vec<f64> = (0..pixels)
            .map(|p| {
                let pixel = UVec2::new(p % 64, p / 64);
                (0..n)
                    .map(|i| {
                        sampler.start_pixel_sample(pixel, i);
                        let c = sampler.camera_sample();
                        let (z, w) = (sampler.next_1d(), sampler.next_1d());
                        let (x, y) = (f64::from(c.film.x), f64::from(c.film.y));
                        x * x + 3.0 * y * f64::from(z) * f64::from(w)
                    })
                    .sum::<f64>()
                    / f64::from(n)
            })
            .collect();
        let mean = means.iter().sum::<f64>() / f64::from(pixels);
        let variance =
            means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / f64::from(pixels - 1);
        let standard_error = (variance / f64::from(pixels)).sqrt();
        assert!(
            (mean - exact).abs() < 4.0 * standard_error,
            "{kind:?}: {mean} vs {exact} (standard error {standard_error})"
        );
    }
}

/// A `<sampler>` declared at the top level with an id is the sensor's when it references it;
/// both Mitsuba 3's and 0.6's `ldsampler` read.
#[test]
fn a_top_level_sampler_is_referenced_by_id() {
    for (version, sampler, expected, spp) in [
        (
            "3.0.0",
            r#"<sampler type="orthogonal" id="s"><integer name="sample_count" value="10"/><integer name="strength" value="2"/><boolean name="jitter" value="false"/></sampler>"#,
            SamplerKind::Orthogonal {
                strength: 2,
                jitter: false,
            },
            10,
        ),
        (
            "0.6.0",
            r#"<sampler type="ldsampler" id="s"><integer name="sampleCount" value="16"/></sampler>"#,
            SamplerKind::LowDiscrepancy,
            16,
        ),
    ] {
        let text = format!(
            r#"<scene version="{version}">
    {sampler}
    <sensor type="perspective"><ref id="s"/>
        <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film>
    </sensor>
</scene>"#
        );
        let root = read_scene_str(&text, &Path::new(".").join("scene.xml"), &[]).unwrap();
        let scene = build_scene(&root).unwrap().scene;
        assert_eq!(scene.sampler.kind, expected);
        assert_eq!(scene.sampler.samples_per_pixel, spp);
    }
    // A top-level sampler is checked even when no sensor uses it.
    let text = r#"<scene version="3.0.0">
    <sampler type="orthogonal" id="s"><integer name="strength" value="9"/></sampler>
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
</scene>"#;
    let root = read_scene_str(text, &Path::new(".").join("scene.xml"), &[]).unwrap();
    let err = build_scene(&root).err().expect("strength 9 is an error");
    assert!(err.to_string().contains("strength"), "{err}");
}
