use super::*;

use glam::DVec4;

use crate::description::SpectrumValue;

fn read(xml: &str) -> Result<Arc<PluginNode>> {
    read_scene_str(xml, Path::new("/virtual/test.xml"), &[])
}

fn read_with(xml: &str, defines: &[(&str, &str)]) -> Result<Arc<PluginNode>> {
    let defines: Vec<(String, String)> = defines
        .iter()
        .map(|(n, v)| (n.to_string(), v.to_string()))
        .collect();
    read_scene_str(xml, Path::new("/virtual/test.xml"), &defines)
}

/// A v3 scene with `body` as its content.
fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">{body}</scene>")
}

fn error(xml: &str) -> Error {
    match read(xml) {
        Ok(_) => panic!("expected an error for {xml}"),
        Err(err) => err,
    }
}

/// Asserts that the error message or help contains every one of `parts`.
fn assert_error(err: &Error, parts: &[&str]) {
    let text = err.to_string();
    for part in parts {
        assert!(text.contains(part), "\"{part}\" missing from: {text}");
    }
}

fn property<'a>(node: &'a PluginNode, name: &str) -> &'a PropertyValue {
    match node.properties.iter().find(|p| p.name == name) {
        Some(p) => &p.value,
        None => panic!("no property {name} in {}", node.describe()),
    }
}

fn transform_of(ops: &str) -> Result<DMat4> {
    let root = read(&scene(&format!(
        "<shape type=\"sphere\"><transform name=\"to_world\">{ops}</transform></shape>"
    )))?;
    match property(&root.children[0].node, "to_world") {
        PropertyValue::Transform(m) => Ok(*m),
        other => panic!("not a transform: {other:?}"),
    }
}

fn assert_close(a: DVec3, b: DVec3) {
    assert!((a - b).length() < 1e-12, "{a} != {b}");
}

/// A scratch folder removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("prism-reader-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    fn write(&self, name: &str, text: &str) -> PathBuf {
        let path = self.0.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).unwrap();
        }
        std::fs::write(&path, text).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

// ---------------------------------------------------------------- properties

#[test]
fn reads_every_property_type() {
    let root = read(&scene(
        r##"<bsdf type="test">
            <float name="f" value=" -1.5e2 "/>
            <integer name="i" value="-42"/>
            <boolean name="b" value="TRUE"/>
            <boolean name="b2" value="false"/>
            <string name="s" value="a b, c"/>
            <rgb name="c3" value="0.1, 0.2 0.3"/>
            <rgb name="c1" value="0.5"/>
            <rgb name="hex" value="#ff0080"/>
            <spectrum name="u" value="0.25"/>
            <spectrum name="samples" value="400:0.1, 500:0.2,600:0.3"/>
            <point name="p" x="1" z="3"/>
            <point name="pv" value="1, 2, 3"/>
            <vector name="v" value="2"/>
        </bsdf>"##,
    ))
    .unwrap();
    let bsdf = &root.children[0].node;
    assert_eq!(property(bsdf, "f"), &PropertyValue::Float(-150.0));
    assert_eq!(property(bsdf, "i"), &PropertyValue::Integer(-42));
    assert_eq!(property(bsdf, "b"), &PropertyValue::Boolean(true));
    assert_eq!(property(bsdf, "b2"), &PropertyValue::Boolean(false));
    assert_eq!(property(bsdf, "s"), &PropertyValue::String("a b, c".into()));
    assert_eq!(property(bsdf, "c3"), &PropertyValue::Rgb([0.1, 0.2, 0.3]));
    assert_eq!(property(bsdf, "c1"), &PropertyValue::Rgb([0.5; 3]));
    let PropertyValue::Rgb([r, g, b]) = property(bsdf, "hex") else {
        panic!("hex rgb")
    };
    assert_eq!((*r, *g), (1.0, 0.0));
    assert!((b - 0.2158605).abs() < 1e-6, "sRGB-decoded 0x80 is {b}");
    assert_eq!(
        property(bsdf, "u"),
        &PropertyValue::Spectrum(SpectrumValue::Uniform(0.25))
    );
    assert_eq!(
        property(bsdf, "samples"),
        &PropertyValue::Spectrum(SpectrumValue::Samples(vec![
            (400.0, 0.1),
            (500.0, 0.2),
            (600.0, 0.3)
        ]))
    );
    assert_eq!(
        property(bsdf, "p"),
        &PropertyValue::Point(DVec3::new(1.0, 0.0, 3.0))
    );
    assert_eq!(
        property(bsdf, "pv"),
        &PropertyValue::Point(DVec3::new(1.0, 2.0, 3.0))
    );
    assert_eq!(
        property(bsdf, "v"),
        &PropertyValue::Vector(DVec3::splat(2.0))
    );
    // Properties keep document order.
    let names: Vec<&str> = bsdf.properties.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names[..3], ["f", "i", "b"]);
}

#[test]
fn rejects_bad_property_values() {
    let cases: &[(&str, &[&str])] = &[
        (
            r#"<float name="fov" value="abc"/>"#,
            &["<float name=\"fov\">", "\"abc\"", "finite number"],
        ),
        (r#"<float name="fov" value="nan"/>"#, &["finite number"]),
        (r#"<float name="fov" value="inf"/>"#, &["finite number"]),
        (r#"<float name="fov" value=""/>"#, &["finite number"]),
        (
            r#"<integer name="width" value="1.5"/>"#,
            &["<integer name=\"width\">", "not an integer"],
        ),
        (
            r#"<integer name="width" value="99999999999999999999"/>"#,
            &["not an integer"],
        ),
        (
            r#"<boolean name="flag" value="yes"/>"#,
            &["not a boolean", "\"true\""],
        ),
        (
            r#"<rgb name="c" value="1, 2"/>"#,
            &["has 2 numbers", "1 or 3"],
        ),
        (
            r#"<rgb name="c" value="1, x, 2"/>"#,
            &["\"x\"", "finite number"],
        ),
        (
            r##"<rgb name="c" value="#12345g"/>"##,
            &["not a colour", "#rrggbb"],
        ),
        (r#"<spectrum name="s" value="400:0.1"/>"#, &["at least two"]),
        (
            r#"<spectrum name="s" value="500:1, 400:2"/>"#,
            &["must increase"],
        ),
        (
            r#"<spectrum name="s" value="500:1, 500:2"/>"#,
            &["must increase"],
        ),
        (
            r#"<spectrum name="s" value="-5:1, 500:2"/>"#,
            &["not positive"],
        ),
        (
            r#"<spectrum name="s" value="400:a, 500:2"/>"#,
            &["wavelength:value pair"],
        ),
        (
            r#"<spectrum name="s" value="1" filename="a.spd"/>"#,
            &["either a value or a filename"],
        ),
        (r#"<spectrum name="s"/>"#, &["either a value or a filename"]),
        (r#"<point name="p" value="1" x="2"/>"#, &["mixes"]),
        (r#"<point name="p" value="1, 2"/>"#, &["1 or 3"]),
        (r#"<vector name="v" y="q"/>"#, &["\"q\"", "finite number"]),
        (r#"<float value="1"/>"#, &["missing the attribute \"name\""]),
        (r#"<float name="x"/>"#, &["missing the attribute \"value\""]),
        (
            r#"<float name="x" value="1" vlue="2"/>"#,
            &["unexpected attribute \"vlue\"", "did you mean \"value\""],
        ),
        (r#"<float name="" value="1"/>"#, &["empty name"]),
        (
            r#"<float name="x" value="1"><float name="y" value="2"/></float>"#,
            &["cannot contain elements"],
        ),
        (
            r#"<string name="x" value="1">text</string>"#,
            &["unexpected text \"text\""],
        ),
    ];
    for (body, parts) in cases {
        let err = error(&scene(&format!("<bsdf type=\"diffuse\">{body}</bsdf>")));
        assert_eq!(err.kind, prism_core::error::ErrorKind::Input);
        assert!(err.location.is_some(), "{err}");
        assert_error(&err, parts);
    }
}

#[test]
fn duplicate_parameter_names_quote_both_locations() {
    let err = error(
        "<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\">\n  <rgb name=\"reflectance\" value=\"1\"/>\n  <texture type=\"checkerboard\" name=\"reflectance\"/>\n</bsdf></scene>",
    );
    let location = err.location.clone().unwrap();
    assert_eq!((location.line, location.column), (4, 32));
    assert_error(&err, &["\"reflectance\" twice", "test.xml:3:8"]);
}

#[test]
fn reads_spectrum_files_and_reports_their_lines() {
    let dir = TempDir::new("spd");
    dir.write(
        "good.spd",
        "# wavelength value\n400 0.1\n\n500\t0.2 # comment\n600, 0.3\n",
    );
    dir.write("bad.spd", "400 0.1\n500 zero\n");
    let main = dir.write(
        "scene.xml",
        &scene(r#"<emitter type="area"><spectrum name="radiance" filename="good.spd"/></emitter>"#),
    );
    let root = read_scene_file(&main, &[]).unwrap();
    assert_eq!(
        property(&root.children[0].node, "radiance"),
        &PropertyValue::Spectrum(SpectrumValue::Samples(vec![
            (400.0, 0.1),
            (500.0, 0.2),
            (600.0, 0.3)
        ]))
    );

    let main = dir.write(
        "bad.xml",
        &scene(r#"<emitter type="area"><spectrum name="radiance" filename="bad.spd"/></emitter>"#),
    );
    let err = read_scene_file(&main, &[]).unwrap_err();
    let location = err.location.clone().unwrap();
    assert!(location.file.ends_with("bad.spd"), "{err}");
    assert_eq!((location.line, location.column), (2, 5));
    assert_error(&err, &["\"zero\""]);

    let main = dir.write(
        "missing.xml",
        &scene(r#"<emitter type="area"><spectrum name="radiance" filename="nope.spd"/></emitter>"#),
    );
    let err = read_scene_file(&main, &[]).unwrap_err();
    assert_error(&err, &["\"nope.spd\" not found", "looked up in"]);
    assert!(err.location.unwrap().file.ends_with("missing.xml"));
}

// ---------------------------------------------------------------- parameters

#[test]
fn defaults_and_defines_are_substituted() {
    let xml = scene(
        r#"<default name="res" value="1"/><default name="resx" value="64"/>
        <film type="hdrfilm"><integer name="width" value="$resx"/><string name="s" value="$res-\$res"/></film>"#,
    );
    let root = read(&xml).unwrap();
    let film = &root.children[0].node;
    assert_eq!(property(film, "width"), &PropertyValue::Integer(64));
    assert_eq!(property(film, "s"), &PropertyValue::String("1-$res".into()));

    let root = read_with(&xml, &[("resx", "32")]).unwrap();
    assert_eq!(
        property(&root.children[0].node, "width"),
        &PropertyValue::Integer(32)
    );
    // Substitution applies to any attribute, plugin types included.
    let root = read_with(&scene(r#"<integrator type="$i"/>"#), &[("i", "path")]).unwrap();
    assert_eq!(root.children[0].node.plugin_type, "path");
}

#[test]
fn undefined_parameters_and_unused_defines_are_errors() {
    let err = error(&scene(
        "<default name=\"spp\" value=\"4\"/>\n<sampler type=\"independent\"><integer name=\"sample_count\" value=\"$spq\"/></sampler>",
    ));
    assert_error(
        &err,
        &[
            "\"$spq\"",
            "-D spq=",
            "<default name=\"spq\"",
            "did you mean \"$spp\"",
        ],
    );
    assert_eq!(err.location.unwrap().line, 2);

    // A parameter exists only after its <default>.
    let err = error(&scene(
        r#"<film type="hdrfilm"><integer name="width" value="$w"/></film><default name="w" value="1"/>"#,
    ));
    assert_error(&err, &["\"$w\""]);

    let err = read_with(&scene(r#"<default name="spp" value="4"/>"#), &[("sp", "1")]).unwrap_err();
    assert!(err.location.is_none());
    assert_error(&err, &["-D sp=1", "never declares or uses", "spp"]);
    // A define that only overrides a <default> counts as used.
    read_with(
        &scene(r#"<default name="spp" value="4"/>"#),
        &[("spp", "1")],
    )
    .unwrap();
}

// ---------------------------------------------------------------- references

#[test]
fn references_share_the_declared_node() {
    let root = read(&scene(
        r#"<shape type="sphere"><ref id="mat" name="bsdf"/></shape>
        <bsdf type="diffuse" id="mat"/>
        <shape type="cube"><ref id="mat"/></shape>
        <bsdf type="twosided" id="outer"><bsdf type="diffuse" id="inner"/></bsdf>
        <shape type="disk"><ref id="inner"/></shape>"#,
    ))
    .unwrap();
    let first = &root.children[0].node.children[0];
    assert_eq!(first.name.as_deref(), Some("bsdf"));
    assert_eq!(first.node.id.as_deref(), Some("mat"));
    assert!(Arc::ptr_eq(&first.node, &root.children[1].node));
    assert!(Arc::ptr_eq(
        &first.node,
        &root.children[2].node.children[0].node
    ));
    assert!(Arc::ptr_eq(
        &root.children[3].node.children[0].node,
        &root.children[4].node.children[0].node
    ));
    assert_eq!(first.location.line, 1);
}

#[test]
fn reference_errors() {
    let err = error(&scene(
        r#"<bsdf type="diffuse" id="FloorBSDF"/><shape type="cube"><ref id="FloorBDSF"/></shape>"#,
    ));
    assert_error(
        &err,
        &[
            "no object has the id \"FloorBDSF\"",
            "did you mean \"FloorBSDF\"",
        ],
    );

    let err = error(
        "<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"conductor\" id=\"a\"/></scene>",
    );
    let location = err.location.clone().unwrap();
    assert_eq!((location.line, location.column), (3, 24));
    assert_error(&err, &["duplicate id \"a\"", "test.xml:2:22"]);

    let err = error(&scene(
        r#"<bsdf type="twosided" id="outer"><bsdf type="mask"><ref id="outer"/></bsdf></bsdf>"#,
    ));
    assert_error(
        &err,
        &["makes bsdf \"twosided\" (id \"outer\") contain itself"],
    );

    let err = error(&scene(
        r#"<texture type="a" id="x"><ref id="y"/></texture><texture type="b" id="y"><ref id="x"/></texture>"#,
    ));
    assert_error(&err, &["contain itself"]);

    let err = error(&scene(r#"<shape type="cube"><ref name="bsdf"/></shape>"#));
    assert_error(&err, &["missing the attribute \"id\""]);
}

/// Ids as Mitsuba 3.9.1 reads them (each case checked with Mitsuba): in a version 0.x file as in
/// a 3.x one, declared in an included file, before or after the reference, nested anywhere;
/// matched exactly (no renaming in old files, no trimming, letter case counts); a `name` is not
/// an id, and properties take none.
#[test]
fn ids_resolve_as_in_mitsuba() {
    let include = TempDir::new("ids-include");
    include.write(
        "materials.xml",
        r#"<scene version="0.5.0"><bsdf type="diffuse" id="fromInclude"/></scene>"#,
    );
    let main = include.write(
        "main.xml",
        r#"<scene version="0.5.0">
            <shape type="sphere"><ref id="laterMat"/></shape>
            <shape type="sphere"><ref name="bsdf" id="fromInclude"/></shape>
            <include filename="materials.xml"/>
            <shape type="cube"><bsdf type="twosided" id="outerMat"><bsdf type="diffuse" id="laterMat"/></bsdf></shape>
        </scene>"#,
    );
    let root = read_scene_file(&main, &[]).unwrap();
    let shape = |i: usize| &root.children[i].node.children[0].node;
    assert_eq!(shape(0).id.as_deref(), Some("laterMat"));
    assert_eq!(shape(1).id.as_deref(), Some("fromInclude"));
    assert!(Arc::ptr_eq(shape(0), &shape(3).children[0].node));

    for (body, missing) in [
        (
            r#"<bsdf type="diffuse" id="myMat"/><shape type="cube"><ref id="my_mat"/></shape>"#,
            "my_mat",
        ),
        (
            r#"<bsdf type="diffuse" id="m "/><shape type="cube"><ref id="m"/></shape>"#,
            "m",
        ),
        (
            r#"<bsdf type="diffuse" id="m"/><shape type="cube"><ref id="M"/></shape>"#,
            "M",
        ),
        (
            r#"<bsdf type="diffuse" name="m"/><shape type="cube"><ref id="m"/></shape>"#,
            "m",
        ),
    ] {
        let xml = format!("<scene version=\"0.5.0\">{body}</scene>");
        assert_error(
            &error(&xml),
            &[&format!("no object has the id \"{missing}\"")],
        );
    }
    assert_error(
        &error(&scene(r#"<rgb name="x" value="0.5" id="c"/>"#)),
        &["unexpected attribute \"id\""],
    );
}

#[test]
fn aliases_name_earlier_objects() {
    let root = read(&scene(
        r#"<bsdf type="diffuse" id="a"/><alias id="a" as="b"/><shape type="cube"><ref id="b"/></shape>"#,
    ))
    .unwrap();
    assert!(Arc::ptr_eq(
        &root.children[0].node,
        &root.children[1].node.children[0].node
    ));
    assert_error(
        &error(&scene(r#"<alias id="a" as="b"/>"#)),
        &["no object has the id \"a\""],
    );
}

// ---------------------------------------------------------------- transforms

#[test]
fn transform_operations_compose_left_to_right() {
    let p = DVec3::new(1.0, 1.0, 1.0);
    let scale_then_translate = transform_of(r#"<scale value="2"/><translate x="1"/>"#).unwrap();
    assert_close(
        scale_then_translate.transform_point3(p),
        DVec3::new(3.0, 2.0, 2.0),
    );
    let translate_then_scale =
        transform_of(r#"<translate value="1, 0, 0"/><scale x="2" y="2" z="2"/>"#).unwrap();
    assert_close(
        translate_then_scale.transform_point3(p),
        DVec3::new(4.0, 2.0, 2.0),
    );
    // Missing scale components are 1, missing translate components 0.
    let m = transform_of(r#"<scale y="3"/><translate z="5"/>"#).unwrap();
    assert_close(m.transform_point3(p), DVec3::new(1.0, 3.0, 6.0));
}

#[test]
fn rotate_is_right_handed_in_degrees() {
    let m = transform_of(r#"<rotate z="1" angle="90"/>"#).unwrap();
    assert_close(m.transform_vector3(DVec3::X), DVec3::Y);
    assert_error(
        &transform_of(r#"<rotate angle="90"/>"#).unwrap_err(),
        &["zero rotation axis"],
    );
    assert_error(
        &transform_of(r#"<rotate x="1"/>"#).unwrap_err(),
        &["missing the attribute \"angle\""],
    );
}

/// About an axis of length 5, Mitsuba 3's rotation also scales by 5 across the axis; Mitsuba
/// 0.6's normalises the axis. Both warn, at the `<rotate>`.
#[test]
fn rotate_reads_a_long_axis_as_the_file_version_does() {
    let rotate = r#"<shape type="sphere"><transform name="to_world"><rotate value="0, 0, 5" angle="90"/></transform></shape>"#;
    for (version, image_of_x) in [("3.0.0", DVec3::Y * 5.0), ("0.6.0", DVec3::Y)] {
        let xml = format!("<scene version=\"{version}\">{rotate}</scene>");
        let document = read_scene_str_document(&xml, Path::new("/virtual/test.xml"), &[]).unwrap();
        let PropertyValue::Transform(m) = property(&document.root.children[0].node, "to_world")
        else {
            panic!("not a transform");
        };
        assert_close(m.transform_vector3(DVec3::X), image_of_x);
        assert_eq!(document.warnings.len(), 1);
        let warning = &document.warnings[0];
        assert_eq!((warning.location.line, warning.location.column), (1, 72));
        assert!(
            warning
                .message
                .starts_with("<rotate> has an axis of length 5.0000, not 1"),
            "{}",
            warning.message
        );
    }
}

#[test]
fn matrices_are_row_major() {
    let m = transform_of(r#"<matrix value="1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1"/>"#).unwrap();
    assert_eq!(m.w_axis, DVec4::new(5.0, 6.0, 7.0, 1.0));
    let m = transform_of(r#"<matrix value="0 -1 0, 1 0 0, 0 0 1"/>"#).unwrap();
    assert_close(m.transform_vector3(DVec3::X), DVec3::Y);
    assert_eq!(m.w_axis, DVec4::W);
    assert_error(
        &transform_of(r#"<matrix value="1 2 3"/>"#).unwrap_err(),
        &["has 3 numbers", "16 (or 9)"],
    );
    assert_error(
        &transform_of(
            r#"<matrix value="1e300 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1"/><scale value="1e300"/>"#,
        )
        .unwrap_err(),
        &["non-finite"],
    );
}

/// Mitsuba 3 drops a projective last row, with a warning; a 0.6 file keeps it (for the shape to
/// refuse).
#[test]
fn a_projective_matrix_row_is_dropped_in_mitsuba_3_files() {
    let matrix = r#"<shape type="sphere"><transform name="to_world"><matrix value="2 0 0 1  0 1 0 0  0 0 1 0  0.5 0 0 3"/></transform></shape>"#;
    for (version, last_row, warnings) in [
        ("3.0.0", DVec4::W, 1),
        ("0.6.0", DVec4::new(0.5, 0.0, 0.0, 3.0), 0),
    ] {
        let xml = format!("<scene version=\"{version}\">{matrix}</scene>");
        let document = read_scene_str_document(&xml, Path::new("/virtual/test.xml"), &[]).unwrap();
        let PropertyValue::Transform(m) = property(&document.root.children[0].node, "to_world")
        else {
            panic!("not a transform");
        };
        assert_eq!(m.row(3), last_row);
        assert_eq!(m.row(0), DVec4::new(2.0, 0.0, 0.0, 1.0));
        assert_eq!(document.warnings.len(), warnings);
    }
}

#[test]
fn lookat_builds_mitsuba_columns() {
    let m = transform_of(r#"<lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/>"#).unwrap();
    assert_eq!(m.z_axis, DVec4::new(0.0, 0.0, -1.0, 0.0)); // dir
    assert_eq!(m.x_axis, DVec4::new(-1.0, 0.0, 0.0, 0.0)); // left = up x dir
    assert_eq!(m.y_axis, DVec4::new(0.0, 1.0, 0.0, 0.0)); // dir x left
    assert_eq!(m.w_axis, DVec4::new(0.0, 0.0, 5.0, 1.0)); // origin
    // Without up, one is generated.
    let m = transform_of(r#"<lookat origin="1, 2, 3" target="1, 2, 4"/>"#).unwrap();
    assert!(m.is_finite());
    assert_error(
        &transform_of(r#"<lookat origin="1, 2, 3" target="1, 2, 3"/>"#).unwrap_err(),
        &["origin and target coincide"],
    );
    assert_error(
        &transform_of(r#"<lookat origin="0, 0, 0" target="0, 1, 0" up="0, 2, 0"/>"#).unwrap_err(),
        &["parallel"],
    );
    assert_error(
        &transform_of(r#"<lookat origin="0, 0" target="0, 1, 0"/>"#).unwrap_err(),
        &["has 2 numbers"],
    );
}

#[test]
fn transform_structure_errors() {
    assert_error(
        &error(&scene(r#"<shape type="cube"><translate x="1"/></shape>"#)),
        &["<translate> can only appear inside a <transform>"],
    );
    assert_error(
        &transform_of(r#"<float name="x" value="1"/>"#).unwrap_err(),
        &["unexpected <float> inside a <transform>"],
    );
    assert_error(
        &transform_of(r#"<translate/>"#).unwrap_err(),
        &["no x, y, z or value"],
    );
    assert_error(
        &transform_of(r#"<lookAt origin="0,0,1" target="0,0,0"/>"#).unwrap_err(),
        &["did you mean <lookat>"],
    );
}

// ---------------------------------------------------------------- versions

#[test]
fn old_scenes_are_upgraded() {
    let root = read(
        r#"<scene version="0.6.0">
            <default name="sampleCount" value="8"/>
            <sensor type="perspective">
                <string name="fovAxis" value="x"/>
                <transform name="toWorld"><lookAt origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
                <sampler type="independent"><integer name="sampleCount" value="$sampleCount"/></sampler>
            </sensor>
            <bsdf type="dielectric"><float name="intIOR" value="1.5"/></bsdf>
            <bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.2"/></bsdf>
            <texture type="bitmap"><float name="uoffset" value="0.5"/><float name="uscale" value="2"/></texture>
        </scene>"#,
    )
    .unwrap();
    let sensor = &root.children[0].node;
    assert_eq!(
        property(sensor, "fov_axis"),
        &PropertyValue::String("x".into())
    );
    assert!(matches!(
        property(sensor, "to_world"),
        PropertyValue::Transform(_)
    ));
    assert_eq!(
        property(&sensor.children[0].node, "sample_count"),
        &PropertyValue::Integer(8)
    );
    assert_eq!(
        property(&root.children[1].node, "int_ior"),
        &PropertyValue::Float(1.5)
    );
    assert_eq!(
        property(&root.children[2].node, "reflectance"),
        &PropertyValue::Rgb([0.2; 3])
    );
    let texture = &root.children[3].node;
    assert_eq!(texture.properties.len(), 1);
    let PropertyValue::Transform(to_uv) = property(texture, "to_uv") else {
        panic!("to_uv")
    };
    // Translate by (0.5, 0), then scale u by 2.
    assert_close(
        to_uv.transform_point3(DVec3::ZERO),
        DVec3::new(1.0, 0.0, 0.0),
    );
    assert_close(to_uv.transform_point3(DVec3::X), DVec3::new(3.0, 0.0, 0.0));

    // Version 3 files are not renamed.
    let root = read(&scene(
        r#"<bsdf type="dielectric"><float name="intIOR" value="1.5"/></bsdf>"#,
    ))
    .unwrap();
    assert_eq!(root.children[0].node.properties[0].name, "intIOR");
}

#[test]
fn root_and_version_errors() {
    assert_error(&error(r#"<scene/>"#), &["no version attribute"]);
    assert_error(
        &error(r#"<scene version="3.0"/>"#),
        &["could not read the version \"3.0\""],
    );
    assert_error(
        &error(r#"<scene version="x.y.z"/>"#),
        &["could not read the version"],
    );
    assert_error(
        &error(r#"<bsdf version="3.0.0" type="diffuse"/>"#),
        &["root element is <bsdf>"],
    );
    assert_error(
        &error(&scene(r#"<scene version="3.0.0"/>"#)),
        &["<scene> can only be the root element"],
    );
    assert_error(
        &error(r#"<scene version="3.0.0" type="scene"/>"#),
        &["unexpected attribute \"type\""],
    );
    let root = read(r#"<scene version="3.0.0" id="main"/>"#).unwrap();
    assert_eq!(
        (root.class, root.plugin_type.as_str()),
        (PluginClass::Scene, "scene")
    );
    assert_eq!(root.id.as_deref(), Some("main"));
}

// ---------------------------------------------------------------- structure

#[test]
fn structure_errors() {
    assert_error(
        &error(&scene(
            r#"<bsdf type="diffuse"><flot name="x" value="1"/></bsdf>"#,
        )),
        &["unknown element <flot>", "did you mean <float>"],
    );
    assert_error(
        &error(&scene(r#"<bsdf type="diffuse" kind="x"/>"#)),
        &["unexpected attribute \"kind\"", "type, id, name"],
    );
    assert_error(
        &error(&scene(r#"<bsdf id="x"/>"#)),
        &["missing the attribute \"type\""],
    );
    assert_error(&error(&scene(r#"<bsdf type=""/>"#)), &["empty type"]);
    assert_error(
        &error(&scene("hello")),
        &["unexpected text \"hello\" inside <scene>"],
    );
    assert_error(
        &error(&scene(r#"<x:bsdf xmlns:x="urn:x" type="a"/>"#)),
        &["namespaced element"],
    );
    // Comments and processing instructions are fine.
    read(&scene("<!-- comment --><?pi data?>")).unwrap();
}

#[test]
fn comments_may_hold_double_hyphens_as_in_mitsuba() {
    read(&scene("<!-- a -- b --->\n<!---- rule ---->")).unwrap();
    // Blanking the hyphens keeps positions: the error after the comments is where it was.
    let err = error(&scene(
        "<!-- é -- ü\n -- --->\n    <shape type=\"sphere\"><float name=\"radius\" value=\"x\"/></shape>",
    ));
    let location = err.location.clone().unwrap();
    assert_eq!((location.line, location.column), (3, 47), "{err}");
}

#[test]
fn nested_plugins_keep_order_names_and_classes() {
    let root = read(&scene(
        r#"<shape type="sphere">
            <bsdf type="diffuse" name="b"/>
            <emitter type="area"><spectrum type="blackbody" name="radiance"><float name="temperature" value="3000"/></spectrum></emitter>
            <medium type="homogeneous" name="interior"/>
        </shape>"#,
    ))
    .unwrap();
    let shape = &root.children[0].node;
    let classes: Vec<PluginClass> = shape.children.iter().map(|c| c.node.class).collect();
    assert_eq!(
        classes,
        [PluginClass::Bsdf, PluginClass::Emitter, PluginClass::Medium]
    );
    assert_eq!(shape.children[0].name.as_deref(), Some("b"));
    assert_eq!(shape.children[1].name, None);
    let spectrum = &shape.children[1].node.children[0];
    assert_eq!(spectrum.node.class, PluginClass::Spectrum);
    assert_eq!(spectrum.name.as_deref(), Some("radiance"));
    assert_eq!(spectrum.node.plugin_type, "blackbody");
}

#[test]
fn locations_are_exact() {
    let xml = "<scene version=\"3.0.0\">\n\
               \t<bsdf type=\"diffuse\" id=\"white\">\n\
               \t\t<rgb name=\"reflectance\" value=\"0.5\"/>\n\
               \t</bsdf>\n\
               \t<shape type=\"cube\">\n\
               \t\t<float name=\"radius\"   value=\"abc\"/>\n\
               \t</shape>\n\
               </scene>";
    let err = error(xml);
    let location = err.location.clone().unwrap();
    assert_eq!(location.file.as_ref(), Path::new("/virtual/test.xml"));
    assert_eq!((location.line, location.column), (6, 26));
    assert_error(&err, &["<float name=\"radius\">", "value=\"abc\""]);

    let fixed = xml.replace("abc", "1");
    let root = read(&fixed).unwrap();
    assert_eq!((root.location.line, root.location.column), (1, 1));
    let bsdf = &root.children[0];
    assert_eq!((bsdf.location.line, bsdf.location.column), (2, 2));
    assert_eq!((bsdf.node.location.line, bsdf.node.location.column), (2, 2));
    let rgb = &bsdf.node.properties[0];
    assert_eq!((rgb.location.line, rgb.location.column), (3, 3));
    let radius = &root.children[1].node.properties[0];
    assert_eq!((radius.location.line, radius.location.column), (6, 3));
}

#[test]
fn malformed_xml_reports_the_parser_position() {
    let err = error("<scene version=\"3.0.0\">\n  <bsdf type=\"diffuse\">\n</scene>");
    let location = err.location.clone().unwrap();
    assert_eq!(location.line, 3);
    assert_error(&err, &["malformed XML"]);
    assert!(!err.message.contains(" at 3:"), "{err}");

    let err = error("<scene version=\"3.0.0\"><bsdf type=\"a\" type=\"b\"/></scene>");
    assert_error(&err, &["malformed XML"]);
    assert_error(&error(""), &["malformed XML"]);
    assert_error(
        &error("<!DOCTYPE x [<!ENTITY a \"b\">]><scene/>"),
        &["malformed XML"],
    );
}

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    let depth = 5000;
    let xml = format!(
        "<scene version=\"3.0.0\">{}{}</scene>",
        "<bsdf type=\"mask\">".repeat(depth),
        "</bsdf>".repeat(depth)
    );
    assert_error(&error(&xml), &["nested more than 256 deep"]);
    // Exactly at the limit is fine.
    let xml = format!(
        "<scene version=\"3.0.0\">{}{}</scene>",
        "<bsdf type=\"mask\">".repeat(MAX_NESTING),
        "</bsdf>".repeat(MAX_NESTING)
    );
    read(&xml).unwrap();
}

// ---------------------------------------------------------------- files

#[test]
fn includes_are_spliced_in_place() {
    let dir = TempDir::new("include");
    dir.write(
        "parts/materials.xml",
        r#"<scene version="0.5.0"><bsdf type="dielectric" id="glass"><float name="intIOR" value="1.5"/></bsdf>
<include filename="more.xml"/></scene>"#,
    );
    dir.write(
        "parts/more.xml",
        "<scene>\n<default name=\"w\" value=\"7\"/>\n<bsdf type=\"diffuse\" id=\"white\"/></scene>",
    );
    let main = dir.write(
        "scene.xml",
        &scene(
            r#"<shape type="cube"><ref id="glass"/></shape><include filename="parts/materials.xml"/><film type="hdrfilm"><integer name="width" value="$w"/></film>"#,
        ),
    );
    let root = read_scene_file(&main, &[]).unwrap();
    let ids: Vec<Option<&str>> = root.children.iter().map(|c| c.node.id.as_deref()).collect();
    assert_eq!(ids, [None, Some("glass"), Some("white"), None]);
    let glass = &root.children[1].node;
    assert!(Arc::ptr_eq(glass, &root.children[0].node.children[0].node));
    // The included 0.5 file is upgraded; its location is its own file.
    assert_eq!(property(glass, "int_ior"), &PropertyValue::Float(1.5));
    assert!(glass.location.file.ends_with("parts/materials.xml"));
    let white = &root.children[2].node;
    assert!(white.location.file.ends_with("more.xml"));
    assert_eq!(white.location.line, 3);
    assert_eq!(
        property(&root.children[3].node, "width"),
        &PropertyValue::Integer(7)
    );
    // Search paths: the holding file's folder, then the main folder.
    assert_eq!(
        white.search_paths.as_slice(),
        [dir.0.join("parts"), dir.0.clone()]
    );
}

#[test]
fn include_errors() {
    let dir = TempDir::new("include-errors");
    dir.write(
        "broken.xml",
        "<scene version=\"3.0.0\">\n<bsdf type=\"a\">\n</scene>",
    );
    dir.write(
        "bad-value.xml",
        "<scene version=\"3.0.0\">\n\n  <bsdf type=\"diffuse\"><float name=\"x\" value=\"y\"/></bsdf></scene>",
    );
    dir.write(
        "self.xml",
        r#"<scene version="3.0.0"><include filename="self.xml"/></scene>"#,
    );
    dir.write("plugin.xml", r#"<bsdf version="3.0.0" type="diffuse"/>"#);

    let check =
        |body: &str| read_scene_file(&dir.write("main.xml", &scene(body)), &[]).unwrap_err();

    let err = check(r#"<include filename="missing.xml"/>"#);
    assert_error(&err, &["\"missing.xml\" not found"]);
    assert!(err.location.unwrap().file.ends_with("main.xml"));

    let err = check(r#"<include filename="broken.xml"/>"#);
    assert!(err.location.clone().unwrap().file.ends_with("main.xml"));
    assert_error(&err, &["could not read the included file", "broken.xml:3:"]);

    let err = check(r#"<include filename="bad-value.xml"/>"#);
    let location = err.location.unwrap();
    assert!(location.file.ends_with("bad-value.xml"));
    assert_eq!(location.line, 3);

    let err = check(r#"<include filename="self.xml"/>"#);
    assert_error(&err, &["nested more than 15 deep"]);

    let err = check(r#"<include filename="plugin.xml"/>"#);
    assert_error(&err, &["must be <scene>"]);
}

#[test]
fn path_elements_extend_the_search_paths() {
    let dir = TempDir::new("path");
    std::fs::create_dir_all(dir.0.join("textures")).unwrap();
    std::fs::create_dir_all(dir.0.join("meshes")).unwrap();
    let main = dir.write(
        "scene.xml",
        &scene(
            r#"<bsdf type="a"/><path value="textures"/><path value="meshes"/><path value="textures"/><bsdf type="b"/>"#,
        ),
    );
    let root = read_scene_file(&main, &[]).unwrap();
    assert_eq!(
        root.children[0].node.search_paths.as_slice(),
        std::slice::from_ref(&dir.0)
    );
    assert_eq!(
        root.children[1].node.search_paths.as_slice(),
        [dir.0.join("textures"), dir.0.join("meshes"), dir.0.clone()]
    );
    let err = read_scene_file(
        &dir.write("missing.xml", &scene(r#"<path value="nowhere"/>"#)),
        &[],
    )
    .unwrap_err();
    assert_error(&err, &["folder \"nowhere\" not found"]);
    let err = read_scene_file(
        &dir.write(
            "nested.xml",
            &scene(r#"<shape type="a"><path value="meshes"/></shape>"#),
        ),
        &[],
    )
    .unwrap_err();
    assert_error(&err, &["directly inside the root"]);
}

#[test]
fn missing_scene_file_is_reported() {
    let err = read_scene_file(Path::new("/nonexistent/scene.xml"), &[]).unwrap_err();
    assert_error(&err, &["not found"]);
}

/// The bundled public scenes read, and Bitterli's Cornell box reads as written.
#[test]
fn reads_the_bundled_public_scenes() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    for name in ["bitterli-cornell-box", "veach-bidir", "veach-mis"] {
        let path = folder.join(name).join("scene.xml");
        read_scene_file(&path, &[]).unwrap_or_else(|err| panic!("{err}"));
    }
    let path = folder.join("bitterli-cornell-box/scene.xml");
    let root = read_scene_file(&path, &[]).unwrap();
    let of_class = |class| {
        root.children
            .iter()
            .filter(move |c| c.node.class == class)
            .map(|c| &c.node)
    };
    let sensor = of_class(PluginClass::Sensor).next().unwrap();
    assert_eq!(property(sensor, "fov"), &PropertyValue::Float(19.5));
    let film = &sensor
        .children
        .iter()
        .find(|c| c.node.class == PluginClass::Film)
        .unwrap()
        .node;
    assert_eq!(property(film, "width"), &PropertyValue::Integer(1024));
    let bsdfs: Vec<_> = of_class(PluginClass::Bsdf).collect();
    assert_eq!(bsdfs.len(), 8);
    assert!(bsdfs.iter().all(|b| b.id.is_some()));
    let light = of_class(PluginClass::Shape)
        .find(|s| s.id.as_deref() == Some("Light"))
        .unwrap();
    let emitter = &light
        .children
        .iter()
        .find(|c| c.node.class == PluginClass::Emitter)
        .unwrap()
        .node;
    assert_eq!(
        property(emitter, "radiance"),
        &PropertyValue::Rgb([17.0, 12.0, 4.0])
    );
    let light_bsdf = &light
        .children
        .iter()
        .find(|c| c.node.class == PluginClass::Bsdf)
        .unwrap()
        .node;
    let light_bsdf_by_id = bsdfs
        .iter()
        .find(|b| b.id.as_deref() == Some("LightBSDF"))
        .unwrap();
    assert!(Arc::ptr_eq(light_bsdf, light_bsdf_by_id));

    let root = read_scene_file(&path, &[("resx".to_string(), "64".to_string())]).unwrap();
    let sensor = &root
        .children
        .iter()
        .find(|c| c.node.class == PluginClass::Sensor)
        .unwrap()
        .node;
    let film = &sensor
        .children
        .iter()
        .find(|c| c.node.class == PluginClass::Film)
        .unwrap()
        .node;
    assert_eq!(property(film, "width"), &PropertyValue::Integer(64));
    assert_eq!(property(film, "height"), &PropertyValue::Integer(1024));
}

#[test]
fn hostile_inputs_do_not_panic() {
    let inputs = [
        "<scene version=\"3.0.0\"><float name=\"x\" value=\"1\"/></scene>",
        "<scene version=\"4294967296.0.0\"/>",
        "<scene version=\"1.0.0\"><bsdf type=\"diffuse\"><float name=\"\" value=\"1\"/></bsdf></scene>",
        "<scene version=\"3.0.0\"><default name=\"a\" value=\"$\"/></scene>",
        "<scene version=\"3.0.0\"><shape type=\"x\"><transform name=\"t\"><rotate value=\"1e-320 0 0\" angle=\"1\"/></transform></shape></scene>",
        "<scene version=\"3.0.0\"><rgb name=\"c\" value=\"#ééééé\"/></scene>",
        "<scene version=\"3.0.0\"><spectrum name=\"s\" value=\":\"/></scene>",
        "\u{feff}<scene version=\"3.0.0\">é<bsdf/></scene>",
        "<scene version=\"3.0.0\"><ref id=\"\"/></scene>",
        "<scene version=\"3.0.0\" id=\"r\"><bsdf type=\"a\"><ref id=\"r\"/></bsdf></scene>",
    ];
    for input in inputs {
        let _ = read(input);
    }
    // Exponential growth through parameters is bounded.
    let mut body = String::from("<default name=\"p0\" value=\"xxxxxxxxxxxxxxxx\"/>");
    for i in 1..40 {
        let prev = i - 1;
        body += &format!("<default name=\"p{i}\" value=\"$p{prev}$p{prev}\"/>");
    }
    assert_error(&error(&scene(&body)), &["longer than 16 MiB"]);
}

/// Random edits of a small scene never make the reader panic (a cheap stand-in for fuzzing).
#[test]
fn mutated_scenes_do_not_panic() {
    let base = r#"<scene version="3.0.0">
    <default name="spp" value="4"/>
    <sensor type="perspective"><float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/><rotate y="1" angle="30"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>
    <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.5"/></bsdf>
    <shape type="sphere"><point name="center" value="0 1 0"/><ref id="white"/>
        <emitter type="area"><spectrum name="radiance" value="400:1, 700:2"/></emitter></shape>
</scene>"#;
    read(base).unwrap();
    let pieces = [
        "<",
        ">",
        "/",
        "\"",
        "$",
        "$spp",
        "<ref id=\"whit\"/>",
        " name=\"x\"",
        "</bsdf>",
        "<bsdf type=\"a\">",
        "#",
        ":",
        "1e999",
        "-",
        "\u{e9}",
        "<!--",
        "&amp;",
        "\\$",
        "<include filename=\"/nonexistent.xml\"/>",
        "<path value=\".\"/>",
        "0",
        ",",
    ];
    let mut state: u64 = 0x853c_49e6_748f_ea9b;
    let mut next = |n: usize| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 33) as usize) % n.max(1)
    };
    for _ in 0..3000 {
        let mut text = base.to_string();
        for _ in 0..1 + next(3) {
            let mut at = next(text.len() + 1);
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            if next(3) == 0 {
                let mut end = (at + next(20)).min(text.len());
                while !text.is_char_boundary(end) {
                    end -= 1;
                }
                text.replace_range(at..end, "");
            } else {
                text.insert_str(at, pieces[next(pieces.len())]);
            }
        }
        let _ = read(&text);
    }
}

#[test]
fn columns_are_counted_in_characters_in_any_order() {
    let text = "<a>\n  é<b/>\n";
    let source = Source::new(Path::new("x.xml"), text, 0);
    let at = |offset: usize| {
        let l = source.location(offset);
        (l.line, l.column)
    };
    let b = text.find("<b").unwrap();
    assert_eq!(at(b), (2, 4));
    assert_eq!(at(0), (1, 1));
    assert_eq!(at(b), (2, 4));
    assert_eq!(at(b + 2), (2, 6));
    assert_eq!(at(4), (2, 1));
    assert_eq!(at(text.len()), (3, 1));
}

/// Mitsuba 0.6's `<srgb>` (sRGB-encoded, decoded to linear `<rgb>`) and `<spectrum>` values
/// without wavelengths: three are linear RGB, N others N bins of equal width over 360–830 nm.
#[test]
fn reads_mitsuba_06_colour_forms() {
    let root = read(&scene(
        r##"<bsdf type="test">
            <srgb name="hex" value="#ff0080"/>
            <srgb name="triple" value="0.5, 0, 1"/>
            <srgb name="grey" value="0.04045"/>
            <spectrum name="rgb" value="0.1 0.4 0.9"/>
            <spectrum name="bins" value="0.2, 0.4, 0.6, 0.8"/>
        </bsdf>"##,
    ))
    .unwrap();
    let bsdf = &root.children[0].node;
    let rgb = |name: &str| match property(bsdf, name) {
        PropertyValue::Rgb(c) => *c,
        other => panic!("{name}: {other:?}"),
    };
    let [r, g, b] = rgb("hex");
    assert_eq!((r, g), (1.0, 0.0));
    assert!((b - 0.2158605).abs() < 1e-6, "sRGB-decoded 0x80 is {b}");
    let [r, g, b] = rgb("triple");
    assert!((r - 0.2140411).abs() < 1e-6, "sRGB-decoded 0.5 is {r}");
    assert_eq!((g, b), (0.0, 1.0));
    for v in rgb("grey") {
        assert!((v - 0.04045 / 12.92).abs() < 1e-7, "{v}");
    }
    assert_eq!(rgb("rgb"), [0.1, 0.4, 0.9]);
    let PropertyValue::Spectrum(SpectrumValue::Samples(samples)) = property(bsdf, "bins") else {
        panic!("bins")
    };
    // Bins of 117.5 nm from 360 nm: each value at both ends, the steps 1e-6 nm wide.
    let expected = [
        (360.0, 0.2),
        (477.5 - 1e-6, 0.2),
        (477.5, 0.4),
        (595.0 - 1e-6, 0.4),
        (595.0, 0.6),
        (712.5 - 1e-6, 0.6),
        (712.5, 0.8),
        (830.0, 0.8),
    ];
    assert_eq!(samples.len(), expected.len());
    for (&(wavelength, value), &(w, v)) in samples.iter().zip(&expected) {
        assert!((wavelength - w).abs() < 1e-9 && value == v, "{samples:?}");
    }
    // Bad values are errors at their attribute.
    for (xml, says) in [
        (r#"<srgb name="c" value="0.1, 0.2"/>"#, "2 numbers"),
        (r##"<srgb name="c" value="#12345"/>"##, "not a colour"),
        (r#"<spectrum name="c" value="0.1 x 0.3"/>"#, "x"),
    ] {
        let err = error(&scene(&format!(r#"<bsdf type="test">{xml}</bsdf>"#)));
        assert_error(&err, &[says]);
    }
}
