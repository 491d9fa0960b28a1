//! The particle tracer (`ptracer`): against the closed form of a disk light over a plane, against
//! the path tracer on the Cornell box and under every kind of light and camera, bit-identical
//! for any thread count, and its passes, resumed renders and merged sample ranges equal to one
//! render.

use std::path::Path;

use glam::UVec2;
use prism_core::film::Film;
use prism_core::integrator::{Integrator, ParticleTracer};
use prism_core::scene::Scene;

use super::convergence::assert_same_image;
use super::guarantees::{
    assert_bit_identical_for_any_thread_count, assert_resumed_and_merged_equal_one_render,
};
use crate::common::scenes::{
    disk_light_over_plane, pixel_mean_and_variance, render_film, scene_from_xml,
};

fn ptracer(max_depth: i32) -> Integrator {
    Integrator::from(ParticleTracer {
        max_depth,
        ..ParticleTracer::default()
    })
}

/// Direct light only (`max_depth` 2) from a disk light over a diffuse plane: each pixel's
/// estimate, standardised by the variance the film reports for it (by batch means over
/// sample indices), agrees with the pixel's exact value in a chi-square test at significance
/// 10⁻³, and the image's mean within 4 standard errors.
#[test]
fn ptracer_matches_the_disk_light_closed_form() {
    let mut setup = disk_light_over_plane(UVec2::new(24, 24));
    setup.scene.integrator = ptracer(2);
    let film = render_film(&setup.scene, 512, 5, None);
    setup.assert_matches(&film);
}

/// The variance the film reports, by batch means over sample indices, predicts the spread
/// between independent renders: E[(a − b)² − var_a − var_b] = 0. Over the pixels of three pairs
/// of renders of the disk-light scene, the mean of that difference is within 4 standard errors
/// (from its own scatter) of 0.
#[test]
fn ptracer_reported_variance_predicts_the_spread_between_renders() {
    let mut scene = disk_light_over_plane(UVec2::new(24, 24)).scene;
    scene.integrator = ptracer(2);
    let mut excess = Vec::new();
    for pair in 0..3 {
        let a = render_film(&scene, 64, 2 * pair + 1, None);
        let b = render_film(&scene, 64, 2 * pair + 2, None);
        for i in 0..a.pixels.len() {
            let (mean_a, variance_a) = pixel_mean_and_variance(&a, i, 1);
            let (mean_b, variance_b) = pixel_mean_and_variance(&b, i, 1);
            excess.push((mean_a - mean_b).powi(2) - variance_a - variance_b);
        }
    }
    let n = excess.len() as f64;
    let mean = excess.iter().sum::<f64>() / n;
    let se = (excess.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / ((n - 1.0) * n)).sqrt();
    assert!(
        mean.abs() < 4.0 * se,
        "observed − predicted variance per pixel: {mean} ± {se}"
    );
}

pub(super) fn cornell_box(size: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    let defines = [
        ("resx".to_string(), size.to_string()),
        ("resy".to_string(), size.to_string()),
    ];
    prism_mitsuba::load_scene(&path, &defines).unwrap().scene
}

/// The particle tracer and the path tracer estimate the same image of the Cornell box (its
/// luminaire seen directly included).
#[test]
fn ptracer_and_path_agree_on_the_cornell_box() {
    let mut scene = cornell_box(24);
    let path = render_film(&scene, 256, 3, None);
    scene.integrator = ptracer(-1);
    let particles = render_film(&scene, 1024, 4, None);
    for c in 0..3 {
        assert_same_image("Cornell box", &particles, &path, c);
    }
}

/// A small scene lit by `emitter` (XML), with a diffuse floor and back wall, a diffuse sphere
/// and `extra` shapes, seen by `sensor` (XML, without film or sampler).
pub(super) fn lit_scene(sensor: &str, emitter: &str, extra: &str) -> Scene {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/emitters");
    let xml = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    {sensor}
    <shape type="rectangle">
        <transform name="to_world"><scale value="2"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.5, 0.4"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/><translate y="1.5" z="1"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.4, 0.5, 0.6"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="-0.5" y="0.2" z="0.35"/><float name="radius" value="0.35"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf>
    </shape>
    {extra}
    {emitter}
</scene>"#
    );
    let scene = scene_from_xml(&xml, &folder.join("ptracer-test.xml").to_string_lossy());
    scene.unwrap()
}

pub(super) const PINHOLE: &str = r#"<sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world"><lookat origin="0, -3, 1.6" target="0, 0, 0.5" up="0, 0, 1"/></transform>
        <sampler type="independent"/>
        <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>"#;

/// Renders `scene` with the path tracer and, at twice the samples, the particle tracer, and
/// asserts the two images agree in X, Y and Z.
fn assert_ptracer_agrees_with_path(name: &str, mut scene: Scene, max_depth: i32, spp: u32) {
    if let Integrator::Path(path) = &mut scene.integrator {
        path.max_depth = max_depth;
    }
    let path = render_film(&scene, spp, 11, None);
    scene.integrator = ptracer(max_depth);
    let particles = render_film(&scene, 2 * spp, 12, None);
    assert!(
        particles.pixels.iter().any(|p| p.sum(1) > 0.0),
        "{name}: black"
    );
    for c in 0..3 {
        assert_same_image(name, &particles, &path, c);
    }
}

/// Every kind of light emits particles as the path tracer's light samples see it: each light's
/// `sample_emission` is unbiased.
#[test]
fn ptracer_and_path_agree_under_every_kind_of_light() {
    let lights = [
        (
            "area",
            r#"<shape type="sphere"><point name="center" x="0.6" y="0" z="1.3"/><float name="radius" value="0.2"/>
                <emitter type="area"><rgb name="radiance" value="8, 6, 4"/></emitter></shape>"#,
        ),
        (
            "textured area",
            r#"<shape type="rectangle"><transform name="to_world"><scale x="0.5" y="0.4"/><rotate x="1" angle="180"/><translate z="1.8"/></transform>
                <emitter type="area"><texture type="bitmap" name="radiance"><string name="filename" value="emit.png"/><string name="filter_type" value="nearest"/></texture></emitter></shape>"#,
        ),
        (
            "point",
            r#"<emitter type="point"><point name="position" x="0.5" y="-0.3" z="1.5"/><rgb name="intensity" value="3, 2, 1"/></emitter>"#,
        ),
        (
            "spot",
            r#"<emitter type="spot"><transform name="to_world"><lookat origin="0.5, -0.5, 1.8" target="0, 0.2, 0"/></transform>
                <rgb name="intensity" value="6"/><float name="cutoff_angle" value="35"/><float name="beam_width" value="20"/></emitter>"#,
        ),
        (
            "projector",
            r#"<emitter type="projector"><texture type="bitmap" name="irradiance"><string name="filename" value="slide.png"/><string name="filter_type" value="nearest"/></texture>
                <float name="scale" value="1.5"/><float name="fov" value="50"/>
                <transform name="to_world"><lookat origin="0.3, -0.8, 2" target="0, 0.3, 0" up="0, 1, 0"/></transform></emitter>"#,
        ),
        (
            "directional",
            r#"<emitter type="directional"><vector name="direction" x="0.3" y="0.5" z="-1"/><rgb name="irradiance" value="2"/></emitter>"#,
        ),
        (
            "constant",
            r#"<emitter type="constant"><rgb name="radiance" value="0.5, 0.6, 0.8"/></emitter>"#,
        ),
        (
            "envmap",
            r#"<emitter type="envmap"><string name="filename" value="emit.png"/></emitter>"#,
        ),
    ];
    for (name, emitter) in lights {
        assert_ptracer_agrees_with_path(name, lit_scene(PINHOLE, emitter, ""), -1, 512);
    }
}

/// Through rough glass (the adjoint BSDF's η² on sampled refractions, and connections across it
/// evaluated from the camera's side) and off a diffuse sphere meshed coarsely with smooth
/// vertex normals (the adjoint's shading-normal factor), the two estimators agree. (Smooth glass
/// or mirrors in view are no test: the particle tracer cannot connect through them, as
/// Mitsuba's cannot, and leaves black what the camera sees in them.)
#[test]
fn ptracer_and_path_agree_through_glass_and_shading_normals() {
    let light = r#"<shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle="180"/><translate x="0.4" z="1.8"/></transform>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>"#;
    let glass = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.7" z="0.5"/><float name="radius" value="0.45"/>
            <bsdf type="roughdielectric"><float name="alpha" value="0.2"/><float name="int_ior" value="1.5"/></bsdf></shape>"#;
    assert_ptracer_agrees_with_path("glass", lit_scene(PINHOLE, light, glass), 8, 2048);
    let folder = std::env::temp_dir().join(format!("prism-ptracer-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    let mesh = folder.join("coarse-sphere.obj");
    std::fs::write(&mesh, coarse_sphere_obj(6, 4)).unwrap();
    let smooth = format!(
        r#"<shape type="obj"><string name="filename" value="{}"/>
            <transform name="to_world"><scale value="0.5"/><translate x="0.3" y="-0.6" z="0.5"/></transform>
            <bsdf type="diffuse"/></shape>"#,
        mesh.display()
    );
    let scene = lit_scene(PINHOLE, light, &smooth);
    std::fs::remove_dir_all(&folder).ok();
    assert_ptracer_agrees_with_path("shading normals", scene, 4, 1024);
}

/// A unit sphere of `segments` × `rings` quads (the poles' as triangles) whose vertex normals
/// are the smooth sphere's, far from its coarse faces' normals.
pub(super) fn coarse_sphere_obj(segments: u32, rings: u32) -> String {
    let mut obj = String::new();
    let index = |ring: u32, segment: u32| 1 + ring * segments + segment % segments;
    for ring in 0..=rings {
        let theta = std::f64::consts::PI * f64::from(ring) / f64::from(rings);
        for segment in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * f64::from(segment) / f64::from(segments);
            let p = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            obj += &format!(
                "v {} {} {}\nvn {} {} {}\n",
                p[0], p[1], p[2], p[0], p[1], p[2]
            );
        }
    }
    for ring in 0..rings {
        for segment in 0..segments {
            let (a, b) = (index(ring, segment), index(ring, segment + 1));
            let (c, d) = (index(ring + 1, segment + 1), index(ring + 1, segment));
            obj += &format!("f {a}//{a} {d}//{d} {c}//{c}\nf {a}//{a} {c}//{c} {b}//{b}\n");
        }
    }
    obj
}

/// Behind rough glass whose index varies with wavelength (where both estimators keep only the
/// hero wavelength from the glass on) the two agree in X, Y and Z. The dispersion of rough
/// glass is too blurred for this to tell the hero-only estimate from one that bends all four
/// wavelengths alike; it checks that the estimate keeps its scale across the switch.
#[test]
fn ptracer_and_path_agree_behind_dispersive_rough_glass() {
    let light = r#"<shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle="180"/><translate x="0.4" z="1.8"/></transform>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>"#;
    let glass = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.7" z="0.5"/><float name="radius" value="0.45"/>
            <bsdf type="roughdielectric"><float name="alpha" value="0.2"/>
                <spectrum type="cauchy" name="int_ior"><float name="a" value="1.3"/><float name="b" value="0.03"/></spectrum></bsdf></shape>"#;
    assert_ptracer_agrees_with_path(
        "dispersive glass",
        lit_scene(PINHOLE, light, glass),
        8,
        4096,
    );
}

/// With `hide_emitters` neither estimator shows the light the camera sees, and they agree.
#[test]
fn ptracer_and_path_agree_with_hidden_emitters() {
    let light = r#"<shape type="sphere"><point name="center" x="0.6" y="0" z="1.3"/><float name="radius" value="0.2"/>
                <emitter type="area"><rgb name="radiance" value="8, 6, 4"/></emitter></shape>"#;
    let mut scene = lit_scene(PINHOLE, light, "");
    let shown = render_film(&scene, 64, 1, None);
    let Integrator::Path(path) = &mut scene.integrator else {
        unreachable!("the scene's integrator is path");
    };
    path.hide_emitters = true;
    let path = render_film(&scene, 512, 11, None);
    let brightest = |film: &Film| film.pixels.iter().map(|p| p.mean()[1]).fold(0.0, f64::max);
    assert!(
        brightest(&path) < 0.5 * brightest(&shown),
        "the light is not in view"
    );
    scene.integrator = Integrator::from(ParticleTracer {
        hide_emitters: true,
        ..ParticleTracer::default()
    });
    let particles = render_film(&scene, 1024, 12, None);
    for c in 0..3 {
        assert_same_image("hidden emitters", &particles, &path, c);
    }
}

/// Thin-lens and orthographic cameras receive the particles as they trace camera rays.
#[test]
fn ptracer_and_path_agree_through_a_lens_and_an_orthographic_camera() {
    let light = r#"<emitter type="point"><point name="position" x="0.5" y="-0.3" z="1.5"/><rgb name="intensity" value="3"/></emitter>"#;
    let thinlens = r#"<sensor type="thinlens">
        <float name="fov" value="60"/><float name="aperture_radius" value="0.15"/><float name="focus_distance" value="2"/>
        <transform name="to_world"><lookat origin="0, -3, 1.6" target="0, 0, 0.5" up="0, 0, 1"/></transform>
        <sampler type="independent"/>
        <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>"#;
    assert_ptracer_agrees_with_path("thin lens", lit_scene(thinlens, light, ""), -1, 512);
    let orthographic = r#"<sensor type="orthographic">
        <transform name="to_world"><lookat origin="0, -3, 1.6" target="0, 0, 0.5" up="0, 0, 1"/><scale value="1.3"/></transform>
        <sampler type="independent"/>
        <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="16"/><rfilter type="tent"/></film>
    </sensor>"#;
    assert_ptracer_agrees_with_path("orthographic", lit_scene(orthographic, light, ""), -1, 512);
}

/// A Gaussian-filtered film through a cropped window: the splats spread over the pixels as
/// camera samples' filter weights do.
#[test]
fn ptracer_and_path_agree_under_a_wide_filter_in_a_crop_window() {
    let sensor = r#"<sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world"><lookat origin="0, -3, 1.6" target="0, 0, 0.5" up="0, 0, 1"/></transform>
        <sampler type="independent"/>
        <film type="hdrfilm"><integer name="width" value="28"/><integer name="height" value="24"/>
            <integer name="crop_offset_x" value="4"/><integer name="crop_offset_y" value="6"/>
            <integer name="crop_width" value="20"/><integer name="crop_height" value="14"/>
            <rfilter type="gaussian"/></film>
    </sensor>"#;
    let light = r#"<shape type="sphere"><point name="center" x="0.6" y="0" z="1.3"/><float name="radius" value="0.2"/>
                <emitter type="area"><rgb name="radiance" value="8, 6, 4"/></emitter></shape>"#;
    assert_ptracer_agrees_with_path("gaussian, cropped", lit_scene(sensor, light, ""), -1, 512);
}

fn small_scene() -> Scene {
    let mut scene = cornell_box(13);
    scene.integrator = ptracer(-1);
    scene
}

/// One and two threads give the same film to the last bit (the splats' sums are exact), and
/// another seed another film.
#[test]
fn ptracer_is_bit_identical_for_any_thread_count() {
    assert_bit_identical_for_any_thread_count(&small_scene(), 6);
}

/// A render continued pass by pass from its state (as `--resume` does), and the renders of
/// disjoint sample ranges merged (as `prism merge` does), equal one render of all the samples.
#[test]
fn ptracer_resumed_and_merged_renders_equal_one_render() {
    assert_resumed_and_merged_equal_one_render(&small_scene(), &[2, 7, 9]);
}

/// `samples_per_pass` bounds the passes without changing the image.
#[test]
fn samples_per_pass_leaves_the_image_unchanged() {
    let mut scene = small_scene();
    let whole = render_film(&scene, 5, 3, Some(2));
    scene.integrator = Integrator::from(ParticleTracer {
        samples_per_pass: Some(2),
        ..ParticleTracer::default()
    });
    assert_eq!(render_film(&scene, 5, 3, Some(2)).pixels, whole.pixels);
}
