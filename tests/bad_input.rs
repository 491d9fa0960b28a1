//! A suite of malformed inputs — scene XML, OBJ and PLY meshes, render states, command-line
//! parameters — each run through the `prism` binary, asserting the exit status (2 for bad input)
//! and the exact place (file:line:column) the error names, and that nothing panics.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One malformed input: the files to write, the arguments after the program name (`{dir}` is
/// replaced by the case's folder), and what the error must say.
struct Case {
    name: &'static str,
    files: &'static [(&'static str, &'static str)],
    arguments: &'static [&'static str],
    /// The error's location, relative to the case's folder ("" when the error has none).
    location: &'static str,
    /// A phrase the message must contain.
    says: &'static str,
}

/// A scene with a film of 4 × 4 pixels and `body` after the sensor.
macro_rules! scene {
    ($body:expr) => {
        concat!(
            "<scene version=\"3.0.0\">\n",
            "    <sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/><integer name=\"height\" value=\"4\"/></film></sensor>\n",
            $body,
            "\n</scene>\n"
        )
    };
}

const RENDER: &[&str] = &[
    "render",
    "{dir}/scene.xml",
    "-o",
    "{dir}/out.exr",
    "--spp",
    "1",
];

fn render_scene(
    name: &'static str,
    xml: &'static str,
    location: &'static str,
    says: &'static str,
) -> Case {
    Case {
        name,
        files: Box::leak(Box::new([("scene.xml", xml)])),
        arguments: RENDER,
        location,
        says,
    }
}

fn with_mesh(
    name: &'static str,
    mesh: (&'static str, &'static str),
    location: &'static str,
    says: &'static str,
) -> Case {
    let shape: &'static str = if mesh.0.ends_with(".obj") {
        scene!("    <shape type=\"obj\"><string name=\"filename\" value=\"mesh.obj\"/></shape>")
    } else {
        scene!("    <shape type=\"ply\"><string name=\"filename\" value=\"mesh.ply\"/></shape>")
    };
    Case {
        name,
        files: Box::leak(Box::new([("scene.xml", shape), mesh])),
        arguments: RENDER,
        location,
        says,
    }
}

/// A scene lit by an environment map read from `image`, a malformed image file: the error names
/// the `filename` property and says the image could not be read.
fn with_image(name: &'static str, image: (&'static str, &'static str)) -> Case {
    let xml = scene!(
        "    <emitter type=\"envmap\"><string name=\"filename\" value=\"IMAGE\"/></emitter>"
    )
    .replace("IMAGE", image.0);
    Case {
        name,
        files: Box::leak(Box::new([("scene.xml", &*xml.leak()), image])),
        arguments: RENDER,
        location: "scene.xml:3:28",
        says: "could not read the image",
    }
}

fn cases() -> Vec<Case> {
    let mut cases = vec![
        // XML syntax.
        render_scene(
            "unclosed element",
            "<scene version=\"3.0.0\">\n    <shape type=\"sphere\">\n</scene>\n",
            "scene.xml:3:",
            "shape",
        ),
        render_scene(
            "no version",
            "<scene>\n</scene>\n",
            "scene.xml:1:1",
            "version",
        ),
        render_scene(
            "bad version",
            "<scene version=\"three\">\n</scene>\n",
            "scene.xml:1:",
            "version",
        ),
        render_scene(
            "unknown element",
            scene!("    <shap type=\"sphere\"/>"),
            "scene.xml:3:5",
            "did you mean <shape>",
        ),
        render_scene(
            "unknown attribute",
            scene!("    <shape type=\"sphere\" colour=\"red\"/>"),
            "scene.xml:3:",
            "colour",
        ),
        render_scene(
            "property at the root of a transform",
            scene!(
                "    <shape type=\"sphere\"><transform name=\"to_world\"><float name=\"x\" value=\"1\"/></transform></shape>"
            ),
            "scene.xml:3:",
            "transform",
        ),
        render_scene(
            "transform operation outside a transform",
            scene!("    <shape type=\"sphere\"><translate x=\"1\"/></shape>"),
            "scene.xml:3:",
            "<transform>",
        ),
        render_scene(
            "text content",
            scene!("    <shape type=\"sphere\">hello</shape>"),
            "scene.xml:3:",
            "text",
        ),
        render_scene(
            "duplicate id",
            scene!("    <bsdf type=\"diffuse\" id=\"a\"/>\n    <bsdf type=\"diffuse\" id=\"a\"/>"),
            "scene.xml:4:",
            "\"a\"",
        ),
        render_scene(
            "unknown reference",
            scene!("    <shape type=\"sphere\"><ref id=\"nowhere\"/></shape>"),
            "scene.xml:3:",
            "nowhere",
        ),
        render_scene(
            "duplicate property",
            scene!(
                "    <shape type=\"sphere\"><float name=\"radius\" value=\"1\"/><float name=\"radius\" value=\"2\"/></shape>"
            ),
            "scene.xml:3:",
            "radius",
        ),
        render_scene(
            "undefined parameter",
            scene!("    <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>"),
            "scene.xml:3:",
            "$r",
        ),
        render_scene(
            "rgb with two values",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.1, 0.2\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "reflectance",
        ),
        render_scene(
            "spectrum out of order",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" value=\"500:0.5, 400:0.2\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "increasing",
        ),
        render_scene(
            "bad boolean",
            scene!(
                "    <shape type=\"sphere\"><boolean name=\"flip_normals\" value=\"yes\"/></shape>"
            ),
            "scene.xml:3:",
            "true",
        ),
        render_scene(
            "fractional integer",
            scene!(
                "    <integrator type=\"path\"><integer name=\"max_depth\" value=\"1.5\"/></integrator>"
            ),
            "scene.xml:3:",
            "max_depth",
        ),
        render_scene(
            "direct with shading_samples and emitter_samples",
            scene!(
                "    <integrator type=\"direct\"><integer name=\"shading_samples\" value=\"2\"/><integer name=\"emitter_samples\" value=\"1\"/></integrator>"
            ),
            "scene.xml:3:",
            "cannot be given with \"shading_samples\"",
        ),
        render_scene(
            "direct without samples",
            scene!(
                "    <integrator type=\"direct\"><integer name=\"shading_samples\" value=\"0\"/></integrator>"
            ),
            "scene.xml:3:",
            "at least one emitter or BSDF sample",
        ),
        render_scene(
            "moment without nested integrators",
            scene!("    <integrator type=\"moment\"/>"),
            "scene.xml:3:",
            "at least one nested integrator",
        ),
        render_scene(
            "moment with a nested integrator named as an unnamed one is",
            scene!(
                "    <integrator type=\"moment\"><integrator type=\"path\" name=\"_arg_0\"/>\n<integrator type=\"direct\"/></integrator>"
            ),
            "scene.xml:4:",
            "named \"_arg_0\"",
        ),
        render_scene(
            "aov of an unknown type",
            scene!(
                "    <integrator type=\"aov\"><string name=\"aovs\" value=\"nn:sh_normals\"/></integrator>"
            ),
            "scene.xml:3:",
            "did you mean \"sh_normal\"",
        ),
        render_scene(
            "aov without a type",
            scene!(
                "    <integrator type=\"aov\"><string name=\"aovs\" value=\"nn\"/></integrator>"
            ),
            "scene.xml:3:",
            "not a name:type pair",
        ),
        render_scene(
            "aov of a type Prism cannot produce",
            scene!(
                "    <integrator type=\"aov\"><string name=\"aovs\" value=\"d:duv_dx\"/></integrator>"
            ),
            "scene.xml:3:",
            "ray differentials",
        ),
        render_scene(
            "aov named as an image channel",
            scene!(
                "    <integrator type=\"aov\"><string name=\"aovs\" value=\"variance:position\"/></integrator>"
            ),
            "scene.xml:3:",
            "would replace the image's own",
        ),
        render_scene(
            "NaN float",
            scene!("    <shape type=\"sphere\"><float name=\"radius\" value=\"nan\"/></shape>"),
            "scene.xml:3:",
            "finite",
        ),
        render_scene(
            "degenerate lookat",
            scene!(
                "    <shape type=\"sphere\"><transform name=\"to_world\"><lookat origin=\"1,1,1\" target=\"1,1,1\"/></transform></shape>"
            ),
            "scene.xml:3:",
            "lookat",
        ),
        render_scene(
            "rotation about a zero axis",
            scene!(
                "    <shape type=\"sphere\"><transform name=\"to_world\"><rotate angle=\"30\"/></transform></shape>"
            ),
            "scene.xml:3:",
            "axis",
        ),
        render_scene(
            "matrix of 15 values",
            scene!(
                "    <shape type=\"sphere\"><transform name=\"to_world\"><matrix value=\"1 0 0 0 0 1 0 0 0 0 1 0 0 0 0\"/></transform></shape>"
            ),
            "scene.xml:3:",
            "16",
        ),
        render_scene(
            "missing include",
            scene!("    <include filename=\"other.xml\"/>"),
            "scene.xml:3:",
            "other.xml",
        ),
        render_scene(
            "missing path folder",
            "<scene version=\"3.0.0\">\n    <path value=\"nowhere\"/>\n</scene>\n",
            "scene.xml:2:",
            "nowhere",
        ),
        // Scene semantics.
        render_scene(
            "unknown plugin",
            scene!("    <shape type=\"teapot\"/>"),
            "scene.xml:3:5",
            "obj, ply, rectangle",
        ),
        render_scene(
            "misspelled parameter",
            scene!("    <shape type=\"sphere\"><float name=\"radios\" value=\"1\"/></shape>"),
            "scene.xml:3:",
            "did you mean \"radius\"",
        ),
        render_scene(
            "wrong type",
            scene!("    <shape type=\"sphere\"><string name=\"radius\" value=\"1\"/></shape>"),
            "scene.xml:3:",
            "must be a float",
        ),
        render_scene(
            "zero radius",
            scene!("    <shape type=\"sphere\"><float name=\"radius\" value=\"0\"/></shape>"),
            "scene.xml:3:",
            "positive",
        ),
        render_scene(
            "stretched sphere",
            scene!(
                "    <shape type=\"sphere\"><transform name=\"to_world\"><scale x=\"2\"/></transform></shape>"
            ),
            "scene.xml:3:",
            "uniformly",
        ),
        render_scene(
            "negative radiance",
            scene!(
                "    <shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"-1\"/></emitter></shape>"
            ),
            "scene.xml:3:",
            "negative",
        ),
        render_scene(
            "reflectance above one",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><float name=\"reflectance\" value=\"1.5\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "above 1",
        ),
        render_scene(
            "area emitter at the top",
            scene!("    <emitter type=\"area\"/>"),
            "scene.xml:3:5",
            "nested in a shape",
        ),
        render_scene(
            "twosided in twosided",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"twosided\"><bsdf type=\"twosided\"><bsdf type=\"diffuse\"/></bsdf></bsdf></shape>"
            ),
            "scene.xml:3:",
            "twosided",
        ),
        render_scene(
            "no sensor",
            "<scene version=\"3.0.0\">\n    <shape type=\"sphere\"/>\n</scene>\n",
            "scene.xml:1:1",
            "no <sensor>",
        ),
        render_scene(
            "zero sample count",
            "<scene version=\"3.0.0\">\n    <sensor type=\"perspective\"><sampler type=\"independent\"><integer name=\"sample_count\" value=\"0\"/></sampler></sensor>\n</scene>\n",
            "scene.xml:2:",
            "sample_count",
        ),
        render_scene(
            "crop outside the film",
            "<scene version=\"3.0.0\">\n    <sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/><integer name=\"height\" value=\"4\"/><integer name=\"crop_width\" value=\"9\"/></film></sensor>\n</scene>\n",
            "scene.xml:2:",
            "does not fit",
        ),
        render_scene(
            "film of 10^6 × 10^6 pixels",
            "<scene version=\"3.0.0\">\n    <sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"1000000\"/><integer name=\"height\" value=\"1000000\"/></film></sensor>\n</scene>\n",
            "scene.xml:2:",
            "not possible",
        ),
        // OBJ meshes.
        with_mesh(
            "OBJ index out of range",
            ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
            "mesh.obj:4:",
            "vertex 4",
        ),
        with_mesh(
            "OBJ NaN coordinate",
            ("mesh.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
            "mesh.obj:2:",
            "finite",
        ),
        with_mesh(
            "OBJ malformed face",
            ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n"),
            "mesh.obj:4:",
            "x",
        ),
        with_mesh(
            "OBJ index 0",
            ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
            "mesh.obj:4:",
            "0",
        ),
        with_mesh(
            "OBJ without faces",
            ("mesh.obj", "v 0 0 0\nv 1 0 0\n"),
            "mesh.obj",
            "face",
        ),
        // PLY meshes.
        with_mesh(
            "PLY bad magic",
            ("mesh.ply", "plx\nformat ascii 1.0\nend_header\n"),
            "mesh.ply:1:",
            "ply",
        ),
        with_mesh(
            "PLY unknown format",
            (
                "mesh.ply",
                "ply\nformat binary_middle_endian 1.0\nend_header\n",
            ),
            "mesh.ply:2:",
            "binary_middle_endian",
        ),
        with_mesh(
            "PLY without z",
            (
                "mesh.ply",
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 1\n3 0 1 2\n",
            ),
            "mesh.ply",
            "z",
        ),
        with_mesh(
            "PLY claiming 10^12 vertices",
            (
                "mesh.ply",
                "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
            ),
            "mesh.ply",
            "1000000000000",
        ),
        with_mesh(
            "PLY index out of range",
            (
                "mesh.ply",
                concat!(
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
                    "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"
                ),
            ),
            "mesh.ply:13:",
            "5",
        ),
        with_mesh(
            "PLY face of two vertices",
            (
                "mesh.ply",
                concat!(
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
                    "0 0 0\n1 0 0\n0 1 0\n2 0 1\n\n\n\n\n"
                ),
            ),
            "mesh.ply:13:",
            "2",
        ),
        with_mesh(
            "PLY truncated",
            (
                "mesh.ply",
                concat!(
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
                    "0 0 0\n1 0"
                ),
            ),
            "mesh.ply:3:1",
            "too short",
        ),
        // Images.
        with_image("EXR of garbage", ("sky.exr", "v/1\u{1} and no header")),
        with_image(
            "PNG cut after its signature",
            ("sky.png", "\u{89}PNG\r\n\u{1a}\n"),
        ),
        with_image("JPEG that is text", ("sky.jpg", "this is not a JPEG")),
        with_image(
            "HDR without pixels",
            (
                "sky.hdr",
                "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 3 +X 6\n",
            ),
        ),
        with_image("image of unknown format", ("sky.tga", "TRUEVISION")),
        Case {
            name: "bitmap texture that is not a PNG",
            files: &[
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"wood.png\"/></texture></bsdf></shape>"
                    ),
                ),
                ("wood.png", "\u{89}PNG\r\n\u{1a}\n and then nothing"),
            ],
            arguments: RENDER,
            location: "scene.xml:3:",
            says: "could not read the image",
        },
        // Render states.
        Case {
            name: "state of garbage",
            files: &[
                ("scene.xml", scene!("    <shape type=\"sphere\"/>")),
                (
                    "bad.state",
                    "PRISMRS\0 and nothing that follows makes sense",
                ),
            ],
            arguments: &[
                "render",
                "{dir}/scene.xml",
                "-o",
                "{dir}/out.exr",
                "--resume",
                "{dir}/bad.state",
            ],
            location: "",
            says: "not a valid render state",
        },
        Case {
            name: "state that is not one",
            files: &[
                ("scene.xml", scene!("    <shape type=\"sphere\"/>")),
                ("bad.state", "hello"),
            ],
            arguments: &["merge", "{dir}/bad.state", "-o", "{dir}/out.exr"],
            location: "",
            says: "header",
        },
        Case {
            name: "missing state",
            files: &[("scene.xml", scene!("    <shape type=\"sphere\"/>"))],
            arguments: &[
                "render",
                "{dir}/scene.xml",
                "-o",
                "{dir}/out.exr",
                "--resume",
                "{dir}/missing.state",
            ],
            location: "",
            says: "missing.state",
        },
    ];
    // Command-line parameters.
    for (name, extra, says) in [
        ("zero samples", &["--spp", "0"][..], "--spp"),
        (
            "crop outside the film",
            &["--crop", "0,0,9,9"][..],
            "outside",
        ),
        ("pixel outside the film", &["--pixel", "7,0"][..], "outside"),
        ("zero time limit", &["--time-limit=0"][..], "--time-limit"),
        (
            "negative target error",
            &["--target-error=-1"][..],
            "--target-error",
        ),
        (
            "empty sample range",
            &["--sample-range", "5..5"][..],
            "empty",
        ),
        ("define without a value", &["-D", "spp"][..], "NAME=VALUE"),
        ("zero threads", &["--threads", "0"][..], "--threads"),
    ] {
        let mut arguments = RENDER.to_vec();
        arguments.extend_from_slice(extra);
        cases.push(Case {
            name,
            files: Box::leak(Box::new([(
                "scene.xml",
                scene!("    <shape type=\"sphere\"/>"),
            )])),
            arguments: Box::leak(arguments.into_boxed_slice()),
            location: "",
            says,
        });
    }
    cases
}

fn run_case(case: &Case, dir: &Path) -> (i32, String) {
    for (name, contents) in case.files {
        std::fs::write(dir.join(name), contents).unwrap();
    }
    let arguments: Vec<String> = case
        .arguments
        .iter()
        .map(|a| a.replace("{dir}", dir.to_str().unwrap()))
        .collect();
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(&arguments)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stdout).into_owned()
        + &String::from_utf8_lossy(&output.stderr);
    (output.status.code().unwrap_or(-1), text)
}

#[test]
fn every_malformed_input_gets_one_clear_error() {
    let cases = cases();
    assert!(
        cases.len() >= 40,
        "the suite has only {} cases",
        cases.len()
    );
    let root: PathBuf =
        std::env::temp_dir().join(format!("prism-bad-input-{}", std::process::id()));
    let mut failures = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let dir = root.join(i.to_string());
        std::fs::create_dir_all(&dir).unwrap();
        let (status, text) = run_case(case, &dir);
        let location = if case.location.is_empty() {
            String::new()
        } else {
            format!("{}/{}", dir.display(), case.location)
        };
        let ok = status == 2
            && text.starts_with("error: ")
            && text.contains(&location)
            && text.contains(case.says)
            && !text.contains("panicked");
        if !ok {
            failures.push(format!(
                "{}: status {status}, expected location {location:?} and {:?}:\n{text}",
                case.name, case.says
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&root);
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
