//! Depth parity with Mitsuba 3 where paths cross surfaces with null lobes
//! (docs/mitsuba-compatibility.md, "Depth and null interactions"): the scenes of
//! `tests/data/depth-parity/` (a sphere of fog behind a `null`, `thindielectric` or `mask`
//! boundary, a `thindielectric` sphere without fog, a `thindielectric` sphere of fog inside a
//! `null` one) rendered by `volpath` and `volpathmis` at `max_depth` 2 and 6 (and 64 behind
//! `thindielectric`), and the sphere without fog by `path` at 2, 3 and 6. The image means of X,
//! Y and Z agree with Mitsuba 3.9.1's (`tests/data/depth-parity/README.md` says how they were
//! made) within four standard errors of their difference; Prism's standard error is from its
//! pixels' sample variances, Mitsuba's from the per-pixel differences of its two renders.
//!
//! `path` is not compared on the `mask` scene: Mitsuba's drops the estimate of a sample whose
//! path made only null BSDF samples (docs/mitsuba-compatibility.md), and light sampled at the
//! mask before its pass is lost with it. On the nested spheres `path`, which ignores fog,
//! finds almost nothing at these depths.

use std::path::Path;

use crate::common::scenes::{image_mean_and_standard_error, render_film};

/// Mitsuba's image of one scene, integrator and depth: the means of X, Y and Z over the image
/// and their standard errors.
struct Reference {
    scene: &'static str,
    integrator: &'static str,
    max_depth: u32,
    mean: [f64; 3],
    standard_error: [f64; 3],
}

/// Mitsuba 3.9.1 `scalar_spectral`, the mean of two renders (seeds 7 and 8) of 1024 spp each
/// for `volpath` at `max_depth` 6 on `null`, `thindielectric`, `thindielectric_vacuum` and
/// `nested`, of 512 spp each for the other rows.
const REFERENCES: &[Reference] = &[
    Reference {
        scene: "null",
        integrator: "volpath",
        max_depth: 2,
        mean: [0.0133456, 0.0140436, 0.0152666],
        standard_error: [1.69e-05, 1.77e-05, 2.34e-05],
    },
    Reference {
        scene: "null",
        integrator: "volpath",
        max_depth: 6,
        mean: [0.0291488, 0.0306795, 0.0333455],
        standard_error: [2.33e-05, 2.44e-05, 3.22e-05],
    },
    Reference {
        scene: "null",
        integrator: "volpathmis",
        max_depth: 2,
        mean: [0.0133173, 0.0140177, 0.0152188],
        standard_error: [1.70e-05, 1.77e-05, 2.30e-05],
    },
    Reference {
        scene: "null",
        integrator: "volpathmis",
        max_depth: 6,
        mean: [0.0290891, 0.0306195, 0.0332552],
        standard_error: [3.15e-05, 3.28e-05, 4.35e-05],
    },
    Reference {
        scene: "thindielectric",
        integrator: "volpath",
        max_depth: 2,
        mean: [0.0134220, 0.0141256, 0.0153553],
        standard_error: [2.77e-05, 2.87e-05, 3.74e-05],
    },
    Reference {
        scene: "thindielectric",
        integrator: "volpath",
        max_depth: 6,
        mean: [0.0282350, 0.0297101, 0.0323265],
        standard_error: [2.72e-05, 2.84e-05, 3.72e-05],
    },
    Reference {
        scene: "thindielectric",
        integrator: "volpath",
        max_depth: 64,
        mean: [0.0329806, 0.0347201, 0.0376914],
        standard_error: [4.63e-05, 4.84e-05, 6.32e-05],
    },
    Reference {
        scene: "thindielectric",
        integrator: "volpathmis",
        max_depth: 2,
        mean: [0.0134470, 0.0141445, 0.0154150],
        standard_error: [2.93e-05, 3.06e-05, 3.87e-05],
    },
    Reference {
        scene: "thindielectric",
        integrator: "volpathmis",
        max_depth: 6,
        mean: [0.0282436, 0.0297241, 0.0323297],
        standard_error: [3.75e-05, 3.87e-05, 5.26e-05],
    },
    Reference {
        scene: "thindielectric",
        integrator: "volpathmis",
        max_depth: 64,
        mean: [0.0328925, 0.0346255, 0.0375888],
        standard_error: [4.33e-05, 4.56e-05, 5.70e-05],
    },
    Reference {
        scene: "thindielectric_vacuum",
        integrator: "path",
        max_depth: 2,
        mean: [0.0272368, 0.0286531, 0.0311874],
        standard_error: [3.03e-05, 3.15e-05, 4.09e-05],
    },
    Reference {
        scene: "thindielectric_vacuum",
        integrator: "path",
        max_depth: 3,
        mean: [0.0279618, 0.0294187, 0.0320278],
        standard_error: [3.17e-05, 3.31e-05, 4.21e-05],
    },
    Reference {
        scene: "thindielectric_vacuum",
        integrator: "path",
        max_depth: 6,
        mean: [0.0488285, 0.0513742, 0.0559415],
        standard_error: [4.74e-05, 4.96e-05, 6.18e-05],
    },
    Reference {
        scene: "thindielectric_vacuum",
        integrator: "volpath",
        max_depth: 2,
        mean: [0.0462666, 0.0486785, 0.0529901],
        standard_error: [3.09e-05, 3.22e-05, 4.28e-05],
    },
    Reference {
        scene: "thindielectric_vacuum",
        integrator: "volpath",
        max_depth: 6,
        mean: [0.0491968, 0.0517661, 0.0563231],
        standard_error: [2.46e-05, 2.59e-05, 3.26e-05],
    },
    Reference {
        scene: "thindielectric_vacuum",
        integrator: "volpathmis",
        max_depth: 2,
        mean: [0.0462317, 0.0486361, 0.0529640],
        standard_error: [3.20e-05, 3.31e-05, 4.37e-05],
    },
    Reference {
        scene: "thindielectric_vacuum",
        integrator: "volpathmis",
        max_depth: 6,
        mean: [0.0491791, 0.0517445, 0.0563075],
        standard_error: [3.77e-05, 3.93e-05, 5.10e-05],
    },
    Reference {
        scene: "nested",
        integrator: "volpath",
        max_depth: 2,
        mean: [0.0132644, 0.0139565, 0.0151809],
        standard_error: [1.76e-05, 1.83e-05, 2.38e-05],
    },
    Reference {
        scene: "nested",
        integrator: "volpath",
        max_depth: 6,
        mean: [0.0289926, 0.0305104, 0.0331587],
        standard_error: [2.43e-05, 2.53e-05, 3.27e-05],
    },
    Reference {
        scene: "nested",
        integrator: "volpath",
        max_depth: 64,
        mean: [0.0333395, 0.0350886, 0.0381130],
        standard_error: [4.36e-05, 4.58e-05, 5.70e-05],
    },
    Reference {
        scene: "nested",
        integrator: "volpathmis",
        max_depth: 2,
        mean: [0.0132836, 0.0139780, 0.0152097],
        standard_error: [1.79e-05, 1.87e-05, 2.46e-05],
    },
    Reference {
        scene: "nested",
        integrator: "volpathmis",
        max_depth: 6,
        mean: [0.0289573, 0.0304791, 0.0331052],
        standard_error: [3.29e-05, 3.41e-05, 4.51e-05],
    },
    Reference {
        scene: "nested",
        integrator: "volpathmis",
        max_depth: 64,
        mean: [0.0333084, 0.0350591, 0.0380855],
        standard_error: [3.98e-05, 4.17e-05, 5.29e-05],
    },
    Reference {
        scene: "mask",
        integrator: "volpath",
        max_depth: 2,
        mean: [0.0131590, 0.0136693, 0.0130686],
        standard_error: [1.27e-05, 1.31e-05, 1.66e-05],
    },
    Reference {
        scene: "mask",
        integrator: "volpath",
        max_depth: 6,
        mean: [0.0202200, 0.0210675, 0.0208196],
        standard_error: [2.16e-05, 2.23e-05, 2.82e-05],
    },
    Reference {
        scene: "mask",
        integrator: "volpathmis",
        max_depth: 2,
        mean: [0.0131363, 0.0136445, 0.0130499],
        standard_error: [1.33e-05, 1.36e-05, 1.76e-05],
    },
    Reference {
        scene: "mask",
        integrator: "volpathmis",
        max_depth: 6,
        mean: [0.0202620, 0.0211158, 0.0208253],
        standard_error: [2.05e-05, 2.13e-05, 2.67e-05],
    },
];

/// Renders every reference row of `scene` at `spp` samples per pixel and asserts each channel's
/// mean within four standard errors of the difference from Mitsuba's, Prism's standard error
/// small enough (below 0.25 % of the mean) to see a 1 % bias.
fn assert_depth_parity(scene: &str, spp: u32) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/depth-parity")
        .join(format!("{scene}.xml"));
    let rows: Vec<&Reference> = REFERENCES.iter().filter(|r| r.scene == scene).collect();
    assert!(!rows.is_empty(), "no reference for {scene}");
    let mut failures = Vec::new();
    for r in rows {
        let defines = [
            ("integrator".to_string(), r.integrator.to_string()),
            ("max_depth".to_string(), r.max_depth.to_string()),
        ];
        let root = prism_mitsuba::reader::read_scene_file(&path, &defines)
            .unwrap_or_else(|e| panic!("{e}"));
        let loaded = prism_mitsuba::factory::build_scene(&root).unwrap_or_else(|e| panic!("{e}"));
        let film = render_film(&loaded.scene, spp, 5, None);
        for (c, channel) in ["X", "Y", "Z"].into_iter().enumerate() {
            let (mean, se) = image_mean_and_standard_error(&film, c);
            let reference = r.mean[c];
            let tolerance = 4.0 * (se * se + r.standard_error[c] * r.standard_error[c]).sqrt();
            let row = format!(
                "{scene}, {} at max_depth {}: mean {channel} {mean:.6} against Mitsuba's \
                 {reference:.6} (ratio {:.4}",
                r.integrator,
                r.max_depth,
                mean / reference
            );
            if (mean - reference).abs() >= tolerance {
                failures.push(format!("{row}, tolerance {tolerance:.2e})"));
            }
            if se >= 0.0025 * mean {
                failures.push(format!("{row}): standard error {se:.2e} hides a 1 % bias"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn null_boundary_of_a_medium() {
    assert_depth_parity("null", 256);
}

/// The pane's reflections of the emitter are the noisiest part of these images.
#[test]
fn thindielectric_boundary_of_a_medium() {
    assert_depth_parity("thindielectric", 1024);
}

#[test]
fn thindielectric_without_a_medium() {
    assert_depth_parity("thindielectric_vacuum", 256);
}

#[test]
fn thindielectric_medium_inside_a_null_one() {
    assert_depth_parity("nested", 512);
}

#[test]
fn mask_boundary_of_a_medium() {
    assert_depth_parity("mask", 256);
}
