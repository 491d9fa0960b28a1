//! Bad light input gives one clear message naming the file, line and column, and exit status 2
//! — never a panic: missing, unreadable, too small or negative environment maps, negative or
//! non-finite emission, bad black-body temperatures, impossible spot and directional
//! parameters, area lights on shapes without area or attached to two shapes, and emitters nested
//! where Mitsuba does not allow them.

use std::path::{Path, PathBuf};
use std::process::Command;

use prism_core::image::{ChannelImage, write_exr, write_png_srgb};

/// A fresh folder for one test's files.
fn folder(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("prism-light-errors-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `scene.xml` in a fresh folder: a valid 4 × 4 scene whose body starts on line 8.
fn scene(name: &str, body: &str) -> PathBuf {
    let dir = folder(name);
    let text = format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <film type="hdrfilm">
            <integer name="width" value="4"/>
            <integer name="height" value="4"/>
        </film>
    </sensor>
{body}
</scene>
"#
    );
    std::fs::write(dir.join("scene.xml"), text).unwrap();
    dir
}

/// Runs `prism render` on the folder's scene; asserts exit status 2, one error message naming
/// `location` ("scene.xml:line:column") and containing every phrase in `says`, and no panic.
fn assert_error(dir: &Path, location: &str, says: &[&str]) {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("render")
        .arg(dir.join("scene.xml"))
        .arg("-o")
        .arg(dir.join("out.exr"))
        .args(["--spp", "1"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "exit status for:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(
        stderr.contains(location),
        "expected location {location} in:\n{stderr}"
    );
    for phrase in says {
        assert!(
            stderr.contains(phrase),
            "expected \"{phrase}\" in:\n{stderr}"
        );
    }
}

fn envmap(file: &str) -> String {
    format!(
        "    <emitter type=\"envmap\">\n        <string name=\"filename\" value=\"{file}\"/>\n    </emitter>"
    )
}

#[test]
fn every_light_renders() {
    let dir = scene(
        "good",
        r#"    <shape type="sphere"><emitter type="area"><spectrum type="blackbody" name="radiance"><float name="temperature" value="4000"/></spectrum></emitter></shape>
    <emitter type="point"><point name="position" x="0" y="3" z="0"/></emitter>
    <emitter type="spot"><float name="cutoff_angle" value="30"/></emitter>
    <emitter type="directional"><vector name="direction" x="0" y="-1" z="0"/></emitter>
    <emitter type="envmap"><string name="filename" value="sky.png"/></emitter>"#,
    );
    write_png_srgb(&dir.join("sky.png"), 2, 3, &[0.5; 18]).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("render")
        .arg(dir.join("scene.xml"))
        .arg("-o")
        .arg(dir.join("out.exr"))
        .args(["--spp", "1"])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn missing_environment_map() {
    let dir = scene("missing-envmap", &envmap("nope.exr"));
    assert_error(&dir, "scene.xml:9:9", &["\"nope.exr\" not found"]);
}

#[test]
fn unreadable_environment_map() {
    let dir = scene("corrupt-envmap", &envmap("sky.exr"));
    std::fs::write(dir.join("sky.exr"), b"v/1\x01 not an OpenEXR file").unwrap();
    assert_error(
        &dir,
        "scene.xml:9:9",
        &["could not read the image", "sky.exr"],
    );
}

#[test]
fn environment_map_too_small() {
    let dir = scene("small-envmap", &envmap("sky.png"));
    write_png_srgb(&dir.join("sky.png"), 2, 2, &[0.5; 12]).unwrap();
    assert_error(&dir, "scene.xml:9:9", &["2 × 2 pixels", "at least 2 × 3"]);
}

#[test]
fn environment_map_with_a_negative_pixel() {
    let dir = scene("negative-envmap", &envmap("sky.exr"));
    let mut red = vec![1.0; 6];
    red[3] = -0.5;
    let image = ChannelImage {
        width: 2,
        height: 3,
        channels: vec![
            ("R".into(), red),
            ("G".into(), vec![1.0; 6]),
            ("B".into(), vec![1.0; 6]),
        ],
    };
    write_exr(&dir.join("sky.exr"), &image).unwrap();
    assert_error(&dir, "scene.xml:9:9", &["pixel (1, 1)", "negative"]);
}

#[test]
fn negative_environment_scale() {
    let dir = scene(
        "negative-scale",
        "    <emitter type=\"envmap\">\n        <string name=\"filename\" value=\"sky.png\"/>\n        <float name=\"scale\" value=\"-2\"/>\n    </emitter>",
    );
    write_png_srgb(&dir.join("sky.png"), 2, 3, &[0.5; 18]).unwrap();
    assert_error(&dir, "scene.xml:10:9", &["scale", "at least 0"]);
}

#[test]
fn negative_or_non_finite_emission() {
    let dir = scene(
        "negative-radiance",
        "    <shape type=\"sphere\">\n        <emitter type=\"area\">\n            <rgb name=\"radiance\" value=\"1, -1, 1\"/>\n        </emitter>\n    </shape>",
    );
    assert_error(
        &dir,
        "scene.xml:10:13",
        &["radiance", "negative or non-finite"],
    );
    let dir = scene(
        "infinite-intensity",
        "    <emitter type=\"point\">\n        <float name=\"intensity\" value=\"inf\"/>\n    </emitter>",
    );
    // The reader refuses the value itself, pointing at the attribute.
    assert_error(
        &dir,
        "scene.xml:9:33",
        &["intensity", "not a finite number"],
    );
    let dir = scene(
        "negative-irradiance",
        "    <emitter type=\"directional\">\n        <spectrum name=\"irradiance\" value=\"-3\"/>\n    </emitter>",
    );
    assert_error(
        &dir,
        "scene.xml:9:9",
        &["irradiance", "negative or non-finite"],
    );
}

#[test]
fn bad_blackbody_temperature() {
    let body = |t: &str| {
        format!(
            "    <emitter type=\"constant\">\n        <spectrum type=\"blackbody\" name=\"radiance\">\n            {t}\n        </spectrum>\n    </emitter>"
        )
    };
    let dir = scene(
        "negative-temperature",
        &body("<float name=\"temperature\" value=\"-300\"/>"),
    );
    assert_error(&dir, "scene.xml:10:13", &["temperature", "-300"]);
    let dir = scene("missing-temperature", &body(""));
    assert_error(&dir, "scene.xml:9:9", &["needs a \"temperature\""]);
    let dir = scene(
        "other-spectrum-plugin",
        "    <emitter type=\"constant\">\n        <spectrum type=\"d65\" name=\"radiance\"/>\n    </emitter>",
    );
    assert_error(
        &dir,
        "scene.xml:9:9",
        &["unknown spectrum type \"d65\"", "blackbody"],
    );
}

#[test]
fn impossible_spot_and_directional_parameters() {
    let dir = scene(
        "wide-beam",
        "    <emitter type=\"spot\">\n        <float name=\"cutoff_angle\" value=\"20\"/>\n        <float name=\"beam_width\" value=\"30\"/>\n    </emitter>",
    );
    assert_error(&dir, "scene.xml:10:9", &["beam_width", "[0, 20]"]);
    let dir = scene(
        "direction-and-transform",
        "    <emitter type=\"directional\">\n        <vector name=\"direction\" x=\"0\" y=\"0\" z=\"1\"/>\n        <transform name=\"to_world\"><rotate x=\"1\" angle=\"30\"/></transform>\n    </emitter>",
    );
    assert_error(
        &dir,
        "scene.xml:9:9",
        &["either \"direction\" or \"to_world\""],
    );
    let dir = scene(
        "zero-direction",
        "    <emitter type=\"directional\">\n        <vector name=\"direction\" x=\"0\" y=\"0\" z=\"0\"/>\n    </emitter>",
    );
    assert_error(&dir, "scene.xml:9:9", &["non-zero"]);
}

#[test]
fn area_light_on_a_shape_without_area() {
    let dir = scene(
        "degenerate-mesh",
        "    <shape type=\"obj\">\n        <string name=\"filename\" value=\"flat.obj\"/>\n        <emitter type=\"area\"/>\n    </shape>",
    );
    std::fs::write(dir.join("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n").unwrap();
    assert_error(&dir, "scene.xml:10:9", &["has no area, so it cannot emit"]);
}

#[test]
fn emitters_nested_where_mitsuba_does_not_allow_them() {
    let dir = scene(
        "environment-in-shape",
        "    <shape type=\"sphere\">\n        <emitter type=\"constant\"/>\n    </shape>",
    );
    assert_error(&dir, "scene.xml:9:9", &["cannot be attached to a shape"]);
    let dir = scene(
        "area-on-two-shapes",
        "    <emitter type=\"area\" id=\"light\"/>\n    <shape type=\"sphere\"><ref id=\"light\"/></shape>\n    <shape type=\"disk\"><ref id=\"light\"/></shape>",
    );
    assert_error(
        &dir,
        "scene.xml:10:24",
        &["already attached", "scene.xml:9:26"],
    );
    let dir = scene(
        "emitter-in-bsdf",
        "    <shape type=\"sphere\">\n        <bsdf type=\"diffuse\">\n            <emitter type=\"area\"/>\n        </bsdf>\n    </shape>",
    );
    assert_error(&dir, "scene.xml:10:13", &["does not take a nested emitter"]);
    let dir = scene(
        "emitter-in-emitter",
        "    <emitter type=\"constant\">\n        <emitter type=\"point\"/>\n    </emitter>",
    );
    assert_error(&dir, "scene.xml:9:9", &["does not take a nested emitter"]);
    let dir = scene(
        "two-environments",
        "    <emitter type=\"constant\"/>\n    <emitter type=\"constant\"/>",
    );
    assert_error(
        &dir,
        "scene.xml:9:5",
        &["more than one environment emitter"],
    );
}

#[test]
fn unknown_emitter_sampling() {
    let dir = scene(
        "emitter-sampling",
        "    <integrator type=\"path\">\n        <string name=\"emitter_sampling\" value=\"by_luck\"/>\n    </integrator>",
    );
    assert_error(
        &dir,
        "scene.xml:9:9",
        &["emitter_sampling", "by_luck", "uniform"],
    );
}
