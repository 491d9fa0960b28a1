//! Bidirectional path tracing (`bdpt`): against closed forms (a furnace, a disk light over a
//! plane), against the path tracer on the Cornell box, under glossy, glass and smooth-shaded
//! surfaces and a point light and with each of its switches, bit-identical for any thread count,
//! its resumed and merged renders equal to one render, and its parameters checked when read.
//! The weights of its strategies summing to one is a unit test of
//! `prism_core::integrator::bdpt::weights`.

use glam::UVec2;
use prism_core::integrator::{BdptIntegrator, Integrator, PathIntegrator};
use prism_core::scene::Scene;

use super::closed_form::{furnace_scene, inner_sphere};
use super::convergence::assert_same_image;
use super::guarantees::{
    assert_bit_identical_for_any_thread_count, assert_resumed_and_merged_equal_one_render,
};
use super::ptracer::{PINHOLE, coarse_sphere_obj, cornell_box, lit_scene};
use crate::common::scenes::{
    assert_mean_luminance, disk_light_over_plane, render_film, scene_from_xml,
};

fn bdpt(max_depth: i32) -> Integrator {
    Integrator::from(BdptIntegrator {
        max_depth,
        ..BdptIntegrator::default()
    })
}

/// A closed sphere whose inside has reflectance 0.5 and emits 1: the radiance everywhere is
/// 1 / (1 − 0.5) = 2, reached through every strategy and path length.
#[test]
fn bdpt_sphere_furnace_gives_le_over_one_minus_rho() {
    let scene = furnace_scene(inner_sphere(), 0.5, 1.0, bdpt(-1));
    let film = render_film(&scene, 512, 3, None);
    assert_mean_luminance("bdpt sphere furnace", &film, 2.0);
}

/// Direct light only (`max_depth` 2) from a disk light over a diffuse plane: each pixel, by the
/// variance the film reports for it, agrees with its exact value in a chi-square test at
/// significance 10⁻³, and the image's mean within 4 standard errors.
#[test]
fn bdpt_matches_the_disk_light_closed_form() {
    let mut setup = disk_light_over_plane(UVec2::new(16, 16));
    setup.scene.integrator = bdpt(2);
    let film = render_film(&setup.scene, 256, 5, None);
    setup.assert_matches(&film);
}

/// Bidirectional and path tracing estimate the same image of the Cornell box, its luminaire
/// seen directly included, per channel.
#[test]
fn bdpt_and_path_agree_on_the_cornell_box() {
    let mut scene = cornell_box(16);
    let path = render_film(&scene, 512, 3, None);
    scene.integrator = bdpt(-1);
    let bidirectional = render_film(&scene, 128, 4, None);
    for c in 0..3 {
        assert_same_image("Cornell box", &bidirectional, &path, c);
    }
}

/// Renders `scene` with the path tracer and with `integrator` (bdpt) at `spp` samples each, and
/// asserts the two images agree in X, Y and Z.
fn assert_agrees_with_path(name: &str, mut scene: Scene, integrator: BdptIntegrator, spp: u32) {
    scene.integrator = Integrator::from(PathIntegrator {
        max_depth: integrator.max_depth,
        hide_emitters: integrator.hide_emitters,
        ..PathIntegrator::default()
    });
    let path = render_film(&scene, spp, 11, None);
    scene.integrator = Integrator::from(integrator);
    let bidirectional = render_film(&scene, spp, 12, None);
    assert!(
        bidirectional.pixels.iter().any(|p| p.sum(1) > 0.0),
        "{name}: black"
    );
    for c in 0..3 {
        assert_same_image(name, &bidirectional, &path, c);
    }
}

const SPHERE_LIGHT: &str = r#"<shape type="sphere"><point name="center" x="0.6" y="0" z="1.3"/><float name="radius" value="0.2"/>
                <emitter type="area"><rgb name="radiance" value="8, 6, 4"/></emitter></shape>"#;

const RECTANGLE_LIGHT: &str = r#"<shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle="180"/><translate x="0.4" z="1.8"/></transform>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>"#;

/// Glossy surfaces (a rough conductor and rough plastic), where connections at glossy vertices
/// carry most of the weight, and a point light (a delta light: no strategy s = 0).
#[test]
fn bdpt_and_path_agree_on_glossy_surfaces_and_under_a_point_light() {
    let glossy = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.6" z="0.45"/><float name="radius" value="0.4"/>
            <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.15"/></bsdf></shape>
        <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="-60"/><translate x="-0.8" y="0.2" z="0.5"/></transform>
            <bsdf type="roughplastic"><float name="alpha" value="0.1"/><rgb name="diffuse_reflectance" value="0.2, 0.4, 0.6"/></bsdf></shape>"#;
    assert_agrees_with_path(
        "glossy",
        lit_scene(PINHOLE, SPHERE_LIGHT, glossy),
        BdptIntegrator::default(),
        512,
    );
    let point = r#"<emitter type="point"><point name="position" x="0.5" y="-0.3" z="1.5"/><rgb name="intensity" value="3, 2, 1"/></emitter>"#;
    assert_agrees_with_path(
        "point light",
        lit_scene(PINHOLE, point, glossy),
        BdptIntegrator::default(),
        256,
    );
}

/// Through smooth and rough glass (delta vertices, refraction's η² on the light side) and off a
/// coarse sphere with smooth vertex normals (the adjoint's shading-normal factor).
#[test]
fn bdpt_and_path_agree_through_glass_and_shading_normals() {
    let glass = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.7" z="0.5"/><float name="radius" value="0.45"/>
            <bsdf type="roughdielectric"><float name="alpha" value="0.2"/><float name="int_ior" value="1.5"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="-0.6" y="-0.4" z="0.3"/><float name="radius" value="0.3"/>
            <bsdf type="dielectric"/></shape>"#;
    let depth_8 = BdptIntegrator {
        max_depth: 8,
        ..BdptIntegrator::default()
    };
    assert_agrees_with_path(
        "glass",
        lit_scene(PINHOLE, RECTANGLE_LIGHT, glass),
        depth_8.clone(),
        512,
    );
    let folder = std::env::temp_dir().join(format!("prism-bdpt-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    let mesh = folder.join("coarse-sphere.obj");
    std::fs::write(&mesh, coarse_sphere_obj(6, 4)).unwrap();
    let smooth = format!(
        r#"<shape type="obj"><string name="filename" value="{}"/>
            <transform name="to_world"><scale value="0.5"/><translate x="0.3" y="-0.6" z="0.5"/></transform>
            <bsdf type="diffuse"/></shape>"#,
        mesh.display()
    );
    let scene = lit_scene(PINHOLE, RECTANGLE_LIGHT, &smooth);
    std::fs::remove_dir_all(&folder).ok();
    assert_agrees_with_path("shading normals", scene, depth_8, 512);
}

/// Behind rough glass whose index varies with wavelength, where both subpaths keep only the
/// hero wavelength from the glass on, the estimate keeps its scale.
#[test]
fn bdpt_and_path_agree_behind_dispersive_rough_glass() {
    let glass = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.7" z="0.5"/><float name="radius" value="0.45"/>
            <bsdf type="roughdielectric"><float name="alpha" value="0.2"/>
                <spectrum type="cauchy" name="int_ior"><float name="a" value="1.3"/><float name="b" value="0.03"/></spectrum></bsdf></shape>"#;
    assert_agrees_with_path(
        "dispersive glass",
        lit_scene(PINHOLE, RECTANGLE_LIGHT, glass),
        BdptIntegrator {
            max_depth: 8,
            ..BdptIntegrator::default()
        },
        1024,
    );
}

/// Without the light-tracing strategies, without light sampling (s = 1 connects the light
/// subpath's first vertex), with hidden emitters and with a depth limit, the estimate is the
/// path tracer's.
#[test]
fn bdpt_switches_keep_the_estimate() {
    let scene = || lit_scene(PINHOLE, SPHERE_LIGHT, "");
    let variants = [
        (
            "no light image",
            BdptIntegrator {
                light_image: false,
                ..BdptIntegrator::default()
            },
        ),
        (
            "no direct sampling",
            BdptIntegrator {
                sample_direct: false,
                ..BdptIntegrator::default()
            },
        ),
        (
            "hidden emitters, depth 3",
            BdptIntegrator {
                hide_emitters: true,
                max_depth: 3,
                ..BdptIntegrator::default()
            },
        ),
    ];
    for (name, integrator) in variants {
        assert_agrees_with_path(name, scene(), integrator, 256);
    }
}

fn small_scene() -> Scene {
    let mut scene = cornell_box(13);
    scene.integrator = bdpt(-1);
    scene
}

/// One and two threads give the same film to the last bit, and another seed another film.
#[test]
fn bdpt_is_bit_identical_for_any_thread_count() {
    assert_bit_identical_for_any_thread_count(&small_scene(), 4);
}

/// A render continued pass by pass from its state (as `--resume` does), and the renders of
/// disjoint sample ranges merged (as `prism merge` does), equal one render of all the samples.
#[test]
fn bdpt_resumed_and_merged_renders_equal_one_render() {
    assert_resumed_and_merged_equal_one_render(&small_scene(), &[2, 5, 6]);
}

/// The error of reading `xml` (a scene), as text.
fn load_error(xml: &str) -> String {
    match scene_from_xml(xml, "bdpt-test.xml") {
        Ok(_) => panic!("the scene was accepted"),
        Err(error) => error.to_string(),
    }
}

/// A scene with `integrator` (XML), a camera and `rest`.
fn scene_with(integrator: &str, rest: &str) -> String {
    format!(
        r#"<scene version="3.0.0">{integrator}{PINHOLE}
        <shape type="sphere"><bsdf type="diffuse"/></shape>{rest}</scene>"#
    )
}

/// Mitsuba 0.6's parameter names (upgraded to snake case in a file of version 0.6) are read;
/// bad values, lights it cannot start from, media and sensors it cannot connect to are refused
/// with the line that holds them.
#[test]
fn bdpt_parameters_and_scenes_are_checked_when_read() {
    let old = r#"<scene version="0.6.0"><integrator type="bdpt"><integer name="maxDepth" value="6"/>
        <integer name="rrDepth" value="3"/><boolean name="lightImage" value="false"/>
        <boolean name="sampleDirect" value="false"/></integrator>
        <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
        <shape type="sphere"><emitter type="area"/></shape></scene>"#;
    let scene = scene_from_xml(old, "bdpt-0.6.xml").unwrap();
    let Integrator::Bdpt(integrator) = &scene.integrator else {
        panic!("not bdpt: {:?}", scene.integrator);
    };
    assert_eq!(
        (
            integrator.max_depth,
            integrator.rr_depth,
            integrator.light_image,
            integrator.sample_direct
        ),
        (6, 3, false, false)
    );
    let bad_depth = load_error(&scene_with(
        r#"<integrator type="bdpt"><integer name="max_depth" value="-2"/></integrator>"#,
        "",
    ));
    assert!(bad_depth.contains("max_depth must be -1"), "{bad_depth}");
    let bad_rr = load_error(&scene_with(
        r#"<integrator type="bdpt"><integer name="rr_depth" value="0"/></integrator>"#,
        "",
    ));
    assert!(bad_rr.contains("rr_depth must be at least 1"), "{bad_rr}");
    let xml = scene_with(
        r#"<integrator type="bdpt"/>"#,
        "\n<emitter type=\"constant\"/>",
    );
    let line = xml[..xml.find("<emitter type=\"constant\"").unwrap()]
        .matches('\n')
        .count()
        + 1;
    let environment = load_error(&xml);
    assert!(
        environment.contains("does not start light paths on a constant emitter")
            && environment.contains(&format!("bdpt-test.xml:{line}:")),
        "{environment}"
    );
    let medium = load_error(&scene_with(
        r#"<integrator type="bdpt"/>"#,
        r#"<medium type="homogeneous" id="fog"/>"#,
    ));
    assert!(
        medium.contains("bdpt integrator does not render participating media"),
        "{medium}"
    );
}

/// veach-bidir, the scene bidirectional methods were made for, loads with `bdpt` as its
/// integrator and renders finite and not black (its relMSE against `path` at equal time is in
/// docs/performance.md).
#[test]
fn veach_bidir_renders_with_bdpt() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/veach-bidir/scene.xml");
    let defines = [
        ("integrator".to_string(), "bdpt".to_string()),
        ("resx".to_string(), "24".to_string()),
        ("resy".to_string(), "24".to_string()),
    ];
    let scene = prism_mitsuba::load_scene(&path, &defines).unwrap().scene;
    assert!(matches!(scene.integrator, Integrator::Bdpt(_)));
    let film = render_film(&scene, 2, 1, None);
    assert!(film.pixels.iter().any(|p| p.sum(1) > 0.0), "black");
    assert!(
        film.pixels
            .iter()
            .all(|p| (0..3).all(|c| p.sum(c).is_finite())),
        "not finite"
    );
}
