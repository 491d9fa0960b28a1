//! Renders of new BSDFs, shapes, emitters, volumes and PLY face colours against Mitsuba 3's images of the same scenes
//! (`tests/references/README.md`): the image means of X, Y and Z agree within four standard
//! errors of their difference. Prism's standard error comes from its pixels' sample variances;
//! the reference's, rendered with the same estimator at 2048 spp, is taken as Prism's scaled
//! by √(spp/2048), unless the reference's estimator differs (`sunsky`: Mitsuba samples it
//! otherwise), when it is the one measured from two Mitsuba renders.

use std::path::Path;

use crate::common::scenes::{image_mean_and_standard_error, render_film};

/// Samples per pixel of the reference images.
const REFERENCE_SPP: u32 = 2048;

fn assert_matches_reference(name: &str) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references");
    assert_matches_reference_at(name, &dir.join(format!("{name}.xml")), None, 256);
}

/// Compares the render of the scene at `scene_path` at `spp` samples per pixel with
/// `tests/references/{name}.exr`, whose image means have the standard errors `reference_se`
/// (X, Y, Z) when they are given.
fn assert_matches_reference_at(
    name: &str,
    scene_path: &Path,
    reference_se: Option<[f64; 3]>,
    spp: u32,
) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references");
    let root =
        prism_mitsuba::reader::read_scene_file(scene_path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let loaded = prism_mitsuba::factory::build_scene(&root).unwrap_or_else(|e| panic!("{e}"));
    let film = render_film(&loaded.scene, spp, 11, None);
    let reference = prism_core::image::read_exr(&dir.join(format!("{name}.exr")))
        .unwrap_or_else(|e| panic!("{e}"));
    for (c, channel) in ["X", "Y", "Z"].into_iter().enumerate() {
        let values = reference
            .channel(channel)
            .unwrap_or_else(|| panic!("{name}.exr has no channel {channel}"));
        let reference_mean =
            values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64;
        let (mean, se) = image_mean_and_standard_error(&film, c);
        let reference_se = reference_se
            .map(|se| se[c])
            .unwrap_or(se * (f64::from(spp) / f64::from(REFERENCE_SPP)).sqrt());
        let tolerance = 4.0 * (se * se + reference_se * reference_se).sqrt();
        assert!(
            (mean - reference_mean).abs() < tolerance,
            "{name}: mean {channel} {mean} but Mitsuba's {reference_mean} (tolerance {tolerance})"
        );
        assert!(
            se < 2e-3 * mean,
            "{name}: standard error {se} too large to see a 1 % bias in {channel}"
        );
    }
}

#[test]
fn pplastic_matches_mitsuba() {
    assert_matches_reference("pplastic");
}

#[test]
fn principled_matches_mitsuba() {
    assert_matches_reference("principled");
}

#[test]
fn transmitting_principled_matches_mitsuba() {
    assert_matches_reference("principled_trans_env");
}

#[test]
fn principledthin_matches_mitsuba() {
    assert_matches_reference("thin_env");
}

#[test]
fn ellipsoids_match_mitsuba() {
    assert_matches_reference("ellipsoids");
}

#[test]
fn sdfgrid_with_smooth_normals_matches_mitsuba() {
    assert_matches_reference("sdfgrid_smooth");
}

#[test]
fn sdfgrid_with_analytic_normals_matches_mitsuba() {
    assert_matches_reference("sdfgrid_analytic");
}

#[test]
fn linearcurve_matches_mitsuba() {
    assert_matches_reference("linearcurve");
}

#[test]
fn bsplinecurve_matches_mitsuba() {
    assert_matches_reference("bsplinecurve");
}

/// `directionalarea` through `ptracer`: a tilted square beaming onto a diffuse floor (1024 spp,
/// for the edges of the beam's footprint, where the particles' landing is noisiest).
#[test]
fn directionalarea_matches_mitsuba() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references/directionalarea.xml");
    assert_matches_reference_at("directionalarea", &scene, None, 1024);
}

/// `sggx`'s extinction: an absorbing medium whose coefficient is scaled by the flakes'
/// projected area √(ωᵀSω) along each ray, for a skewed S.
#[test]
fn sggx_extinction_matches_mitsuba() {
    assert_matches_reference("sggx");
}

/// `perspective` with `principal_point_offset_x/y` (0.2, −0.15), as the Mitsuba Blender add-on
/// writes a lens shift: the shifted view's image mean is 0.68 times the unshifted one's
/// (1024 spp, for the image's edges within their pixels).
#[test]
fn principal_point_offset_matches_mitsuba() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references/principal_point.xml");
    assert_matches_reference_at("principal_point", &scene, None, 1024);
}

/// Three-channel `gridvolume`s: a colour albedo grid tiled by `wrap_mode` repeat over a
/// density grid, and a colour extinction grid read by its nearest voxels (1024 spp, for the
/// media's noise).
#[test]
fn colour_grids_match_mitsuba() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references/rgb_grid.xml");
    assert_matches_reference_at("rgb_grid", &scene, None, 1024);
}

/// A `homogeneous` medium whose albedo is a colour `gridvolume` tiled by `wrap_mode` repeat
/// (1024 spp, for the medium's noise).
#[test]
fn homogeneous_medium_with_an_albedo_grid_matches_mitsuba() {
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references/homogeneous_albedo_grid.xml");
    assert_matches_reference_at("homogeneous_albedo_grid", &scene, None, 1024);
}

#[test]
fn hair_matches_mitsuba() {
    assert_matches_reference("hair");
}

#[test]
fn hair_by_absorption_matches_mitsuba() {
    assert_matches_reference("hair_sigma_a");
}

#[test]
fn ply_face_colours_match_mitsuba() {
    assert_matches_reference("face_color");
}

/// `volume` textures in the form of Mitsuba's lego tutorial scene: a `principled` sphere whose
/// base colour and roughness are grids read at the surface point's world position, on a floor
/// whose reflectance is a `constvolume`.
#[test]
fn volume_textures_match_mitsuba() {
    assert_matches_reference("volume_texture");
}

/// Mitsuba 3.9.1 divides XYZ by 106.75026 (`MI_CIE_Y_NORMALIZATION`), where the integral of its
/// ȳ, and Prism's divisor, is 106.857028: a spectrum that is not D65-shaped comes out this much
/// brighter in its images (its D65 emission is normalised by the same number, so `<rgb>` lights
/// agree).
const MITSUBA_Y_NORMALIZATION_RATIO: f64 = 106.857_028_330_325 / 106.750_26;

/// The textured projector (`projector_slide.xml`): its texels are upsampled as reflectances,
/// without D65, so Mitsuba's image is brighter by [`MITSUBA_Y_NORMALIZATION_RATIO`] (Prism's
/// uncorrected means are 0.9989, 0.9988 and 0.9991 of Mitsuba's). Mitsuba's means are those of
/// two `scalar_spectral` renders of 4096 spp (seeds 7 and 8), their standard errors measured from
/// the two renders' per-pixel differences. The tolerance adds to four standard errors of the
/// difference 3 · 10⁻⁴ of the mean for the two renderers' RGB-to-spectrum tables (Prism's
/// corrected means are 0.99994, 0.99985 and 1.00011 of Mitsuba's).
#[test]
fn textured_projector_matches_mitsuba_up_to_its_normalization() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/references/projector_slide.xml");
    let root =
        prism_mitsuba::reader::read_scene_file(&scene, &[]).unwrap_or_else(|e| panic!("{e}"));
    let loaded = prism_mitsuba::factory::build_scene(&root).unwrap_or_else(|e| panic!("{e}"));
    let film = render_film(&loaded.scene, 1024, 11, None);
    let mitsuba = [
        (0.051_345_28, 3.45e-6),
        (0.050_834_68, 1.66e-6),
        (0.045_269_11, 1.03e-5),
    ];
    for (c, (reference, reference_se)) in mitsuba.into_iter().enumerate() {
        let (mean, se) = image_mean_and_standard_error(&film, c);
        let corrected = mean * MITSUBA_Y_NORMALIZATION_RATIO;
        let se = se * MITSUBA_Y_NORMALIZATION_RATIO;
        let tolerance = 4.0 * (se * se + reference_se * reference_se).sqrt() + 3e-4 * reference;
        assert!(
            (corrected - reference).abs() < tolerance,
            "channel {c}: {corrected} (Prism's mean {mean} times Mitsuba's normalization) but \
             Mitsuba's {reference} (tolerance {tolerance})"
        );
    }
}

/// `scenes/emitters/sunsky.xml`: sky and sun over a diffuse ground and sphere in a +y-up world.
/// Mitsuba's own samples of this emitter are noisier than Prism's (about 38 times the variance
/// per sample on the ground), so the reference's standard errors are measured: from the
/// per-pixel differences of its renders with seeds 7 and 8 (`tests/references/README.md`).
#[test]
fn sunsky_matches_mitsuba() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/emitters/sunsky.xml");
    assert_matches_reference_at("sunsky", &scene, Some([1.82e-4, 1.84e-4, 1.69e-4]), 256);
}
