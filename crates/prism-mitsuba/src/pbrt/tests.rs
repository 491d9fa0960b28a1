//! The directives read into the plugin tree: each transform directive's matrix on a shape's
//! `to_world`, the graphics state's scoping, and the translation of lights, materials, media
//! and instances.

use std::path::Path;

use glam::{DMat4, DVec3};

use super::read_pbrt_str;
use super::spectra::luminance;
use crate::description::{PluginClass, PluginNode, PropertyValue, SpectrumValue};

fn root(text: &str) -> std::sync::Arc<PluginNode> {
    read_pbrt_str(text, Path::new("test.pbrt"))
        .unwrap_or_else(|e| panic!("{e}"))
        .root
}

fn error(text: &str) -> String {
    match read_pbrt_str(text, Path::new("test.pbrt")) {
        Ok(_) => panic!("the scene was read"),
        Err(e) => e.to_string(),
    }
}

fn nodes(root: &PluginNode, class: PluginClass) -> Vec<&PluginNode> {
    root.children
        .iter()
        .map(|c| c.node.as_ref())
        .filter(|n| n.class == class)
        .collect()
}

fn property<'a>(node: &'a PluginNode, name: &str) -> &'a PropertyValue {
    &node
        .properties
        .iter()
        .find(|p| p.name == name)
        .unwrap_or_else(|| panic!("{} has no {name}", node.describe()))
        .value
}

fn transform(node: &PluginNode) -> DMat4 {
    match property(node, "to_world") {
        PropertyValue::Transform(m) => *m,
        other => panic!("{other:?}"),
    }
}

/// The `to_world` of each shape of the world block `world`.
fn shape_transforms(world: &str) -> Vec<DMat4> {
    let root = root(&format!("WorldBegin\n{world}"));
    nodes(&root, PluginClass::Shape)
        .into_iter()
        .map(transform)
        .collect()
}

fn assert_close(found: DMat4, expected: DMat4) {
    assert!(
        found.abs_diff_eq(expected, 1e-12),
        "found {found:?}, expected {expected:?}"
    );
}

/// A matrix from its rows, as written on paper.
fn rows(r: [[f64; 4]; 4]) -> DMat4 {
    DMat4::from_cols_array_2d(&r).transpose()
}

#[test]
fn transforms_right_multiply_the_ctm() {
    // Translate then Scale: points are scaled first, then moved.
    let [m] = shape_transforms("Translate 1 2 3\nScale 2 2 2\nShape \"sphere\"")[..] else {
        panic!()
    };
    assert_close(
        m,
        rows([
            [2.0, 0.0, 0.0, 1.0],
            [0.0, 2.0, 0.0, 2.0],
            [0.0, 0.0, 2.0, 3.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
    );
    // Rotate 90 about z, then Translate 1 0 0: the point (0, 0, 0) goes to (0, 1, 0).
    let [m] = shape_transforms("Rotate 90 0 0 1\nTranslate 1 0 0\nShape \"sphere\"")[..] else {
        panic!()
    };
    assert_close(
        m,
        rows([
            [0.0, -1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
    );
}

#[test]
fn transform_sets_and_concat_transform_multiplies() {
    let scaled = "[2 0 0 0  0 3 0 0  0 0 4 0  0 0 0 1]";
    let moved = "[1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]";
    let found = shape_transforms(&format!(
        "Scale 9 9 9\nTransform {moved}\nShape \"sphere\"\nConcatTransform {scaled}\nShape \"sphere\"\nIdentity\nShape \"sphere\""
    ));
    let translation = rows([
        [1.0, 0.0, 0.0, 5.0],
        [0.0, 1.0, 0.0, 6.0],
        [0.0, 0.0, 1.0, 7.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);
    assert_close(found[0], translation);
    assert_close(
        found[1],
        rows([
            [2.0, 0.0, 0.0, 5.0],
            [0.0, 3.0, 0.0, 6.0],
            [0.0, 0.0, 4.0, 7.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
    );
    assert_close(found[2], DMat4::IDENTITY);
}

#[test]
fn attributes_and_transform_blocks_restore_the_state() {
    let found = shape_transforms(
        "Translate 1 0 0\nAttributeBegin\n  Translate 0 1 0\n  ReverseOrientation\n  Shape \"sphere\"\nAttributeEnd\nShape \"sphere\"\nTransformBegin\n  Scale 2 2 2\nTransformEnd\nShape \"sphere\"",
    );
    assert_close(found[0], DMat4::from_translation(DVec3::new(1.0, 1.0, 0.0)));
    assert_close(found[1], DMat4::from_translation(DVec3::X));
    assert_close(found[2], DMat4::from_translation(DVec3::X));
    let root = root(
        "WorldBegin\nAttributeBegin\nReverseOrientation\nShape \"sphere\"\nAttributeEnd\nShape \"sphere\"",
    );
    let shapes = nodes(&root, PluginClass::Shape);
    assert_eq!(
        property(shapes[0], "flip_normals"),
        &PropertyValue::Boolean(true)
    );
    assert!(
        shapes[1]
            .properties
            .iter()
            .all(|p| p.name != "flip_normals")
    );
    assert!(
        error("WorldBegin\nAttributeBegin\n")
            .contains("test.pbrt:2:1: this AttributeBegin is never ended")
    );
    assert!(
        error("WorldBegin\nTransformBegin\nAttributeEnd\n")
            .contains("test.pbrt:3:1: AttributeEnd does not match")
    );
}

#[test]
fn named_coordinate_systems() {
    let found = shape_transforms(
        "Translate 0 0 5\nCoordinateSystem \"lamp\"\nIdentity\nCoordSysTransform \"lamp\"\nShape \"sphere\"",
    );
    assert_close(found[0], DMat4::from_translation(DVec3::new(0.0, 0.0, 5.0)));
    // "camera" is the camera's world-from-camera transform.
    let root = root(
        "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nCoordSysTransform \"camera\"\nShape \"sphere\"",
    );
    let shape = nodes(&root, PluginClass::Shape)[0];
    assert_close(
        transform(shape),
        DMat4::from_translation(DVec3::new(0.0, 0.0, -5.0)),
    );
    assert!(
        error("WorldBegin\nCoordSysTransform \"nowhere\"")
            .contains("test.pbrt:2:19: unknown coordinate system")
    );
}

#[test]
fn the_camera_mirrors_x_and_measures_fov_along_the_shorter_axis() {
    let root = root(
        "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 20 \"integer yresolution\" 10\nWorldBegin\n",
    );
    let sensor = nodes(&root, PluginClass::Sensor)[0];
    assert_eq!(sensor.plugin_type, "perspective");
    assert_eq!(property(sensor, "fov"), &PropertyValue::Float(30.0));
    assert_eq!(
        property(sensor, "fov_axis"),
        &PropertyValue::String("smaller".into())
    );
    assert_close(
        transform(sensor),
        rows([
            [-1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, -5.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
    );
}

#[test]
fn quadrics_are_placed_as_pbrt_places_them() {
    let root = root(
        "WorldBegin\nShape \"disk\" \"float height\" 2 \"float radius\" 3\nShape \"cylinder\" \"float zmin\" -2 \"float zmax\" 4 \"float radius\" 0.5\nShape \"sphere\" \"float radius\" 2",
    );
    let shapes = nodes(&root, PluginClass::Shape);
    assert_close(
        transform(shapes[0]),
        rows([
            [3.0, 0.0, 0.0, 0.0],
            [0.0, 3.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 2.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
    );
    assert_eq!(
        property(shapes[1], "p0"),
        &PropertyValue::Point(DVec3::new(0.0, 0.0, -2.0))
    );
    assert_eq!(
        property(shapes[1], "p1"),
        &PropertyValue::Point(DVec3::new(0.0, 0.0, 4.0))
    );
    assert_eq!(property(shapes[2], "radius"), &PropertyValue::Float(2.0));
}

#[test]
fn lights_are_scaled_to_pbrts_luminance() {
    let root = root(
        "WorldBegin\nLightSource \"point\" \"rgb I\" [1 2 3] \"float scale\" 2\nLightSource \"point\" \"blackbody I\" 3000 \"float scale\" 5\nLightSource \"distant\" \"spectrum L\" [400 1 700 1]\n",
    );
    let emitters = nodes(&root, PluginClass::Emitter);
    assert_eq!(
        property(emitters[0], "intensity"),
        &PropertyValue::Rgb([2.0, 4.0, 6.0])
    );
    for (emitter, name, expected) in [
        (emitters[1], "intensity", 5.0),
        (emitters[2], "irradiance", 1.0),
    ] {
        let PropertyValue::Spectrum(SpectrumValue::Samples(samples)) = property(emitter, name)
        else {
            panic!("{:?}", property(emitter, name));
        };
        let found = luminance(samples);
        assert!((found - expected).abs() < 1e-9 * expected, "{found}");
    }
    assert!(
        error("WorldBegin\nLightSource \"point\" \"float power\" 10").contains("test.pbrt:2:21:")
    );
    assert!(
        error("WorldBegin\nLightSource \"point\" \"float illuminance\" 10")
            .contains("test.pbrt:2:21:")
    );
    // A uniform sky of illuminance E has the radiance E / π (times `scale`).
    let sky = super::read_pbrt_str(
        "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 2 3] \"float scale\" 2 \"float illuminance\" 6.283185307179586\n",
        Path::new("test.pbrt"),
    )
    .unwrap()
    .root;
    assert_eq!(
        property(nodes(&sky, PluginClass::Emitter)[0], "radiance"),
        &PropertyValue::Rgb([4.0, 8.0, 12.0])
    );
}

#[test]
fn materials_map_to_mitsubas_bsdfs() {
    let root = root(
        "WorldBegin\nMakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.04\nMakeNamedMaterial \"glass\" \"string type\" \"dielectric\" \"spectrum eta\" \"glass-BK7\"\nMaterial \"mix\" \"string materials\" [\"gold\" \"glass\"] \"float amount\" 0.25\nShape \"sphere\"\nMaterial \"interface\"\nShape \"sphere\"",
    );
    let shapes = nodes(&root, PluginClass::Shape);
    let bsdf = |shape: &PluginNode| shape.children[0].node.clone();
    let mix = bsdf(shapes[0]);
    assert_eq!(mix.plugin_type, "blendbsdf");
    assert_eq!(property(&mix, "weight"), &PropertyValue::Float(0.25));
    let gold = &mix.children[0].node;
    assert_eq!(gold.plugin_type, "twosided");
    let gold = &gold.children[0].node;
    assert_eq!(gold.plugin_type, "roughconductor");
    assert_eq!(
        property(gold, "material"),
        &PropertyValue::String("Au".into())
    );
    assert_eq!(property(gold, "alpha"), &PropertyValue::Float(0.2));
    let glass = &mix.children[1].node;
    assert_eq!(glass.plugin_type, "dielectric");
    assert!(matches!(
        property(glass, "int_ior"),
        PropertyValue::Spectrum(SpectrumValue::Samples(s)) if s.len() == 29
    ));
    assert_eq!(bsdf(shapes[1]).plugin_type, "null");
    assert!(
        error("WorldBegin\nNamedMaterial \"golf\"")
            .contains("test.pbrt:2:15: unknown material \"golf\"")
    );
}

#[test]
fn coated_materials_map_to_the_layered_bsdfs() {
    let root = root(
        "WorldBegin\nMaterial \"coateddiffuse\" \"rgb reflectance\" [0.2 0.4 0.6] \"float roughness\" 0.09 \"float eta\" 1.33 \"rgb albedo\" [0.5 0.5 0.5] \"float g\" 0.3 \"integer nsamples\" 2\nShape \"sphere\"\nMaterial \"coatedconductor\" \"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\" \"float conductor.uroughness\" 0.04 \"float conductor.vroughness\" 0.16 \"float thickness\" 0.2 \"integer maxdepth\" 20\nShape \"sphere\"",
    );
    let shapes = nodes(&root, PluginClass::Shape);
    let diffuse = &shapes[0].children[0].node;
    assert_eq!(diffuse.plugin_type, "coateddiffuse");
    assert!(
        (match property(diffuse, "alpha") {
            PropertyValue::Float(a) => *a,
            other => panic!("{other:?}"),
        } - 0.3)
            .abs()
            < 1e-12
    );
    assert_eq!(property(diffuse, "eta"), &PropertyValue::Float(1.33));
    assert_eq!(property(diffuse, "g"), &PropertyValue::Float(0.3));
    assert_eq!(property(diffuse, "samples"), &PropertyValue::Integer(2));
    assert_eq!(property(diffuse, "max_depth"), &PropertyValue::Integer(10));
    let conductor = &shapes[1].children[0].node;
    assert_eq!(conductor.plugin_type, "coatedconductor");
    assert_eq!(
        property(conductor, "material"),
        &PropertyValue::String("Au".into())
    );
    assert_eq!(
        property(conductor, "conductor_alpha_u"),
        &PropertyValue::Float(0.2)
    );
    assert_eq!(
        property(conductor, "conductor_alpha_v"),
        &PropertyValue::Float(0.4)
    );
    assert_eq!(
        property(conductor, "interface_alpha"),
        &PropertyValue::Float(0.0)
    );
    assert_eq!(
        property(conductor, "interface_eta"),
        &PropertyValue::Float(1.5)
    );
    assert_eq!(property(conductor, "thickness"), &PropertyValue::Float(0.2));
    assert!(
        error("WorldBegin\nMaterial \"coateddiffuse\" \"integer maxdepth\" 0")
            .contains("test.pbrt:2:26: Material \"coateddiffuse\": parameter \"integer maxdepth\" must be between 1 and 65536")
    );
}

#[test]
fn diffuse_transmission_maps_to_its_bsdf() {
    let root = root(
        "WorldBegin\nMaterial \"diffusetransmission\" \"rgb transmittance\" [0.5 0.5 0.5]\nShape \"sphere\"",
    );
    let bsdf = &nodes(&root, PluginClass::Shape)[0].children[0].node;
    assert_eq!(bsdf.plugin_type, "diffusetransmission");
    assert_eq!(property(bsdf, "reflectance"), &PropertyValue::Float(0.25));
    assert!(matches!(
        property(bsdf, "transmittance"),
        PropertyValue::Rgb(..)
    ));
    assert!(
        error("WorldBegin\nMaterial \"diffusetransmission\" \"float scale\" 2")
            .contains("test.pbrt:2:32: Material \"diffusetransmission\": parameter \"float scale\" is not read by Prism")
    );
}

#[test]
fn objects_become_shape_groups_and_instances() {
    let root = root(
        "WorldBegin\nObjectBegin \"pair\"\nShape \"sphere\"\nTranslate 2 0 0\nShape \"sphere\"\nObjectEnd\nTranslate 0 5 0\nObjectInstance \"pair\"\n",
    );
    let shapes = nodes(&root, PluginClass::Shape);
    assert_eq!(shapes.len(), 2);
    assert_eq!(shapes[0].plugin_type, "shapegroup");
    assert_eq!(shapes[0].children.len(), 2);
    assert_close(
        transform(&shapes[0].children[1].node),
        DMat4::from_translation(DVec3::X * 2.0),
    );
    assert_eq!(shapes[1].plugin_type, "instance");
    assert_close(
        transform(shapes[1]),
        DMat4::from_translation(DVec3::Y * 5.0),
    );
    assert!(std::sync::Arc::ptr_eq(
        &shapes[1].children[0].node,
        &root.children[2].node
    ));
    assert!(
        error("WorldBegin\nObjectInstance \"none\"").contains("test.pbrt:2:16: unknown object")
    );
}

#[test]
fn medium_interfaces_give_shapes_their_media() {
    let root = root(
        "WorldBegin\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [0.5 0.5 0.5] \"float g\" 0.3\nMediumInterface \"fog\" \"\"\nShape \"sphere\"\nMediumInterface \"fog\"\nShape \"sphere\"",
    );
    let shapes = nodes(&root, PluginClass::Shape);
    let media: Vec<_> = shapes[0]
        .children
        .iter()
        .filter_map(|c| c.name.as_deref())
        .collect();
    assert_eq!(media, ["interior"]);
    let fog = &shapes[0].children[1].node;
    assert_eq!(fog.plugin_type, "homogeneous");
    assert_eq!(fog.children[0].node.plugin_type, "hg");
    // The same medium on both sides is no boundary.
    assert_eq!(shapes[1].children.len(), 1);
}

#[test]
fn options_and_world_directives_keep_their_places() {
    assert!(error("Shape \"sphere\"").contains("test.pbrt:1:1: Shape must come after WorldBegin"));
    assert!(
        error("WorldBegin\nCamera \"perspective\"")
            .contains("test.pbrt:2:1: Camera must come before WorldBegin")
    );
    assert!(
        error("WorldBegin\n\"float radius\" 1").contains("test.pbrt:2:1: expected a directive")
    );
    assert!(
        error("Sampler \"zsobol\" \"integer pixelsamples\" [16")
            .contains("test.pbrt:1:41: this \"[\" is never closed")
    );
}

#[test]
fn textures_map_pbrts_coordinates() {
    let root = root(
        "WorldBegin\nTexture \"image\" \"spectrum\" \"imagemap\" \"string filename\" \"grid.png\" \"float uscale\" 2 \"float vdelta\" 0.25\nTexture \"checks\" \"spectrum\" \"checkerboard\" \"float vscale\" 4\nMakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"texture reflectance\" \"image\"\nMaterial \"diffuse\" \"texture reflectance\" \"checks\"\nShape \"sphere\"\nNamedMaterial \"a\"\nShape \"sphere\"",
    );
    let shapes = nodes(&root, PluginClass::Shape);
    let texture = |shape: &PluginNode| {
        let diffuse = shape.children[0].node.children[0].node.clone();
        let child = &diffuse.children[0];
        assert_eq!(child.name.as_deref(), Some("reflectance"));
        child.node.clone()
    };
    let to_uv = |node: &PluginNode| match property(node, "to_uv") {
        PropertyValue::Transform(m) => *m,
        other => panic!("{other:?}"),
    };
    // Checkerboard: (s, t) = (u, 4v), halved for Prism's squares of ½.
    let checks = texture(shapes[0]);
    assert_eq!(checks.plugin_type, "checkerboard");
    assert_close(to_uv(&checks), DMat4::from_scale(DVec3::new(0.5, 2.0, 1.0)));
    // Image: (s, t) = (2u, v + 0.25), looked up at (s, 1 − t).
    let image = texture(shapes[1]);
    assert_eq!(image.plugin_type, "bitmap");
    assert_eq!(property(&image, "raw"), &PropertyValue::Boolean(false));
    assert_close(
        to_uv(&image),
        rows([
            [2.0, 0.0, 0.0, 0.0],
            [0.0, -1.0, 0.0, 0.75],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
    );
}

#[test]
fn an_orthographic_camera_spans_the_shorter_axis() {
    // pbrt spans [−1, 1] along the shorter axis (y on a 2:1 film), Mitsuba [−1, 1] along x:
    // the camera is scaled by the aspect ratio.
    let wide = root(
        "Camera \"orthographic\"\nFilm \"rgb\" \"integer xresolution\" 20 \"integer yresolution\" 10\nWorldBegin\n",
    );
    let sensor = nodes(&wide, PluginClass::Sensor)[0];
    assert_eq!(sensor.plugin_type, "orthographic");
    assert_close(
        transform(sensor),
        DMat4::from_scale(DVec3::new(-2.0, 2.0, 1.0)),
    );
    // A tall film spans [−1, 1] along x in both.
    let tall = root(
        "Camera \"orthographic\"\nFilm \"rgb\" \"integer xresolution\" 10 \"integer yresolution\" 20\nWorldBegin\n",
    );
    let sensor = nodes(&tall, PluginClass::Sensor)[0];
    assert_close(
        transform(sensor),
        DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
    );
}

#[test]
fn the_samplers_seed_wins_over_the_option() {
    let seed = |text: &str| {
        let root = root(text);
        let sensor = nodes(&root, PluginClass::Sensor)[0];
        let sampler = &sensor.children[1].node;
        property(sampler, "seed").clone()
    };
    assert_eq!(
        seed("Option \"integer seed\" 7\nWorldBegin"),
        PropertyValue::Integer(7)
    );
    assert_eq!(
        seed("Option \"integer seed\" 7\nSampler \"independent\" \"integer seed\" 3\nWorldBegin"),
        PropertyValue::Integer(3)
    );
}

#[test]
fn scale_and_mix_textures_nest_their_operands() {
    let root = root(
        "WorldBegin\nTexture \"checks\" \"float\" \"checkerboard\"\nTexture \"amount\" \"float\" \"scale\" \"float tex\" 0.5 \"texture scale\" \"checks\"\nTexture \"blend\" \"spectrum\" \"mix\" \"rgb tex1\" [0.8 0.8 0.8] \"texture amount\" \"amount\"\nMaterial \"diffuse\" \"texture reflectance\" \"blend\"\nShape \"sphere\"",
    );
    let shape = nodes(&root, PluginClass::Shape)[0];
    let diffuse = &shape.children[0].node.children[0].node;
    let blend = &diffuse.children[0].node;
    assert_eq!(blend.plugin_type, "mix");
    assert_eq!(property(blend, "tex1"), &PropertyValue::Rgb([0.8; 3]));
    // pbrt's defaults: tex2 = 1.
    assert_eq!(property(blend, "tex2"), &PropertyValue::Float(1.0));
    let amount = &blend.children[0];
    assert_eq!(amount.name.as_deref(), Some("amount"));
    assert_eq!(amount.node.plugin_type, "scale");
    assert_eq!(property(&amount.node, "tex"), &PropertyValue::Float(0.5));
    assert_eq!(amount.node.children[0].name.as_deref(), Some("scale"));
    assert_eq!(amount.node.children[0].node.plugin_type, "checkerboard");
    // A float texture's operand names a float texture; a spectrum texture is not one.
    assert!(
        error("WorldBegin\nTexture \"c\" \"spectrum\" \"checkerboard\"\nTexture \"s\" \"float\" \"scale\" \"texture tex\" \"c\"")
            .contains("test.pbrt:3:29: Texture \"s\" \"float\" \"scale\": parameter \"texture tex\" names the unknown float texture \"c\"")
    );
}

#[test]
fn a_direction_mix_takes_its_direction_to_the_world() {
    let scene = root(
        "WorldBegin\nRotate 90 0 0 1\nScale 1 3 1\nTexture \"d\" \"spectrum\" \"directionmix\" \"rgb tex1\" [0.8 0.8 0.8] \"vector dir\" [0 2 0]\nMaterial \"diffuse\" \"texture reflectance\" \"d\"\nShape \"sphere\"",
    );
    let shape = nodes(&scene, PluginClass::Shape)[0];
    let mix = &shape.children[0].node.children[0].node.children[0].node;
    assert_eq!(mix.plugin_type, "directionmix");
    assert_eq!(property(mix, "tex1"), &PropertyValue::Rgb([0.8; 3]));
    // pbrt's defaults: tex2 = 1, dir = (0, 1, 0).
    assert_eq!(property(mix, "tex2"), &PropertyValue::Float(1.0));
    // (0, 2, 0) scaled to (0, 6, 0), then turned by 90° about z to (−6, 0, 0).
    let PropertyValue::Vector(dir) = property(mix, "dir") else {
        panic!("dir is a vector");
    };
    assert!(
        (*dir - DVec3::new(-6.0, 0.0, 0.0)).length() < 1e-12,
        "{dir}"
    );
    let default = root(
        "WorldBegin\nTexture \"d\" \"spectrum\" \"directionmix\"\nMaterial \"diffuse\" \"texture reflectance\" \"d\"\nShape \"sphere\"",
    );
    let shape = nodes(&default, PluginClass::Shape)[0];
    let mix = &shape.children[0].node.children[0].node.children[0].node;
    assert_eq!(property(mix, "dir"), &PropertyValue::Vector(DVec3::Y));
    assert!(
        error("WorldBegin\nTexture \"d\" \"float\" \"directionmix\" \"vector3 dir\" [0 0 0]")
            .contains("test.pbrt:2:36: Texture \"d\" \"float\" \"directionmix\": parameter \"vector3 dir\" has no direction")
    );
    assert!(
        error("WorldBegin\nScale 1 0 1\nTexture \"d\" \"float\" \"directionmix\"")
            .contains("test.pbrt:3:1: Texture \"d\" \"float\" \"directionmix\": \"dir\" (0, 1, 0) has no direction")
    );
}

#[test]
fn an_image_infinite_light_is_an_equal_area_map() {
    let root = root(
        "WorldBegin\nAttributeBegin\nRotate -90 1 0 0\nLightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" 3\nAttributeEnd",
    );
    let light = nodes(&root, PluginClass::Emitter)[0];
    assert_eq!(light.plugin_type, "equal_area_envmap");
    assert_eq!(
        property(light, "filename"),
        &PropertyValue::String("sky.exr".into())
    );
    assert_eq!(property(light, "scale"), &PropertyValue::Float(3.0));
    assert_close(
        transform(light),
        DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2),
    );
    assert!(
        error("WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.exr\" \"rgb L\" [1 1 1]")
            .contains("test.pbrt:2:52: LightSource \"infinite\": parameter \"rgb L\" cannot be given with \"filename\"")
    );
    assert!(
        error("WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.exr\" \"float illuminance\" 5")
            .contains("test.pbrt:2:52: LightSource \"infinite\": parameter \"float illuminance\" sets the light by a photometric quantity")
    );
}

#[test]
fn a_uniform_grid_is_a_heterogeneous_medium_with_an_empty_border() {
    let root = root(
        "WorldBegin\nTranslate 1 0 0\nMakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\" \"integer nx\" 2 \"float density\" [3 5] \"point3 p0\" [0 0 0] \"point3 p1\" [4 1 1] \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [0.5 3 4] \"float scale\" 2 \"float g\" 0.5\nMediumInterface \"smoke\" \"\"\nMaterial \"interface\"\nShape \"sphere\"",
    );
    let shape = nodes(&root, PluginClass::Shape)[0];
    let medium = &shape
        .children
        .iter()
        .find(|c| c.name.as_deref() == Some("interior"))
        .expect("an interior")
        .node;
    assert_eq!(medium.plugin_type, "heterogeneous");
    // σ_a = 2 · d · (1, 1, 1), σ_s = 2 · d · (0.5, 3, 4).
    assert_eq!(property(medium, "scale"), &PropertyValue::Float(2.0));
    assert_eq!(property(medium, "sigma_a"), &PropertyValue::Rgb([1.0; 3]));
    assert_eq!(
        property(medium, "sigma_s"),
        &PropertyValue::Rgb([0.5, 3.0, 4.0])
    );
    let grid = &medium.children[0];
    assert_eq!(grid.name.as_deref(), Some("density"));
    assert_eq!(grid.node.plugin_type, "inlinegrid");
    assert_eq!(medium.children[1].node.plugin_type, "hg");
    // 2 × 1 × 1 voxels in a 4 × 3 × 3 grid of zeros, over the box grown by a voxel (2 × 1 × 1).
    let PropertyValue::Numbers(values) = property(&grid.node, "values") else {
        panic!("no values");
    };
    let mut expected = vec![0.0; 36];
    expected[(3 + 1) * 4 + 1] = 3.0;
    expected[(3 + 1) * 4 + 2] = 5.0;
    assert_eq!(values, &expected);
    assert_eq!(
        property(&grid.node, "resolution_x"),
        &PropertyValue::Integer(4)
    );
    assert_close(
        transform(&grid.node),
        DMat4::from_translation(DVec3::new(1.0 - 2.0, -1.0, -1.0))
            * DMat4::from_scale(DVec3::new(8.0, 3.0, 3.0)),
    );
    let medium = |parameters: &str, expected: &str| {
        let message = error(&format!(
            "WorldBegin\nMakeNamedMedium \"m\" \"string type\" \"uniformgrid\" {parameters}"
        ));
        assert!(message.contains(expected), "{message}");
    };
    medium(
        "\"integer nx\" 2 \"float density\" [1 2 3]",
        "test.pbrt:2:64: MakeNamedMedium \"m\": parameter \"float density\" has 3 values, but nx × ny × nz = 2 × 1 × 1 = 2 are expected",
    );
    medium(
        "\"float density\" [1] \"float temperature\" [900]",
        "test.pbrt:2:69: MakeNamedMedium \"m\": parameter \"float temperature\" makes the medium glow",
    );
}

#[test]
fn bdpt_is_prisms_bdpt_with_one_more_depth() {
    let root = root("Integrator \"bdpt\" \"integer maxdepth\" 7\nWorldBegin\nShape \"sphere\"");
    let integrator = nodes(&root, PluginClass::Integrator)[0];
    assert_eq!(integrator.plugin_type, "bdpt");
    assert_eq!(
        property(integrator, "max_depth"),
        &PropertyValue::Integer(8)
    );
    assert!(
        error("Integrator \"bdpt\" \"string lightsampler\" \"uniform\"\nWorldBegin")
            .contains("chooses lights by power only")
    );
    assert!(
        error("Integrator \"bdpt\" \"bool visualizestrategies\" true\nWorldBegin")
            .contains("images of each strategy")
    );
}
