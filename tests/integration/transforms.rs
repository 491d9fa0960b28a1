//! The `<transform>` operations that Mitsuba's versions read differently, against Mitsuba 3's
//! images of the same scenes (`tests/references/transforms/README.md`): a `<rotate>` about an
//! axis that is not of unit length (as given in a version 3 file, normalised in a 0.6 file), a
//! `<lookat>` whose `up` is neither of unit length nor perpendicular to the view, and a sheared
//! `<matrix>` with and without a projective last row. The image means of X, Y and Z agree within
//! four standard errors of their difference; each scene warns where, and only where, the two
//! Mitsubas differ.

use std::path::{Path, PathBuf};

use crate::common::scenes::{image_mean_and_standard_error, render_film};

/// Samples per pixel of the reference images.
const REFERENCE_SPP: u32 = 4096;

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references/transforms")
}

/// Renders `scene`.xml and compares its image means with `reference`.exr; returns the
/// warnings as `line:column: message`.
fn render_against_reference(scene: &str, reference: &str) -> Vec<String> {
    let loaded = prism_mitsuba::load_scene(&folder().join(format!("{scene}.xml")), &[])
        .unwrap_or_else(|e| panic!("{e}"));
    let spp = 1024;
    let film = render_film(&loaded.scene, spp, 11, None);
    let image = prism_core::image::read_exr(&folder().join(format!("{reference}.exr")))
        .unwrap_or_else(|e| panic!("{e}"));
    for (c, channel) in ["X", "Y", "Z"].into_iter().enumerate() {
        let values = image
            .channel(channel)
            .unwrap_or_else(|| panic!("{reference}.exr has no channel {channel}"));
        let reference_mean =
            values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64;
        let (mean, se) = image_mean_and_standard_error(&film, c);
        // Both renderers sample these scenes alike: the reference's standard error is Prism's
        // at its sample count.
        let reference_se = se * (f64::from(spp) / f64::from(REFERENCE_SPP)).sqrt();
        let tolerance = 4.0 * (se * se + reference_se * reference_se).sqrt();
        assert!(
            (mean - reference_mean).abs() < tolerance,
            "{scene}: mean {channel} {mean} but Mitsuba's {reference_mean} (tolerance {tolerance})"
        );
        assert!(
            se < 2e-3 * mean,
            "{scene}: standard error {se} too large to see a 1 % bias in {channel}"
        );
    }
    loaded
        .warnings
        .iter()
        .map(|w| format!("{}:{}: {}", w.location.line, w.location.column, w.message))
        .collect()
}

/// Mitsuba 3 rotates about (0, 1, 1) as given: the cube is stretched and sheared, and renders
/// 1.87 times as bright as about the unit axis (`rotate_unit`).
#[test]
fn a_rotation_about_a_long_axis_stretches_as_in_mitsuba_3() {
    let warnings = render_against_reference("rotate_emitter", "rotate_emitter");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("14:13: <rotate> has an axis of length 1.4142, not 1: Mitsuba 3"),
        "{warnings:?}"
    );
}

#[test]
fn a_rotation_about_a_unit_axis_warns_of_nothing() {
    let warnings = render_against_reference("rotate_unit", "rotate_unit");
    assert!(warnings.is_empty(), "{warnings:?}");
}

/// A lit diffuse cube, so that the shading of the stretched faces is compared too.
#[test]
fn a_lit_cube_rotated_about_a_long_axis_matches_mitsuba_3() {
    let warnings = render_against_reference("rotate_lit", "rotate_lit");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
}

/// The same rotation in a version 0.6.0 file is Mitsuba 0.6's, about the normalised axis.
#[test]
fn a_rotation_in_a_mitsuba_0_6_file_normalises_its_axis() {
    let warnings = render_against_reference("rotate_legacy", "rotate_unit");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("Mitsuba 0.6, this file's version, normalises it"),
        "{warnings:?}"
    );
}

#[test]
fn lookat_makes_any_up_vector_orthonormal() {
    let warnings = render_against_reference("lookat_up", "lookat_up");
    assert!(warnings.is_empty(), "{warnings:?}");
}

#[test]
fn a_sheared_matrix_is_used_as_given() {
    let warnings = render_against_reference("matrix_shear", "matrix_shear");
    assert!(warnings.is_empty(), "{warnings:?}");
}

/// Mitsuba 3 renders `matrix_projective` exactly as `matrix_shear`: it drops the last row.
#[test]
fn a_projective_last_row_is_dropped_with_a_warning() {
    let warnings = render_against_reference("matrix_projective", "matrix_shear");
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("12:13: <matrix> has the last row 0.3 0 0.2 1.5, not 0 0 0 1"),
        "{warnings:?}"
    );
}
