//! Bad input gives one clear message naming the file, line and column, and exit status 2 —
//! never a panic. Each test writes a small broken scene and runs the `prism` binary on it.

use std::path::{Path, PathBuf};
use std::process::Command;

/// A fresh folder for one test's files.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-cli-errors-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A valid scene with `shape` (XML) as its only shape, and `sensor_extra` inside the film.
fn scene(shape: &str, film_extra: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <film type="hdrfilm">
            <integer name="width" value="4"/>
            <integer name="height" value="4"/>{film_extra}
        </film>
    </sensor>
{shape}
</scene>
"#
    )
}

/// Runs `prism render` on `scene.xml` in `dir`; returns (status, stderr).
fn render(dir: &Path, extra: &[&str]) -> (i32, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("render")
        .arg(dir.join("scene.xml"))
        .arg("-o")
        .arg(dir.join("out.exr"))
        .args(["--spp", "1"])
        .args(extra)
        .output()
        .unwrap();
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Asserts a failed render: status 2, one error message with `location` (a "file:line:col"
/// suffix) and every phrase in `says`, no panic.
fn assert_error(dir: &Path, extra: &[&str], location: &str, says: &[&str]) {
    let (status, stderr) = render(dir, extra);
    assert_eq!(status, 2, "exit status for:\n{stderr}");
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

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

#[test]
fn a_good_scene_renders() {
    let dir = folder("good");
    write(
        &dir,
        "scene.xml",
        &scene(r#"    <shape type="sphere"/>"#, ""),
    );
    let (status, stderr) = render(&dir, &[]);
    assert_eq!(status, 0, "{stderr}");
    assert!(dir.join("out.exr").exists() && dir.join("out.png").exists());
    assert!(
        stderr.contains("samples/s") && stderr.contains("rays/s"),
        "{stderr}"
    );
}

#[test]
fn malformed_xml() {
    let dir = folder("malformed");
    write(
        &dir,
        "scene.xml",
        "<scene version=\"3.0.0\">\n    <shape type=\"sphere\">\n</scene>\n",
    );
    assert_error(&dir, &[], "scene.xml:3:", &[]);
}

#[test]
fn unknown_plugin_lists_the_supported_ones() {
    let dir = folder("unknown-plugin");
    let shape = "    <shape type=\"sphere\">\n        <bsdf type=\"plastik\"/>\n    </shape>";
    write(&dir, "scene.xml", &scene(shape, ""));
    assert_error(
        &dir,
        &[],
        "scene.xml:9:9",
        &[
            "unknown bsdf type \"plastik\"",
            "diffusetransmission, hair, mask",
            "twosided",
        ],
    );
    let dir = folder("unknown-shape");
    write(
        &dir,
        "scene.xml",
        &scene("    <shape type=\"teapot\"/>", ""),
    );
    assert_error(
        &dir,
        &[],
        "scene.xml:8:5",
        &["unknown shape type \"teapot\"", "obj, ply, rectangle"],
    );
}

#[test]
fn misspelled_parameter_suggests_the_right_one() {
    let dir = folder("misspelled");
    let shape = "    <shape type=\"sphere\">\n        <bsdf type=\"diffuse\">\n            <rgb name=\"reflectanse\" value=\"0.5\"/>\n        </bsdf>\n    </shape>";
    write(&dir, "scene.xml", &scene(shape, ""));
    assert_error(
        &dir,
        &[],
        "scene.xml:10:13",
        &[
            "unknown parameter \"reflectanse\"",
            "did you mean \"reflectance\"",
        ],
    );
}

#[test]
fn value_of_the_wrong_type() {
    let dir = folder("wrong-type");
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"sphere\"/>",
            "\n            <string name=\"crop_width\" value=\"two\"/>",
        ),
    );
    assert_error(
        &dir,
        &[],
        "scene.xml:6:13",
        &["\"crop_width\"", "must be an integer"],
    );
}

#[test]
fn unparsable_number() {
    let dir = folder("bad-number");
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"sphere\">\n        <float name=\"radius\" value=\"1.0.0\"/>\n    </shape>",
            "",
        ),
    );
    assert_error(&dir, &[], "scene.xml:9:30", &["radius", "1.0.0"]);
}

#[test]
fn parameter_without_a_default() {
    let dir = folder("no-default");
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"sphere\">\n        <float name=\"radius\" value=\"$size\"/>\n    </shape>",
            "",
        ),
    );
    assert_error(&dir, &[], "scene.xml:9:30", &["$size", "-D"]);
    // With the define it renders.
    let (status, stderr) = render(&dir, &["-D", "size=2"]);
    assert_eq!(status, 0, "{stderr}");
}

#[test]
fn missing_mesh_file() {
    let dir = folder("missing-mesh");
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"obj\">\n        <string name=\"filename\" value=\"nowhere.obj\"/>\n    </shape>",
            "",
        ),
    );
    assert_error(&dir, &[], "scene.xml:9:9", &["nowhere.obj", "not found"]);
}

#[test]
fn unreadable_mesh_file() {
    let dir = folder("unreadable-mesh");
    // A folder where the mesh should be: found, but it cannot be read.
    std::fs::create_dir_all(dir.join("mesh.obj")).unwrap();
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"obj\">\n        <string name=\"filename\" value=\"mesh.obj\"/>\n    </shape>",
            "",
        ),
    );
    assert_error(&dir, &[], "scene.xml:8:5", &["mesh.obj"]);
}

#[test]
fn mesh_with_an_index_out_of_range() {
    let dir = folder("bad-index");
    write(
        &dir,
        "mesh.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
    );
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"obj\">\n        <string name=\"filename\" value=\"mesh.obj\"/>\n    </shape>",
            "",
        ),
    );
    assert_error(&dir, &[], "mesh.obj:5:", &["vertex 9", "scene.xml:8:5"]);
}

#[test]
fn mesh_with_nan_coordinates() {
    let dir = folder("nan-mesh");
    write(&dir, "mesh.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"obj\">\n        <string name=\"filename\" value=\"mesh.obj\"/>\n    </shape>",
            "",
        ),
    );
    assert_error(&dir, &[], "mesh.obj:2:", &["finite"]);
}

#[test]
fn ply_with_an_index_out_of_range() {
    let dir = folder("bad-ply");
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    write(&dir, "mesh.ply", ply);
    write(
        &dir,
        "scene.xml",
        &scene(
            "    <shape type=\"ply\">\n        <string name=\"filename\" value=\"mesh.ply\"/>\n    </shape>",
            "",
        ),
    );
    assert_error(&dir, &[], "mesh.ply:13:", &["7"]);
}

#[test]
fn zero_size_film() {
    let dir = folder("zero-film");
    let text = scene("    <shape type=\"sphere\"/>", "")
        .replace("name=\"width\" value=\"4\"", "name=\"width\" value=\"0\"");
    write(&dir, "scene.xml", &text);
    assert_error(&dir, &[], "scene.xml:4:13", &["0 × 4"]);
}

#[test]
fn unknown_define_and_bad_arguments() {
    let dir = folder("bad-args");
    write(
        &dir,
        "scene.xml",
        &scene("    <shape type=\"sphere\"/>", ""),
    );
    let (status, stderr) = render(&dir, &["-D", "nothing=1"]);
    assert_eq!(status, 2, "{stderr}");
    assert!(stderr.contains("nothing"), "{stderr}");
    let (status, stderr) = render(&dir, &["--crop", "0,0,9,9"]);
    assert_eq!(status, 2, "{stderr}");
    assert!(stderr.contains("outside"), "{stderr}");
    let (status, _) = render(&dir, &["--spp", "0"]);
    assert_eq!(status, 2);
}

/// `--accel embree` renders in a build with the feature `embree` and otherwise says how to get
/// one; an unknown name is refused.
#[test]
fn accel_embree_needs_the_feature() {
    let dir = folder("accel");
    write(
        &dir,
        "scene.xml",
        &scene("    <shape type=\"sphere\"/>", ""),
    );
    let (status, stderr) = render(&dir, &["--accel", "embree"]);
    if cfg!(feature = "embree") {
        assert_eq!(status, 0, "{stderr}");
        assert!(stderr.contains("traced by Embree"), "{stderr}");
    } else {
        assert_eq!(status, 2, "{stderr}");
        assert!(
            stderr.contains("--features embree") && stderr.contains("tools/install-embree"),
            "{stderr}"
        );
    }
    let (status, stderr) = render(&dir, &["--accel", "kd-tree"]);
    assert_eq!(status, 2, "{stderr}");
    assert!(stderr.contains("bvh or embree"), "{stderr}");
}

/// `--denoise` renders in a build with the feature `denoise` and otherwise says, before
/// rendering, how to get one.
#[test]
fn denoise_needs_the_feature() {
    let dir = folder("denoise");
    write(
        &dir,
        "scene.xml",
        &scene("    <shape type=\"sphere\"/>", ""),
    );
    let (status, stderr) = render(&dir, &["--denoise"]);
    if cfg!(feature = "denoise") {
        assert_eq!(status, 0, "{stderr}");
    } else {
        assert_eq!(status, 2, "{stderr}");
        assert!(
            stderr.contains("--denoise is not available")
                && stderr.contains("tools/fetch-oidn")
                && stderr.contains("cargo build --release --features denoise"),
            "{stderr}"
        );
        assert!(!dir.join("out.exr").exists(), "nothing is rendered");
    }
}

#[test]
fn missing_scene_file() {
    let dir = folder("missing-scene");
    let (status, stderr) = render(&dir, &[]);
    assert_eq!(status, 2, "{stderr}");
    assert!(stderr.contains("not found"), "{stderr}");
}

/// A scene whose sensor is `sensor` (XML of the whole element) and which has one sphere.
fn scene_with_sensor(sensor: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{sensor}\n    <shape type=\"sphere\"/>\n</scene>\n")
}

#[test]
fn bad_lens_shutter_and_filter_parameters() {
    let cases: [(&str, &str, &str); 8] = [
        (
            "<sensor type=\"thinlens\">\n  <float name=\"aperture_radius\" value=\"0\"/>\n</sensor>",
            "scene.xml:3:3",
            "aperture must be positive",
        ),
        (
            "<sensor type=\"thinlens\">\n  <float name=\"aperture_area\" value=\"-1\"/>\n</sensor>",
            "scene.xml:3:3",
            "aperture must be positive",
        ),
        (
            "<sensor type=\"thinlens\">\n  <float name=\"aperture_radius\" value=\"0.1\"/>\n  <float name=\"focal_distance\" value=\"0\"/>\n</sensor>",
            "scene.xml:4:3",
            "focus distance must be positive",
        ),
        (
            "<sensor type=\"perspective\">\n  <float name=\"shutter_open\" value=\"1\"/>\n  <float name=\"shutter_close\" value=\"0.5\"/>\n</sensor>",
            "scene.xml:4:3",
            "before it opens",
        ),
        (
            "<sensor type=\"perspective\">\n  <film type=\"hdrfilm\">\n    <rfilter type=\"tent\"><float name=\"radius\" value=\"0\"/></rfilter>\n  </film>\n</sensor>",
            "scene.xml:4:26",
            "must be positive",
        ),
        (
            "<sensor type=\"perspective\">\n  <film type=\"hdrfilm\">\n    <rfilter type=\"mitchell\"><float name=\"B\" value=\"3\"/></rfilter>\n  </film>\n</sensor>",
            "scene.xml:4:30",
            "outside the valid range",
        ),
        (
            "<sensor type=\"perspective\">\n  <animation name=\"to_world\">\n    <transform time=\"1\"/>\n    <transform time=\"0\"/>\n  </animation>\n</sensor>",
            "scene.xml:5:5",
            "comes after",
        ),
        (
            "<sensor type=\"perspective\">\n  <animation name=\"toWorld\">\n    <transform time=\"0\"/>\n    <transform time=\"1\"><scale value=\"0\"/></transform>\n  </animation>\n</sensor>",
            "scene.xml:5:5",
            "singular",
        ),
    ];
    for (i, (sensor, location, says)) in cases.iter().enumerate() {
        let dir = folder(&format!("sensor-{i}"));
        write(&dir, "scene.xml", &scene_with_sensor(sensor));
        assert_error(&dir, &[], location, &[says]);
    }
}

/// Runs `prism` with `args`; returns (status, stdout + stderr).
fn prism(args: &[&str]) -> (i32, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(args)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stdout).into_owned()
        + &String::from_utf8_lossy(&output.stderr);
    (output.status.code().unwrap_or(-1), text)
}

#[test]
fn bad_stopping_rules_and_estimator_parameters() {
    let dir = folder("stopping");
    write(
        &dir,
        "scene.xml",
        &scene("    <shape type=\"sphere\"/>", ""),
    );
    let scene_path = dir.join("scene.xml");
    let scene_path = scene_path.to_str().unwrap();
    for (flag, value) in [
        ("--target-error", "0"),
        ("--target-error", "-1"),
        ("--time-limit", "0"),
        ("--time-limit", "nan"),
    ] {
        let argument = format!("{flag}={value}");
        let (status, text) = prism(&[
            "render",
            scene_path,
            "-o",
            dir.join("o.exr").to_str().unwrap(),
            &argument,
        ]);
        assert_eq!(status, 2, "{flag} {value}: {text}");
        assert!(text.contains(flag) && !text.contains("panicked"), "{text}");
    }
    for (name, value, says) in [
        ("bounce_samples", "0", "between 1 and 1024"),
        ("shadow_rays", "-2", "between 1 and 1024"),
        ("rr_threshold", "0", "must be positive"),
    ] {
        let dir = folder(&format!("distrib-{name}"));
        let kind = if name == "rr_threshold" {
            "float"
        } else {
            "integer"
        };
        let text = scene("    <shape type=\"sphere\"/>", "").replace(
            "<scene version=\"3.0.0\">",
            &format!("<scene version=\"3.0.0\">\n    <integrator type=\"distrib\"><{kind} name=\"{name}\" value=\"{value}\"/></integrator>"),
        );
        write(&dir, "scene.xml", &text);
        assert_error(&dir, &[], "scene.xml:2:", &[says]);
    }
}

#[test]
fn compare_refuses_other_sizes_and_corrupt_files() {
    let dir = folder("compare");
    write(
        &dir,
        "scene.xml",
        &scene("    <shape type=\"sphere\"/>", ""),
    );
    let (status, text) = render(&dir, &[]);
    assert_eq!(status, 0, "{text}");
    let image = dir.join("out.exr");
    let image = image.to_str().unwrap();
    let (status, text) = prism(&["compare", image, image]);
    assert_eq!(status, 0, "{text}");
    assert!(text.contains("relMSE"), "{text}");
    let other = dir.join("other.exr");
    let scene_path = dir.join("scene.xml");
    let (status, text) = prism(&[
        "render",
        scene_path.to_str().unwrap(),
        "--crop",
        "0,0,2,2",
        "-o",
        other.to_str().unwrap(),
    ]);
    assert_eq!(status, 0, "{text}");
    let (status, text) = prism(&["compare", image, other.to_str().unwrap()]);
    assert_eq!(status, 2, "{text}");
    assert!(text.contains("4×4") && text.contains("2×2"), "{text}");
    let corrupt = dir.join("corrupt.exr");
    std::fs::write(&corrupt, b"v/1\x01not an exr at all").unwrap();
    let (status, text) = prism(&["compare", image, corrupt.to_str().unwrap()]);
    assert_eq!(status, 2, "{text}");
    assert!(
        text.contains("corrupt.exr") && !text.contains("panicked"),
        "{text}"
    );
    let (status, text) = prism(&[
        "converge",
        dir.join("scene.xml").to_str().unwrap(),
        "--reference",
        other.to_str().unwrap(),
    ]);
    assert_eq!(status, 2, "{text}");
    assert!(text.contains("reference"), "{text}");
}

#[test]
fn bench_refuses_impossible_settings() {
    for (args, says) in [
        (&["--threads", "0"][..], "--threads must be at least 1"),
        (&["--seconds=0"][..], "--seconds must be more than 0"),
        (&["--seconds=nan"][..], "--seconds must be more than 0"),
        (
            &["--reference-spp", "0"][..],
            "--reference-spp must be between",
        ),
        (&["--rays", "0"][..], "--rays at least 1"),
        (
            &["--only", "no-such-scene"][..],
            "matches none of the suite's scenes",
        ),
    ] {
        let cache = folder(&format!("bench-{}", args.join("").replace(['-', '='], "")));
        let mut all = vec!["bench", "--cache"];
        all.push(cache.to_str().unwrap());
        all.extend_from_slice(args);
        let (status, text) = prism(&all);
        assert_eq!(status, 2, "{args:?}: {text}");
        assert!(
            text.contains(says) && !text.contains("panicked"),
            "{args:?}: {text}"
        );
    }
}

/// A reader that stops early (`prism compare a.exr b.exr | head -1`) ends `prism` quietly, as
/// it ends other Unix tools, instead of a panic on the closed pipe.
#[cfg(unix)]
#[test]
fn closed_output_pipe_is_not_a_panic() {
    use std::process::Stdio;
    let dir = folder("closed-pipe");
    std::fs::write(dir.join("scene.xml"), scene("", "")).unwrap();
    let (status, stderr) = render(&dir, &[]);
    assert_eq!(status, 0, "{stderr}");
    let image = dir.join("out.exr");
    let mut child = Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("compare")
        .args([&image, &image])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
}
