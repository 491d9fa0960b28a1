//! The emitter plugins as the scene reader builds them from Mitsuba XML: Mitsuba's defaults
//! (D65 emission of luminance 1, the spot's beam at ¾ of its cutoff, black BSDFs on emitting
//! shapes), the placement parameters, black bodies, environment maps, `emitter_sampling` and
//! delta emitters nested in shapes.

use std::f32::consts::PI;
use std::path::Path;

use glam::{Vec2, Vec3};
use prism_core::bsdf::Bsdf;
use prism_core::light::{Light, LightQuery, LightSampler, LightSource, Receiver};
use prism_core::scene::Scene;
use prism_core::spectrum::SampledWavelengths;
use prism_core::spectrum::cie::d65_normalized;
use prism_core::texture::TextureValues;
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::reader::read_scene_str;

/// Builds a scene from XML placed after a minimal sensor, in `folder` (for files it names).
fn load(folder: &Path, body: &str) -> Scene {
    let text = format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
    {body}
</scene>"#
    );
    let root = read_scene_str(&text, &folder.join("scene.xml"), &[]).unwrap();
    build_scene(&root).unwrap().scene
}

/// The radiance (or intensity, irradiance) a light delivers at `lambda` along a sample from
/// `reference`, undoing the distance falloff of point and spot lights.
fn emission_at(scene: &Scene, light: usize, reference: Vec3, lambda: f32) -> f32 {
    let ls = scene.world.lights[light]
        .sample_incident(LightQuery {
            shapes: &scene.world.geometry.primitives,
            reference,
            time: 0.0,
            u_choice: 0.5,
            u: Vec2::splat(0.5),
            lambda: &SampledWavelengths::single(lambda),
        })
        .unwrap();
    match scene.world.lights[light] {
        Light::Point(_) | Light::Spot(_) => ls.radiance[0] * (ls.p - reference).length_squared(),
        Light::Projector(_) => ls.radiance[0] * ls.wi.z.abs(),
        _ => ls.radiance[0],
    }
}

#[test]
fn default_emission_is_d65_of_luminance_one() {
    let scene = load(
        Path::new("."),
        r#"<shape type="sphere"><point name="center" x="0" y="0" z="5"/><emitter type="area"/></shape>
    <emitter type="point"/>
    <emitter type="spot"/>
    <emitter type="directional"/>
    <emitter type="constant"/>"#,
    );
    assert_eq!(scene.world.lights.len(), 5);
    for lambda in [400.0, 550.0, 700.0] {
        let d65 = d65_normalized(lambda);
        for (light, reference) in [
            (0, Vec3::ZERO),
            (1, Vec3::new(0.0, 0.0, -2.0)),
            (2, Vec3::new(0.0, 0.0, 3.0)),
            (3, Vec3::ZERO),
            (4, Vec3::ZERO),
        ] {
            let value = emission_at(&scene, light, reference, lambda);
            assert!(
                (value / d65 - 1.0).abs() < 1e-3,
                "light {light} at {lambda} nm: {value}, D65 is {d65}"
            );
        }
    }
}

/// Mitsuba gives a shape with an area emitter and no BSDF a black diffuse BSDF, other shapes
/// a 50 % grey one.
#[test]
fn emitting_shapes_without_a_bsdf_are_black() {
    let scene = load(
        Path::new("."),
        r#"<shape type="sphere"><emitter type="area"/></shape>
    <shape type="sphere"><point name="center" x="3" y="0" z="0"/></shape>"#,
    );
    let reflectance = |shape: usize| {
        let material = &scene.world.materials[scene.world.shape_info[shape].material as usize];
        #[allow(unreachable_patterns)] // other BSDFs come with the materials issue
        match &material.front {
            Bsdf::Diffuse(diffuse) => diffuse.reflectance.eval_1(glam::Vec2::ZERO),
            other => panic!("shape {shape} has {other:?}"),
        }
    };
    assert_eq!(reflectance(0), 0.0);
    assert_eq!(reflectance(1), 0.5);
}

/// An `area` emitter declared at the top level with an id (before or after its shape) is the
/// emitter of the shape that references it, registered once; one that
/// no shape references emits nothing, as in Mitsuba 3.
#[test]
fn area_emitters_referenced_by_id() {
    let nested = load(
        Path::new("."),
        r#"<shape type="sphere"><emitter type="area"><rgb name="radiance" value="2, 1, 0.5"/></emitter></shape>
    <emitter type="point"/>"#,
    );
    for body in [
        r#"<emitter type="area" id="light"><rgb name="radiance" value="2, 1, 0.5"/></emitter>
    <shape type="sphere"><ref id="light"/></shape>
    <emitter type="point"/>"#,
        r#"<shape type="sphere"><ref name="emitter" id="light"/></shape>
    <emitter type="point"/>
    <emitter type="area" id="light"><rgb name="radiance" value="2, 1, 0.5"/></emitter>"#,
        r#"<shape type="sphere"><ref id="light"/></shape>
    <emitter type="point"/>
    <emitter type="area" id="unused"><rgb name="radiance" value="7"/></emitter>
    <emitter type="area" id="light"><rgb name="radiance" value="2, 1, 0.5"/></emitter>"#,
    ] {
        let referenced = load(Path::new("."), body);
        assert_eq!(referenced.world.lights.len(), 2, "{body}");
        assert_eq!(referenced.world.shape_info[0].light, Some(0), "{body}");
        assert!(
            matches!(referenced.world.lights[1], Light::Point(_)),
            "{body}"
        );
        for lambda in [450.0, 600.0] {
            let a = emission_at(&nested, 0, Vec3::new(0.0, 0.0, 3.0), lambda);
            let b = emission_at(&referenced, 0, Vec3::new(0.0, 0.0, 3.0), lambda);
            assert_eq!(a, b, "{body} at {lambda} nm");
        }
    }
}

/// The spot's defaults are a 20° cutoff and a beam of ¾ of it; its power is
/// 2πI(1 − (sin c − sin β)/(c − β)) with I of luminance 1.
#[test]
fn spot_defaults_follow_mitsuba() {
    let scene = load(Path::new("."), r#"<emitter type="spot"/>"#);
    let (c, b) = (20f32.to_radians(), 15f32.to_radians());
    let expected = 2.0 * PI * (1.0 - (c.sin() - b.sin()) / (c - b));
    let power = scene.world.lights[0].power(&scene.world.geometry.primitives);
    assert!(
        (power / expected - 1.0).abs() < 1e-3,
        "{power} vs {expected}"
    );
}

/// `direction` is where the light travels; without it, `to_world` turns +z.
#[test]
fn directional_light_placement() {
    let scene = load(
        Path::new("."),
        r#"<emitter type="directional"><vector name="direction" x="0" y="-2" z="0"/></emitter>
    <emitter type="directional"><transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>"#,
    );
    let wi = |light: usize| {
        scene.world.lights[light]
            .sample_incident(LightQuery {
                shapes: &[],
                reference: Vec3::ZERO,
                time: 0.0,
                u_choice: 0.5,
                u: Vec2::splat(0.5),
                lambda: &SampledWavelengths::single(550.0),
            })
            .unwrap()
            .wi
    };
    assert!((wi(0) - Vec3::Y).length() < 1e-6, "{}", wi(0));
    // Rotating +z by 90° about x gives −y: the light arrives from +y.
    assert!((wi(1) - Vec3::Y).length() < 1e-6, "{}", wi(1));
}

#[test]
fn blackbody_radiance_and_uniform_emitter_sampling() {
    let scene = load(
        Path::new("."),
        r#"<integrator type="path"><string name="emitter_sampling" value="uniform"/></integrator>
    <emitter type="constant"><spectrum type="blackbody" name="radiance"><float name="temperature" value="3000"/></spectrum></emitter>
    <emitter type="point"><rgb name="intensity" value="100"/></emitter>"#,
    );
    let value = emission_at(&scene, 0, Vec3::ZERO, 555.0);
    assert!((value / 399.639 - 1.0).abs() < 1e-4, "{value}");
    let integrator = scene.integrator.prepare(&scene.world);
    assert!(matches!(
        integrator.light_sampler(),
        LightSampler::Uniform { count: 2 }
    ));
    assert_eq!(
        integrator
            .light_sampler()
            .pmf(1, &Receiver::point(Vec3::ZERO)),
        0.5
    );
    assert_eq!(scene.world.environment, Some(0));
}

/// Lights are chosen by importance unless the scene asks for power (the lecture's rule) or
/// uniform choice.
#[test]
fn emitter_sampling_is_exhaustive_by_default() {
    let lights = r#"<emitter type="point"><rgb name="intensity" value="100"/></emitter>"#;
    for (integrator, exhaustive) in [
        (r#"<integrator type="path"/>"#, true),
        (r#"<integrator type="volpath"/>"#, true),
        (
            r#"<integrator type="path"><string name="emitter_sampling" value="exhaustive"/></integrator>"#,
            true,
        ),
        (
            r#"<integrator type="path"><string name="emitter_sampling" value="power"/></integrator>"#,
            false,
        ),
    ] {
        let scene = load(Path::new("."), &format!("{integrator}\n    {lights}"));
        let prepared = scene.integrator.prepare(&scene.world);
        assert_eq!(
            matches!(prepared.light_sampler(), LightSampler::Exhaustive(_)),
            exhaustive,
            "{integrator}"
        );
    }
}

/// A PNG environment map is decoded from sRGB, and scaled.
#[test]
fn environment_map_from_a_png() {
    let folder = std::env::temp_dir().join(format!("prism-light-plugins-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    // The linear value whose sRGB code is exactly 128, so that the 8-bit file is exact.
    let linear = prism_core::image::srgb::decode(128.0 / 255.0);
    prism_core::image::write_png_srgb(&folder.join("sky.png"), 4, 3, &[linear; 36]).unwrap();
    let scene = load(
        &folder,
        r#"<emitter type="envmap"><string name="filename" value="sky.png"/><float name="scale" value="2"/></emitter>"#,
    );
    let value = scene.world.lights[0].environment_radiance(
        Vec3::new(0.3, 0.5, -0.8).normalize(),
        &SampledWavelengths::single(600.0),
    )[0];
    let expected = 2.0 * linear * d65_normalized(600.0);
    assert!(
        (value / expected - 1.0).abs() < 1e-3,
        "{value} vs {expected}"
    );
    std::fs::remove_dir_all(&folder).ok();
}

/// Emitters' textures read as Mitsuba 3.9.1 reads them (values printed by its
/// `scalar_spectral` variant at 450, 550 and 650 nm): a white bitmap as an area light's
/// radiance emits the constant 1 (no D65 factor); a projector's white bitmap irradiance gives
/// π at distance 1 on its axis, its default irradiance π · D65; a spot light's white texture
/// leaves its D65 intensity as it is. Prism's D65 and Mitsuba's differ by up to 0.11 % (at
/// 450 nm), so values that carry D65 agree to 2 · 10⁻³, the texture's own to 10⁻³.
#[test]
fn emitter_textures_as_mitsuba_reads_them() {
    let folder = std::env::temp_dir().join(format!("prism-light-textures-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    prism_core::image::write_png_srgb(&folder.join("white.png"), 2, 2, &[1.0; 12]).unwrap();
    let scene = load(
        &folder,
        r#"<shape type="rectangle"><emitter type="area"><texture type="bitmap" name="radiance"><string name="filename" value="white.png"/></texture></emitter></shape>
    <emitter type="projector"><texture type="bitmap" name="irradiance"><string name="filename" value="white.png"/></texture><float name="fov" value="45"/></emitter>
    <emitter type="projector"><float name="fov" value="45"/></emitter>
    <emitter type="spot"><texture type="bitmap" name="texture"><string name="filename" value="white.png"/></texture></emitter>"#,
    );
    let mitsuba_d65 = [(450.0, 1.18193), (550.0, 1.05100), (650.0, 0.80837)];
    let on_axis = Vec3::new(0.0, 0.0, 1.0);
    for (lambda, d65) in mitsuba_d65 {
        for (light, expected, tolerance) in [
            (0, 1.0, 1e-3),
            (1, PI, 1e-3),
            (2, PI * d65, 2e-3),
            (3, d65, 2e-3),
        ] {
            let value = emission_at(&scene, light, on_axis, lambda);
            assert!(
                (value / expected - 1.0).abs() < tolerance,
                "light {light} at {lambda} nm: {value} instead of Mitsuba's {expected}"
            );
        }
    }
    std::fs::remove_dir_all(&folder).ok();
}

/// The `area` emitter's `sampling` chooses how light samples find its shape: by solid angle
/// (the default) or, as the lecture samples lights, by area.
#[test]
fn area_emitter_sampling_is_a_scene_choice() {
    let sampling = |emitter: &str| {
        let scene = load(
            Path::new("."),
            &format!(r#"<shape type="rectangle">{emitter}</shape>"#),
        );
        match &scene.world.lights[0] {
            Light::Area(area) => area.sampling,
            other => panic!("{other:?}"),
        }
    };
    use prism_core::geometry::ShapeSampling;
    assert_eq!(
        sampling(r#"<emitter type="area"/>"#),
        ShapeSampling::SolidAngle
    );
    assert_eq!(
        sampling(r#"<emitter type="area"><string name="sampling" value="area"/></emitter>"#),
        ShapeSampling::Area
    );
    assert_eq!(
        sampling(r#"<emitter type="area"><string name="sampling" value="solid_angle"/></emitter>"#),
        ShapeSampling::SolidAngle
    );
}

/// A spot nested in a sphere, lighting a floor through `direct` (Mitsuba 3 loads such scenes:
/// the spot lights from its own `to_world` and the sphere, whose surface radiance is the spot's
/// `eval`, zero, takes the black BSDF of emitting shapes).
fn spot_in_a_sphere(nested: bool) -> String {
    let spot = r#"<emitter type="spot">
            <transform name="to_world"><lookat origin="0, 2, 0.5" target="0, 0, 0" up="0, 0, 1"/></transform>
            <rgb name="intensity" value="8, 8, 8"/>
            <float name="cutoff_angle" value="40"/>
        </emitter>"#;
    let (inside, outside) = if nested {
        (spot, "")
    } else {
        (
            r#"<bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>"#,
            spot,
        )
    };
    format!(
        r#"<scene version="3.0.0">
    <integrator type="direct"/>
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, 2, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="48"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.5, 0.4"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="0.8" y="0.5" z="0"/>
        <float name="radius" value="0.3"/>
        {inside}
    </shape>
    {outside}
</scene>"#
    )
}

/// The nested spot renders exactly as the same spot declared at the top level beside a black
/// sphere, and as Mitsuba 3 renders the nested form: its image means, stored from
/// `mitsuba-ref` (Mitsuba 3.9.1 `scalar_spectral`, 256 spp, seed 1) of this scene, are within
/// four standard errors of the difference (Prism's standard error, doubled in variance for
/// Mitsuba's equal noise at equal samples).
#[test]
fn a_spot_nested_in_a_shape_lights_from_its_own_placement() {
    use crate::common::scenes::{image_mean_and_standard_error, render_film, scene_from_xml};
    let nested = scene_from_xml(&spot_in_a_sphere(true), "spot-in-sphere").unwrap();
    let top_level = scene_from_xml(&spot_in_a_sphere(false), "spot-beside-sphere").unwrap();
    assert_eq!(nested.world.lights.len(), 1);
    let film = render_film(&nested, 256, 1, None);
    assert_eq!(film.pixels, render_film(&top_level, 256, 1, None).pixels);
    // Mitsuba's linear sRGB means, 0.044822, 0.037338 and 0.029829, in CIE XYZ (IEC 61966-2-1).
    let [r, g, b] = [0.044822, 0.037338, 0.029829];
    let mitsuba = [
        0.4124564 * r + 0.3575761 * g + 0.1804375 * b,
        0.2126729 * r + 0.7151522 * g + 0.0721750 * b,
        0.0193339 * r + 0.1191920 * g + 0.9503041 * b,
    ];
    for (c, expected) in mitsuba.into_iter().enumerate() {
        let (mean, error) = image_mean_and_standard_error(&film, c);
        let z = (mean - expected) / (error * 2f64.sqrt());
        assert!(
            z.abs() < 4.0,
            "channel {c}: {mean} against Mitsuba's {expected} (z = {z:.2})"
        );
    }
}

/// A `directionalarea` nested in a shape, or declared with an id and referenced from one, is
/// the shape's light but shows no emission on its surface (its radiance is a delta along the
/// normal, as Mitsuba's `eval` returns zero), and light samples from any point find nothing.
#[test]
fn a_directional_area_emitter_is_found_by_no_ray() {
    let nested = r#"<shape type="sphere"><emitter type="directionalarea"><rgb name="radiance" value="2"/></emitter></shape>"#;
    let referenced = r#"<emitter type="directionalarea" id="beams"/>
    <shape type="sphere"><ref id="beams"/></shape>"#;
    for body in [nested, referenced] {
        let scene = load(Path::new("."), body);
        assert_eq!(scene.world.lights.len(), 1, "{body}");
        assert!(
            matches!(scene.world.lights[0], Light::DirectionalArea(_)),
            "{body}"
        );
        assert_eq!(scene.world.shape_info[0].light, None, "{body}");
        for reference in [Vec3::new(0.0, 0.0, 3.0), Vec3::new(2.0, -1.0, 0.5)] {
            let sample = scene.world.lights[0].sample_incident(LightQuery {
                shapes: &scene.world.geometry.primitives,
                reference,
                time: 0.0,
                u_choice: 0.5,
                u: Vec2::splat(0.3),
                lambda: &SampledWavelengths::single(550.0),
            });
            assert!(sample.is_none(), "{body}");
        }
    }
}
