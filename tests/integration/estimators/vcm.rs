//! Vertex connection and merging (`vcm`): against closed forms (furnaces in a sphere and in a
//! box, the disk light over a plane), with merging off against `bdpt` and with it on against
//! the path tracer (the Cornell box, glass, a point light, dispersive glass, each switch),
//! bit-identical for any thread count, its resumed and merged renders equal to one render, and
//! its bad parameters and a target error refused.

use glam::UVec2;
use prism_core::film::Film;
use prism_core::integrator::{BdptIntegrator, Integrator, PathIntegrator, VcmIntegrator};
use prism_core::render::{RenderOptions, StopRule, render};
use prism_core::scene::Scene;

use super::closed_form::{furnace_scene, inner_box, inner_sphere};
use super::convergence::assert_same_image;
use super::guarantees::{
    assert_bit_identical_for_any_thread_count, assert_resumed_and_merged_equal_one_render,
};
use super::ptracer::{PINHOLE, cornell_box, lit_scene};
use crate::common::scenes::{
    assert_mean_luminance, disk_light_over_plane, render_film, scene_from_xml,
};

/// Connections only (`use_vm` false): bidirectional path tracing.
fn connections_only() -> VcmIntegrator {
    VcmIntegrator {
        merging: false,
        ..VcmIntegrator::default()
    }
}

/// Inside a sphere the disc of radius r around a point meets the surface in a cap of area
/// exactly π r² (Archimedes), so merging has no radius bias there: the image's mean is
/// le / (1 − rho) = 2 within 4 standard errors, with merging and without.
#[test]
fn vcm_sphere_furnace_gives_le_over_one_minus_rho() {
    for (name, integrator) in [
        ("merging", VcmIntegrator::default()),
        ("connections only", connections_only()),
    ] {
        let scene = furnace_scene(inner_sphere(), 0.5, 1.0, integrator);
        let film = render_film(&scene, 512, 3, None);
        assert_mean_luminance(&format!("vcm sphere furnace, {name}"), &film, 2.0);
    }
}

/// The mean absolute error of Y over the pixels against `expected`.
fn mean_absolute_error(film: &Film, expected: f64) -> f64 {
    film.pixels
        .iter()
        .map(|p| (p.mean()[1] - expected).abs())
        .sum::<f64>()
        / film.pixels.len() as f64
}

/// Inside a box whose every wall emits 1 and reflects half: without merging the estimate is
/// unbiased (the mean within 4 standard errors of 2); with a large radius (0.4 in a 2 × 3 × 4
/// box) the merges blur past the edges, and the error against 2 falls as the iterations grow
/// and the radius shrinks: after 256 iterations it is under 0.8 times that after 16.
#[test]
fn vcm_box_furnace_converges_to_le_over_one_minus_rho() {
    let scene = furnace_scene(inner_box(), 0.5, 1.0, connections_only());
    let film = render_film(&scene, 512, 5, None);
    assert_mean_luminance("vcm box furnace, connections only", &film, 2.0);
    let large = VcmIntegrator {
        initial_radius: Some(0.4),
        ..VcmIntegrator::default()
    };
    let scene = furnace_scene(inner_box(), 0.5, 1.0, large);
    let early = mean_absolute_error(&render_film(&scene, 16, 6, None), 2.0);
    let late = mean_absolute_error(&render_film(&scene, 256, 6, None), 2.0);
    assert!(
        late < 0.8 * early,
        "mean absolute error {early} after 16 iterations, {late} after 256"
    );
}

/// Direct light only (`max_depth` 2) from a disk light over a diffuse plane, connections only:
/// each pixel, by the variance the film reports for it, agrees with its exact value in a
/// chi-square test at significance 10⁻³, and the image's mean within 4 standard errors.
#[test]
fn vcm_matches_the_disk_light_closed_form() {
    let mut setup = disk_light_over_plane(UVec2::new(16, 16));
    setup.scene.integrator = Integrator::from(VcmIntegrator {
        max_depth: 2,
        ..connections_only()
    });
    let film = render_film(&setup.scene, 256, 5, None);
    setup.assert_matches(&film);
}

/// With merging off, vcm and bdpt estimate the same image of the Cornell box, per channel.
#[test]
fn vcm_without_merging_agrees_with_bdpt() {
    let mut scene = cornell_box(16);
    scene.integrator = Integrator::from(BdptIntegrator::default());
    let bdpt = render_film(&scene, 256, 3, None);
    scene.integrator = Integrator::from(connections_only());
    let vcm = render_film(&scene, 256, 4, None);
    for c in 0..3 {
        assert_same_image("Cornell box, connections only", &vcm, &bdpt, c);
    }
}

/// Renders `scene` with the path tracer at `path_spp` and with `integrator` at `spp` samples,
/// and asserts the two images agree in X, Y and Z.
fn assert_agrees_with_path(
    name: &str,
    mut scene: Scene,
    integrator: VcmIntegrator,
    path_spp: u32,
    spp: u32,
) {
    scene.integrator = Integrator::from(PathIntegrator {
        max_depth: integrator.max_depth,
        hide_emitters: integrator.hide_emitters,
        ..PathIntegrator::default()
    });
    let path = render_film(&scene, path_spp, 11, None);
    scene.integrator = Integrator::from(integrator);
    let vcm = render_film(&scene, spp, 12, None);
    assert!(vcm.pixels.iter().any(|p| p.sum(1) > 0.0), "{name}: black");
    for c in 0..3 {
        assert_same_image(name, &vcm, &path, c);
    }
}

/// With merging on (a radius of about a hundredth of the box, shrinking over 256 iterations,
/// whose blur stays within the noise), vcm and the path tracer estimate the same image of the
/// Cornell box.
#[test]
fn vcm_and_path_agree_on_the_cornell_box() {
    let integrator = VcmIntegrator {
        radius_scale: 0.1,
        ..VcmIntegrator::default()
    };
    assert_agrees_with_path("Cornell box", cornell_box(16), integrator, 1024, 256);
}

const RECTANGLE_LIGHT: &str = r#"<shape type="rectangle"><transform name="to_world"><scale value="0.4"/><rotate x="1" angle="180"/><translate x="0.4" z="1.8"/></transform>
                <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>"#;

/// Through smooth and rough glass (caustics, which merging finds) and glossy surfaces under a
/// point light, vcm (with merging) and the path tracer estimate the same image.
#[test]
fn vcm_and_path_agree_through_glass_and_under_a_point_light() {
    let glass = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.7" z="0.5"/><float name="radius" value="0.45"/>
            <bsdf type="roughdielectric"><float name="alpha" value="0.2"/><float name="int_ior" value="1.5"/></bsdf></shape>
        <shape type="sphere"><point name="center" x="-0.6" y="-0.4" z="0.3"/><float name="radius" value="0.3"/>
            <bsdf type="dielectric"/></shape>"#;
    let small = VcmIntegrator {
        max_depth: 8,
        radius_scale: 0.25,
        ..VcmIntegrator::default()
    };
    assert_agrees_with_path(
        "glass",
        lit_scene(PINHOLE, RECTANGLE_LIGHT, glass),
        small.clone(),
        1024,
        256,
    );
    let glossy = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.6" z="0.45"/><float name="radius" value="0.4"/>
            <bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.15"/></bsdf></shape>"#;
    let point = r#"<emitter type="point"><point name="position" x="0.5" y="-0.3" z="1.5"/><rgb name="intensity" value="3, 2, 1"/></emitter>"#;
    assert_agrees_with_path(
        "point light",
        lit_scene(PINHOLE, point, glossy),
        small,
        512,
        256,
    );
}

/// Behind rough glass whose index varies with wavelength, where the subpaths that meet it keep
/// only the hero wavelength, the estimate keeps its scale.
#[test]
fn vcm_and_path_agree_behind_dispersive_rough_glass() {
    let glass = r#"<shape type="sphere"><point name="center" x="0.3" y="-0.7" z="0.5"/><float name="radius" value="0.45"/>
            <bsdf type="roughdielectric"><float name="alpha" value="0.2"/>
                <spectrum type="cauchy" name="int_ior"><float name="a" value="1.3"/><float name="b" value="0.03"/></spectrum></bsdf></shape>"#;
    assert_agrees_with_path(
        "dispersive glass",
        lit_scene(PINHOLE, RECTANGLE_LIGHT, glass),
        VcmIntegrator {
            max_depth: 8,
            radius_scale: 0.25,
            ..VcmIntegrator::default()
        },
        1024,
        512,
    );
}

/// Without the light image (the strategies t = 1 then leave the weights too), with hidden
/// emitters and with a depth limit, the estimate is the path tracer's.
#[test]
fn vcm_switches_keep_the_estimate() {
    let sphere_light = r#"<shape type="sphere"><point name="center" x="0.6" y="0" z="1.3"/><float name="radius" value="0.2"/>
                <emitter type="area"><rgb name="radiance" value="8, 6, 4"/></emitter></shape>"#;
    let variants = [
        (
            "no light image",
            VcmIntegrator {
                light_image: false,
                radius_scale: 0.25,
                ..VcmIntegrator::default()
            },
        ),
        (
            "hidden emitters, depth 3",
            VcmIntegrator {
                hide_emitters: true,
                max_depth: 3,
                radius_scale: 0.25,
                ..VcmIntegrator::default()
            },
        ),
    ];
    for (name, integrator) in variants {
        assert_agrees_with_path(
            name,
            lit_scene(PINHOLE, sphere_light, ""),
            integrator,
            512,
            256,
        );
    }
}

fn small_scene() -> Scene {
    let mut scene = cornell_box(13);
    scene.integrator = Integrator::from(VcmIntegrator::default());
    scene
}

/// One and two threads give the same film to the last bit, and another seed another film.
#[test]
fn vcm_is_bit_identical_for_any_thread_count() {
    assert_bit_identical_for_any_thread_count(&small_scene(), 4);
}

/// A render continued pass by pass from its state (as `--resume` does), and the renders of
/// disjoint sample ranges merged (as `prism merge` does), equal one render of all the samples:
/// iteration s's radius depends on s alone.
#[test]
fn vcm_resumed_and_merged_renders_equal_one_render() {
    assert_resumed_and_merged_equal_one_render(&small_scene(), &[2, 5, 6]);
}

/// A target error is refused with merging (no error bar covers the merges' bias), and
/// accepted without it.
#[test]
fn vcm_refuses_a_target_error_where_it_merges() {
    let options = RenderOptions {
        stop: StopRule {
            target_error: Some(0.5),
            ..StopRule::samples(2)
        },
        ..RenderOptions::fixed(2, 0, None)
    };
    let mut scene = small_scene();
    let error = render(&scene, &options)
        .err()
        .expect("accepted")
        .to_string();
    assert!(error.contains("vcm"), "{error}");
    scene.integrator = Integrator::from(connections_only());
    render(&scene, &options).unwrap();
}

/// Parameters outside their ranges, lights it cannot start from and media are refused when the
/// scene is read, naming the parameter or the problem; Mitsuba 0.5's names are read.
#[test]
fn vcm_parameters_are_checked_when_read() {
    let cases = [
        (r#"<float name="alpha" value="1"/>"#, "alpha"),
        (r#"<float name="alpha" value="0"/>"#, "alpha"),
        (r#"<float name="radius_scale" value="0"/>"#, "radius_scale"),
        (
            r#"<float name="initial_radius" value="-1"/>"#,
            "initial_radius",
        ),
        (r#"<integer name="max_depth" value="-2"/>"#, "max_depth"),
        (r#"<integer name="rr_depth" value="0"/>"#, "rr_depth"),
    ];
    let scene = |integrator: &str, rest: &str| {
        format!(
            r#"<scene version="3.0.0">{integrator}{PINHOLE}
            <shape type="sphere"><bsdf type="diffuse"/></shape>{rest}</scene>"#
        )
    };
    let load_error = |xml: &str| match scene_from_xml(xml, "vcm-test.xml") {
        Ok(_) => panic!("accepted: {xml}"),
        Err(error) => error.to_string(),
    };
    for (parameter, name) in cases {
        let error = load_error(&scene(
            &format!(r#"<integrator type="vcm">{parameter}</integrator>"#),
            "",
        ));
        assert!(error.contains(name), "{parameter}: {error}");
    }
    let environment = load_error(&scene(
        r#"<integrator type="vcm"/>"#,
        r#"<emitter type="constant"/>"#,
    ));
    assert!(
        environment.contains("vcm integrator does not start light paths on a constant emitter"),
        "{environment}"
    );
    let medium = load_error(&scene(
        r#"<integrator type="vcm"/>"#,
        r#"<medium type="homogeneous" id="fog"/>"#,
    ));
    assert!(
        medium.contains("vcm integrator does not render participating media"),
        "{medium}"
    );
    let old = r#"<scene version="0.6.0"><integrator type="vcm"><integer name="maxDepth" value="6"/>
        <integer name="rrDepth" value="3"/><boolean name="lightImage" value="false"/>
        <float name="initialRadius" value="0.5"/><float name="radiusScale" value="2"/>
        <boolean name="useVM" value="false"/></integrator>
        <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
        <shape type="sphere"><emitter type="area"/></shape></scene>"#;
    let scene = scene_from_xml(old, "vcm-0.6.xml").unwrap();
    let Integrator::Vcm(integrator) = &scene.integrator else {
        panic!("not vcm: {:?}", scene.integrator);
    };
    assert_eq!(
        (
            integrator.max_depth,
            integrator.rr_depth,
            integrator.light_image,
            integrator.initial_radius,
            integrator.radius_scale,
            integrator.merging,
        ),
        (6, 3, false, Some(0.5), 2.0, false)
    );
}
