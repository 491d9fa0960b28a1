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
            "NaN polarizer angle",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"polarizer\"><float name=\"theta\" value=\"nan\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "not a finite number",
        ),
        render_scene(
            "polarizer under ptracer",
            scene!(
                "    <integrator type=\"ptracer\"/>\n    <shape type=\"sphere\"><bsdf type=\"polarizer\"/></shape>"
            ),
            "scene.xml:3:",
            "does not render polarized light",
        ),
        render_scene(
            "stokes around direct",
            scene!(
                "    <integrator type=\"stokes\"><integrator type=\"direct\"/></integrator>\n    <shape type=\"sphere\"/>"
            ),
            "scene.xml:3:",
            "cannot be nested in \"stokes\"",
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
            "area emitter on two shapes",
            scene!(
                "    <emitter type=\"area\" id=\"light\"/><shape type=\"sphere\"><ref id=\"light\"/></shape><shape type=\"disk\"><ref id=\"light\"/></shape>"
            ),
            "scene.xml:3:",
            "already attached",
        ),
        render_scene(
            "area emitter radiance texture without its image",
            scene!(
                "    <shape type=\"sphere\"><emitter type=\"area\"><texture type=\"bitmap\" name=\"radiance\"><string name=\"filename\" value=\"missing.png\"/></texture></emitter></shape>"
            ),
            "scene.xml:3:",
            "not found",
        ),
        render_scene(
            "area emitter radiance given as a bsdf",
            scene!(
                "    <shape type=\"sphere\"><emitter type=\"area\"><bsdf type=\"diffuse\" name=\"radiance\"/></emitter></shape>"
            ),
            "scene.xml:3:",
            "is not supported",
        ),
        render_scene(
            "spot light texture with a cutoff beyond 90 degrees",
            scene!(
                "    <emitter type=\"spot\"><float name=\"cutoff_angle\" value=\"120\"/><texture type=\"checkerboard\" name=\"texture\"/></emitter>"
            ),
            "scene.xml:3:",
            "below 90 degrees",
        ),
        render_scene(
            "projector irradiance given as a bsdf",
            scene!(
                "    <emitter type=\"projector\"><bsdf type=\"diffuse\" name=\"irradiance\"/></emitter>"
            ),
            "scene.xml:3:",
            "is not supported",
        ),
        render_scene(
            "unreferenced area emitter with negative radiance",
            scene!(
                "    <emitter type=\"area\" id=\"light\"><rgb name=\"radiance\" value=\"-1\"/></emitter>"
            ),
            "scene.xml:3:",
            "negative",
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
            "a misspelt Mitsuba 0.6 film parameter",
            "<scene version=\"0.6.0\">\n    <sensor type=\"perspective\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"4\"/><integer name=\"height\" value=\"4\"/>\n        <boolean name=\"banerr\" value=\"false\"/></film></sensor>\n</scene>\n",
            "scene.xml:3:9",
            "did you mean \"banner\"",
        ),
        render_scene(
            "ldrfilm gamma of zero",
            "<scene version=\"3.0.0\">\n    <sensor type=\"perspective\"><film type=\"ldrfilm\"><integer name=\"width\" value=\"4\"/><integer name=\"height\" value=\"4\"/>\n        <float name=\"gamma\" value=\"0\"/></film></sensor>\n</scene>\n",
            "scene.xml:3:9",
            "or −1 for the sRGB curve",
        ),
        render_scene(
            "ldrfilm unknown tonemapper",
            "<scene version=\"3.0.0\">\n    <sensor type=\"perspective\"><film type=\"ldrfilm\"><integer name=\"width\" value=\"4\"/><integer name=\"height\" value=\"4\"/>\n        <string name=\"tonemap_method\" value=\"filmic\"/></film></sensor>\n</scene>\n",
            "scene.xml:3:9",
            "gamma, reinhard",
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
        // Linear curves.
        Case {
            name: "linearcurve: a malformed control point",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"linearcurve\"><string name=\"filename\" value=\"c.txt\"/></shape>"
                    ),
                ),
                ("c.txt", "0 0 0 0.1\n1 0 z 0.1\n"),
            ])),
            arguments: RENDER,
            location: "c.txt:2:5",
            says: "not a finite number",
        },
        Case {
            name: "linearcurve: an area emitter",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"linearcurve\"><string name=\"filename\" value=\"c.txt\"/><emitter type=\"area\"/></shape>"
                    ),
                ),
                ("c.txt", "0 0 0 0.1\n1 0 0 0.1\n"),
            ])),
            arguments: RENDER,
            location: "scene.xml:3:",
            says: "has no area sampling",
        },
        // B-spline curves.
        Case {
            name: "bsplinecurve: a curve of three points",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"bsplinecurve\"><string name=\"filename\" value=\"c.txt\"/></shape>"
                    ),
                ),
                (
                    "c.txt",
                    "0 0 0 0.1\n1 0 0 0.1\n2 1 0 0.1\n3 0 0 0.1\n\n0 1 0 0.1\n1 1 0 0.1\n2 1 1 0.1\n",
                ),
            ])),
            arguments: RENDER,
            location: "c.txt:6:1",
            says: "needs at least 4",
        },
        Case {
            name: "bsplinecurve: a comment line",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"bsplinecurve\"><string name=\"filename\" value=\"c.txt\"/></shape>"
                    ),
                ),
                ("c.txt", "0 0 0 0.1\n# a comment\n"),
            ])),
            arguments: RENDER,
            location: "c.txt:2:1",
            says: "3 numbers on a line",
        },
        Case {
            name: "bsplinecurve: an area emitter",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"bsplinecurve\"><string name=\"filename\" value=\"c.txt\"/><emitter type=\"area\"/></shape>"
                    ),
                ),
                ("c.txt", "0 0 0 0.1\n1 0 0 0.1\n2 0 0 0.1\n3 0 0 0.1\n"),
            ])),
            arguments: RENDER,
            location: "scene.xml:3:",
            says: "has no area sampling",
        },
        // Ellipsoids.
        Case {
            name: "ellipsoids: a centre that is not a number",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 nan 0 0 0 0 -1 -1 -1 1 0 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "e.ply:18:3",
            says: "ellipsoid 0: its centre is not finite",
        },
        Case {
            name: "ellipsoids: a zero quaternion",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 0 0 0 0 -1 -1 -1 0 0 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "e.ply:18:28",
            says: "its quaternion is zero",
        },
        Case {
            name: "ellipsoids: more ellipsoids than the file holds",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 0 0 0 0 -1 -1 -1 1 0 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "e.ply:3:1",
            says: "too short",
        },
        Case {
            name: "ellipsoids: a property of type double",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty double y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 0 0 0 0 -1 -1 -1 1 0 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "e.ply:5:1",
            says: "32-bit floats",
        },
        Case {
            name: "ellipsoids: no rotation",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nend_header\n0 0 0 0 0 0 -1 -1 -1 1 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "e.ply:3:1",
            says: "Mitsuba's layout",
        },
        Case {
            name: "ellipsoids: a text where a number belongs",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 0 0 0 0 -1 one -1 1 0 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "e.ply:18:16",
            says: "\"one\" is not a number",
        },
        Case {
            name: "ellipsoids: an area emitter",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/><emitter type=\"area\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 0 0 0 0 -1 -1 -1 1 0 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "scene.xml:3:",
            says: "has no area sampling",
        },
        Case {
            name: "ellipsoids: an extent of zero",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ellipsoids\"><string name=\"filename\" value=\"e.ply\"/><float name=\"extent\" value=\"0\"/></shape>"
                    ),
                ),
                (
                    "e.ply",
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n0 0 0 0 0 0 -1 -1 -1 1 0 0 0\n",
                ),
            ])),
            arguments: RENDER,
            location: "scene.xml:3:",
            says: "must be a positive number",
        },
        // Cylinders.
        render_scene(
            "cylinder: p0 and p1 the same point",
            scene!(
                "    <shape type=\"cylinder\"><point name=\"p1\" x=\"0\" y=\"0\" z=\"0\"/></shape>"
            ),
            "scene.xml:3:5",
            "are the same point",
        ),
        render_scene(
            "cylinder: negative radius",
            scene!("    <shape type=\"cylinder\"><float name=\"radius\" value=\"-1\"/></shape>"),
            "scene.xml:3:",
            "radius must be positive",
        ),
        render_scene(
            "cylinder: an elliptic to_world",
            scene!(
                "    <shape type=\"cylinder\"><transform name=\"to_world\"><scale x=\"2\"/></transform></shape>"
            ),
            "scene.xml:3:",
            "may not make it elliptic",
        ),
        // mesh_attribute textures.
        Case {
            name: "mesh_attribute: the mesh has no such attribute",
            files: &[
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"obj\"><string name=\"filename\" value=\"mesh.obj\"/><bsdf type=\"diffuse\"><texture type=\"mesh_attribute\" name=\"reflectance\"><string name=\"name\" value=\"vertex_color\"/></texture></bsdf></shape>"
                    ),
                ),
                ("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ],
            arguments: RENDER,
            location: "scene.xml:3:5",
            says: "has no attribute \"vertex_color\" (Mitsuba: invalid attribute requested); it has none",
        },
        render_scene(
            "mesh_attribute: a shape that is not a mesh",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"mesh_attribute\" name=\"reflectance\"><string name=\"name\" value=\"vertex_color\"/></texture></bsdf></shape>"
            ),
            "scene.xml:3:5",
            "which a shape that is not a mesh does not carry",
        ),
        render_scene(
            "mesh_attribute: a name without vertex_ or face_",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"mesh_attribute\" name=\"reflectance\"><string name=\"name\" value=\"color\"/></texture></bsdf></shape>"
            ),
            "scene.xml:3:",
            "must start with \"vertex_\" or \"face_\"",
        ),
        Case {
            name: "mesh_attribute: a colour read as a number",
            files: &[
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"ply\"><string name=\"filename\" value=\"mesh.ply\"/><bsdf type=\"roughconductor\"><texture type=\"mesh_attribute\" name=\"alpha\"><string name=\"name\" value=\"vertex_color\"/></texture></bsdf></shape>"
                    ),
                ),
                (
                    "mesh.ply",
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float r\nproperty float g\nproperty float b\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 1 0 0\n1 0 0 1 0 0\n0 1 0 1 0 0\n3 0 1 2\n",
                ),
            ],
            arguments: RENDER,
            location: "scene.xml:3:5",
            says: "is a colour of three channels, which its BSDF reads as a number",
        },
        render_scene(
            "volume texture as an emitter's radiance",
            scene!(
                "    <shape type=\"sphere\"><emitter type=\"area\"><texture type=\"volume\" name=\"radiance\"><float name=\"volume\" value=\"1\"/></texture></emitter></shape>"
            ),
            "scene.xml:3:",
            "an emitter looks its textures up by (u, v) alone",
        ),
        render_scene(
            "volume texture as a bump map's heights",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"bumpmap\"><texture type=\"volume\"><float name=\"volume\" value=\"0.5\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "which gives them no (u, v) gradient",
        ),
        render_scene(
            "volume texture as a normal map",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"normalmap\"><texture type=\"volume\" name=\"normalmap\"><float name=\"volume\" value=\"0.5\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "is read here as a raw RGB triple (a normal map)",
        ),
        render_scene(
            "directionmix texture as an emitter's radiance",
            scene!(
                "    <shape type=\"sphere\"><emitter type=\"area\"><texture type=\"directionmix\" name=\"radiance\"/></emitter></shape>"
            ),
            "scene.xml:3:",
            "blends by the surface's normal, but an emitter looks its textures up by (u, v) alone",
        ),
        render_scene(
            "directionmix texture of a zero direction",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"directionmix\" name=\"reflectance\"><vector name=\"dir\" x=\"0\" y=\"0\" z=\"0\"/></texture></bsdf></shape>"
            ),
            "scene.xml:3:",
            "which has no direction",
        ),
        render_scene(
            "mesh_attribute: no name",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"mesh_attribute\" name=\"reflectance\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "needs the \"name\"",
        ),
        render_scene(
            "rawconstant of three values read as a colour",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"rawconstant\" name=\"reflectance\">\n        <vector name=\"value\" x=\"1\" y=\"0\" z=\"0\"/></texture></bsdf></shape>"
            ),
            "scene.xml:4:9",
            "three values",
        ),
        render_scene(
            "rawconstant without a value",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><texture type=\"rawconstant\" name=\"reflectance\"/></bsdf></shape>"
            ),
            "scene.xml:3:",
            "needs a \"value\"",
        ),
        render_scene(
            "conductor exterior index not a constant",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"conductor\">\n        <spectrum name=\"ext_eta\" value=\"400:1.3, 700:1.4\"/></bsdf></shape>"
            ),
            "scene.xml:4:9",
            "must be a constant",
        ),
        render_scene(
            "colour opacity outside [0, 1]",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"mask\">\n        <rgb name=\"opacity\" value=\"3, 2, 4\"/><bsdf type=\"diffuse\"/></bsdf></shape>"
            ),
            "scene.xml:4:9",
            "whose mean",
        ),
    ];
    // Command-line parameters.
    cases.extend(media_cases());
    cases.extend(instancing_cases());
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

/// A `.vol` header (version 3, 32-bit floats, a zero bounding box) for `resolution` voxels of
/// `channels`, as the 48 bytes the reader checks first; ASCII-safe for these small sizes.
macro_rules! vol_header {
    ($x:literal, $y:literal, $z:literal, $c:literal) => {
        concat!(
            "VOL\x03\x01\x00\x00\x00",
            $x,
            "\x00\x00\x00",
            $y,
            "\x00\x00\x00",
            $z,
            "\x00\x00\x00",
            $c,
            "\x00\x00\x00",
            "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00",
            "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00"
        )
    };
}

/// A scene whose shape bounds a heterogeneous medium with the grid `density.vol`.
const GRID_SCENE: &str = scene!(
    "    <shape type=\"sphere\"><bsdf type=\"null\"/><medium type=\"heterogeneous\" name=\"interior\"><volume type=\"gridvolume\" name=\"sigma_t\"><string name=\"filename\" value=\"density.vol\"/></volume></medium></shape>"
);

/// A scene whose medium scatters by `sggx` with the matrix grid `s.vol`.
const SGGX_SCENE: &str = scene!(
    "    <medium type=\"homogeneous\" id=\"fog\"><phase type=\"sggx\"><volume type=\"gridvolume\" name=\"S\"><string name=\"filename\" value=\"s.vol\"/></volume></phase></medium>"
);

/// Bad media: negative coefficients, albedos above 1, missing, truncated and foreign grids,
/// phase functions out of range (SGGX matrices of the wrong size, varying or not positive definite), misspelt parameters, and media where distrib or ptracer renders.
fn media_cases() -> Vec<Case> {
    let with_grid = |name: &'static str, bytes: &'static str, says: &'static str| Case {
        name,
        files: Box::leak(Box::new([
            ("scene.xml", GRID_SCENE),
            ("density.vol", bytes),
        ])),
        arguments: RENDER,
        location: "scene.xml:3:",
        says,
    };
    let with_sggx_grid = |name: &'static str, bytes: &'static str, says: &'static str| Case {
        name,
        files: Box::leak(Box::new([("scene.xml", SGGX_SCENE), ("s.vol", bytes)])),
        arguments: RENDER,
        location: "scene.xml:3:",
        says,
    };
    vec![
        Case {
            name: "volume texture of a colour grid read as a number",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"sphere\"><bsdf type=\"roughconductor\"><texture type=\"volume\" name=\"alpha\"><volume type=\"gridvolume\" name=\"volume\"><string name=\"filename\" value=\"colour.vol\"/></volume></texture></bsdf></shape>"
                    ),
                ),
                (
                    "colour.vol",
                    // One voxel of colour (0.5, 0, 0).
                    concat!(
                        vol_header!("\x01", "\x01", "\x01", "\x03"),
                        "\x00\x00\x00\x3f\x00\x00\x00\x00\x00\x00\x00\x00"
                    ),
                ),
            ])),
            arguments: RENDER,
            location: "scene.xml:3:",
            says: "holds a three-channel grid, a colour, where a number is wanted",
        },
        render_scene(
            "negative extinction",
            scene!(
                "    <shape type=\"sphere\"><bsdf type=\"null\"/><medium type=\"homogeneous\" name=\"interior\"><float name=\"sigma_t\" value=\"-1\"/></medium></shape>"
            ),
            "scene.xml:3:",
            "negative",
        ),
        render_scene(
            "albedo above 1",
            scene!(
                "    <shape type=\"sphere\"><medium type=\"homogeneous\" name=\"interior\"><float name=\"albedo\" value=\"1.5\"/></medium></shape>"
            ),
            "scene.xml:3:",
            "above 1",
        ),
        render_scene(
            "RGB albedo above 1",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><rgb name=\"albedo\" value=\"0.5, 1.2, 0.3\"/></medium>"
            ),
            "scene.xml:3:",
            "above 1",
        ),
        render_scene(
            "hg asymmetry of 1",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><phase type=\"hg\"><float name=\"g\" value=\"1\"/></phase></medium>"
            ),
            "scene.xml:3:",
            "(-1, 1)",
        ),
        render_scene(
            "tabphase value not a number",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><phase type=\"tabphase\"><string name=\"values\" value=\"1, x, 2\"/></phase></medium>"
            ),
            "scene.xml:3:",
            "\"x\" is not a number",
        ),
        render_scene(
            "tabphase with a negative value",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><phase type=\"tabphase\"><string name=\"values\" value=\"1, -2, 2\"/></phase></medium>"
            ),
            "scene.xml:3:",
            "none negative",
        ),
        render_scene(
            "tabphase without values",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><phase type=\"tabphase\"/></medium>"
            ),
            "scene.xml:3:",
            "needs its \"values\"",
        ),
        render_scene(
            "tabphase with one value",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><phase type=\"tabphase\"><string name=\"values\" value=\"3\"/></phase></medium>"
            ),
            "scene.xml:3:",
            "at least two",
        ),
        render_scene(
            "misspelt medium parameter",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><float name=\"sigmat\" value=\"1\"/></medium>"
            ),
            "scene.xml:3:",
            "did you mean \"sigma_t\"",
        ),
        render_scene(
            "sigma_a without sigma_s",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><float name=\"sigma_a\" value=\"1\"/></medium>"
            ),
            "scene.xml:3:",
            "without \"sigma_s\"",
        ),
        render_scene(
            "distrib with a medium",
            scene!(
                "    <integrator type=\"distrib\"/>\n    <medium type=\"homogeneous\" id=\"fog\"/>"
            ),
            "scene.xml:4:",
            "volpath",
        ),
        render_scene(
            "ptracer with a medium",
            scene!(
                "    <integrator type=\"ptracer\"/>\n    <medium type=\"homogeneous\" id=\"fog\"/>"
            ),
            "scene.xml:4:",
            "the ptracer integrator does not render participating media",
        ),
        render_scene(
            "ptracer with a radiance meter",
            concat!(
                "<scene version=\"3.0.0\">\n",
                "    <sensor type=\"radiancemeter\"><film type=\"hdrfilm\"><integer name=\"width\" value=\"1\"/><integer name=\"height\" value=\"1\"/></film></sensor>\n",
                "    <integrator type=\"ptracer\"/>\n",
                "</scene>\n"
            ),
            "scene.xml:3:",
            "cannot connect light paths to a radiancemeter sensor",
        ),
        render_scene("missing grid", GRID_SCENE, "scene.xml:3:", "not found"),
        with_grid(
            "truncated grid",
            concat!(
                vol_header!("\x02", "\x02", "\x02", "\x01"),
                "\x00\x00\x00\x3f"
            ),
            "truncated",
        ),
        with_grid(
            "grid longer than its header says",
            concat!(
                vol_header!("\x01", "\x01", "\x01", "\x01"),
                "\x00\x00\x00\x00\x00\x00\x00\x00"
            ),
            "bytes more",
        ),
        with_grid("not a grid", "this is not a volume", "VOL"),
        with_grid(
            "grid header cut short",
            "VOL\x03\x01\x00\x00\x00\x02\x00",
            "header",
        ),
        with_grid(
            "two-channel grid",
            concat!(
                vol_header!("\x01", "\x01", "\x01", "\x02"),
                "\x00\x00\x00\x00\x00\x00\x00\x00"
            ),
            "one (a number) or three (a colour)",
        ),
        with_grid(
            "three-channel grid with a voxel's colour cut short",
            concat!(
                vol_header!("\x02", "\x01", "\x01", "\x03"),
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00",
                "\x00\x00\x00\x00\x00\x00\x00\x00"
            ),
            "2 × 1 × 1 voxels of 3 channel(s), but the file is truncated",
        ),
        with_grid(
            "three-channel grid with a colour too many",
            concat!(
                vol_header!("\x01", "\x01", "\x01", "\x03"),
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00",
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00"
            ),
            "1 × 1 × 1 voxels of 3 channel(s), but the file has 12 bytes more",
        ),
        Case {
            name: "colour albedo grid above 1",
            files: Box::leak(Box::new([
                (
                    "scene.xml",
                    scene!(
                        "    <shape type=\"sphere\"><bsdf type=\"null\"/><medium type=\"heterogeneous\" name=\"interior\"><volume type=\"gridvolume\" name=\"albedo\"><string name=\"filename\" value=\"albedo.vol\"/></volume></medium></shape>"
                    ),
                ),
                (
                    "albedo.vol",
                    // One voxel of colour (3, 0, 0).
                    concat!(
                        vol_header!("\x01", "\x01", "\x01", "\x03"),
                        "\x00\x00\x40\x40\x00\x00\x00\x00\x00\x00\x00\x00"
                    ),
                ),
            ])),
            arguments: RENDER,
            location: "scene.xml:3:",
            says: "reaches 3, above 1",
        },
        with_grid(
            "negative value in a grid",
            concat!(
                vol_header!("\x01", "\x01", "\x01", "\x01"),
                "\x00\x00\u{bf}"
            ),
            "at least 0",
        ),
        with_sggx_grid(
            "sggx matrix of one channel",
            concat!(
                vol_header!("\x01", "\x01", "\x01", "\x01"),
                "\x00\x00\x00\x00"
            ),
            "needs six",
        ),
        with_sggx_grid(
            "sggx matrix of zeros",
            concat!(
                vol_header!("\x01", "\x01", "\x01", "\x06"),
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00",
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00"
            ),
            "not positive definite",
        ),
        with_sggx_grid(
            "sggx matrix varying between voxels",
            concat!(
                vol_header!("\x02", "\x01", "\x01", "\x06"),
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00",
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00",
                "\x00\x00\x00\x01\x00\x00\x00\x00\x00\x00\x00\x00",
                "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00"
            ),
            "varies from voxel to voxel",
        ),
        render_scene(
            "sggx matrix as a constvolume",
            scene!(
                "    <medium type=\"homogeneous\" id=\"fog\"><phase type=\"sggx\"><volume type=\"constvolume\" name=\"S\"/></phase></medium>"
            ),
            "scene.xml:3:",
            "not a gridvolume",
        ),
    ]
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

/// Bad instancing: emitters, moving shapes and nested groups or instances inside a shapegroup,
/// an instance of something that is not a group, and an instance naming no group.
fn instancing_cases() -> Vec<Case> {
    vec![
        render_scene(
            "emitter in a shapegroup",
            scene!(
                "    <shape type=\"shapegroup\" id=\"g\">\n        <shape type=\"sphere\"><emitter type=\"area\"/></shape>\n    </shape>"
            ),
            "scene.xml:4:30",
            "cannot emit light",
        ),
        render_scene(
            "shapegroup in a shapegroup",
            scene!(
                "    <shape type=\"shapegroup\" id=\"g\">\n        <shape type=\"shapegroup\"><shape type=\"sphere\"/></shape>\n    </shape>"
            ),
            "scene.xml:4:9",
            "instancing does not nest",
        ),
        render_scene(
            "instance in a shapegroup",
            scene!(
                "    <shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\"/></shape>\n    <shape type=\"shapegroup\" id=\"h\">\n        <shape type=\"instance\"><ref id=\"g\"/></shape>\n    </shape>"
            ),
            "scene.xml:5:9",
            "instancing does not nest",
        ),
        render_scene(
            "moving shape in a shapegroup",
            scene!(
                "    <shape type=\"shapegroup\" id=\"g\">\n        <shape type=\"sphere\"><animation name=\"to_world\"><transform time=\"0\"/><transform time=\"1\"><translate x=\"1\"/></transform></animation></shape>\n    </shape>"
            ),
            "scene.xml:4:9",
            "cannot move",
        ),
        render_scene(
            "instance of a sphere",
            scene!(
                "    <shape type=\"sphere\" id=\"ball\"/>\n    <shape type=\"instance\"><ref id=\"ball\"/></shape>"
            ),
            "scene.xml:4:28",
            "places a shapegroup",
        ),
        render_scene(
            "instance of nothing",
            scene!("    <shape type=\"instance\"/>"),
            "scene.xml:3:5",
            "shapegroup",
        ),
    ]
}
/// A malformed Mitsuba serialized mesh: the scene loads `mesh.serialized` with `properties`
/// inside its `<shape>`, and the error must name the shape (scene.xml line 3) and say `says`.
struct SerializedCase {
    name: &'static str,
    mesh: Vec<u8>,
    properties: &'static str,
    says: &'static str,
}

fn serialized_cases() -> Vec<SerializedCase> {
    use crate::common::serialized::{
        SerializedShape, serialized_file, shape_header, triangle_shape,
    };
    use miniz_oxide::deflate::compress_to_vec_zlib;

    let good = serialized_file(&[triangle_shape()], 4);
    let with_stream = |stream: &[u8]| {
        let mut file = shape_header(4);
        file.extend_from_slice(&compress_to_vec_zlib(stream, 6));
        file.extend_from_slice(&0u64.to_le_bytes());
        file.extend_from_slice(&1u32.to_le_bytes());
        file
    };
    let mut huge = 0x1000u32.to_le_bytes().to_vec();
    huge.push(0);
    huge.extend_from_slice(&1_000_000_000_000u64.to_le_bytes());
    huge.extend_from_slice(&1u64.to_le_bytes());
    let mut bad_version = good.clone();
    bad_version[2] = 5;
    let mut bad_offset = serialized_file(&[triangle_shape(), triangle_shape()], 4);
    let entry = bad_offset.len() - 12;
    bad_offset[entry..entry + 8].copy_from_slice(&1_000_000u64.to_le_bytes());
    let shape = |positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>| {
        serialized_file(
            &[SerializedShape {
                positions,
                triangles,
                ..SerializedShape::default()
            }],
            3,
        )
    };
    let corner = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mut corrupt = shape_header(4);
    corrupt.extend_from_slice(&[0x78, 0x9c, 0xff, 0xff, 0xff, 0xff, 0, 0, 0, 0, 1, 0, 0, 0]);
    vec![
        SerializedCase {
            name: "serialized: not one",
            mesh: b"PK\x03\x04 a zip file".to_vec(),
            properties: "",
            says: "not a Mitsuba serialized mesh",
        },
        SerializedCase {
            name: "serialized: shorter than a header",
            mesh: vec![0x1c],
            properties: "",
            says: "ends inside the shape header",
        },
        SerializedCase {
            name: "serialized: unknown version",
            mesh: bad_version,
            properties: "",
            says: "has version 5",
        },
        SerializedCase {
            name: "serialized: cut short",
            mesh: good[..good.len() / 2].to_vec(),
            properties: "",
            says: "ends before the data its header declares",
        },
        SerializedCase {
            name: "serialized: corrupt zlib stream",
            mesh: corrupt,
            properties: "",
            says: "is corrupt",
        },
        SerializedCase {
            name: "serialized: shape index out of range",
            mesh: good.clone(),
            properties: "<integer name=\"shape_index\" value=\"1\"/>",
            says: "shape_index 1 is out of range: the file holds 1 shapes (0..0)",
        },
        SerializedCase {
            name: "serialized: negative shape index",
            mesh: good.clone(),
            properties: "<integer name=\"shape_index\" value=\"-1\"/>",
            says: "must be 0 or more",
        },
        SerializedCase {
            name: "serialized: table pointing outside the file",
            mesh: bad_offset,
            properties: "<integer name=\"shape_index\" value=\"1\"/>",
            says: "outside the shapes",
        },
        SerializedCase {
            name: "serialized: counts the file cannot hold",
            mesh: with_stream(&huge),
            properties: "",
            says: "more than the rest of the file can hold",
        },
        SerializedCase {
            name: "serialized: index out of range",
            mesh: shape(corner.clone(), vec![[0, 1, 3]]),
            properties: "",
            says: "refers to vertex 3",
        },
        SerializedCase {
            name: "serialized: position not a number",
            mesh: shape(
                vec![[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]],
                vec![[0, 1, 2]],
            ),
            properties: "",
            says: "vertex 1 is not a finite number",
        },
        SerializedCase {
            name: "serialized: no triangles",
            mesh: shape(corner, Vec::new()),
            properties: "",
            says: "has no triangles",
        },
    ]
}

#[test]
fn every_malformed_serialized_mesh_gets_one_clear_error() {
    let root: PathBuf =
        std::env::temp_dir().join(format!("prism-bad-serialized-{}", std::process::id()));
    let mut failures = Vec::new();
    let cases = serialized_cases();
    for (i, case) in cases.iter().enumerate() {
        let dir = root.join(i.to_string());
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("mesh.serialized"), &case.mesh).unwrap();
        let xml = scene!(
            "    <shape type=\"serialized\"><string name=\"filename\" value=\"mesh.serialized\"/>PROPERTIES</shape>"
        )
        .replace("PROPERTIES", case.properties);
        let scene = Case {
            name: case.name,
            files: Box::leak(Box::new([("scene.xml", &*xml.leak())])),
            arguments: RENDER,
            location: "scene.xml:3:",
            says: case.says,
        };
        let (status, text) = run_case(&scene, &dir);
        let location = format!("{}/scene.xml:3:", dir.display());
        if !(status == 2
            && text.starts_with("error: ")
            && text.contains(&location)
            && text.contains(case.says)
            && !text.contains("panicked"))
        {
            failures.push(format!(
                "{}: status {status}, expected {location:?} and {:?}:\n{text}",
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
