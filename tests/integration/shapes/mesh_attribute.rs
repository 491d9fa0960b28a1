//! `mesh_attribute` textures: a mesh's attribute is interpolated barycentrically at a hit (and
//! a face attribute is constant over its triangle); a PLY or serialized mesh whose vertices (or
//! a PLY whose faces) all have one colour renders as the same colour given as `<rgb>`.

use std::path::PathBuf;

use glam::Vec3;
use prism_core::film::Film;
use prism_core::geometry::ShapeGeometry;
use prism_core::geometry::shape::MeshAttribute;
use prism_core::geometry::{TriangleMesh, triangle::TriangleHit};
use prism_core::image::srgb;
use prism_core::math::Ray;
use prism_mitsuba::load_scene;

use crate::common::scenes::{pixel_mean_and_variance, render_film};
use crate::common::serialized::{serialized_file, triangle_shape};

#[test]
fn attributes_are_interpolated_barycentrically_and_faces_are_constant() {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
    let mut mesh = TriangleMesh::new(positions, None, None, vec![[0, 1, 2], [1, 3, 2]], false);
    let vertex = [
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(-4.0, 0.5, 8.0),
        Vec3::new(0.25, -1.0, 2.0),
        Vec3::new(7.0, 7.0, 7.0),
    ];
    mesh.set_attributes(vec![
        MeshAttribute {
            name: "vertex_color".into(),
            per_face: false,
            channels: 3,
            values: vertex.to_vec(),
        },
        MeshAttribute {
            name: "face_color".into(),
            per_face: true,
            channels: 3,
            values: vec![Vec3::splat(0.1), Vec3::splat(0.9)],
        },
    ]);
    assert!(mesh.bind_attribute("vertex_color", 3));
    assert!(mesh.bind_attribute("face_color", 0));
    assert!(!mesh.bind_attribute("vertex_normal", 1));
    let hit = TriangleHit {
        t: 1.0,
        b0: 0.5,
        b1: 0.3,
        b2: 0.2,
    };
    let ray = Ray::new(Vec3::ZERO, Vec3::Z, f32::INFINITY, 0.0);
    let at = mesh.interaction(&ray, 1, &hit, 0).attributes.0;
    let expected = vertex[1] * 0.5 + vertex[3] * 0.3 + vertex[2] * 0.2;
    assert!(at[3].abs_diff_eq(expected, 1e-6), "{} != {expected}", at[3]);
    assert_eq!(at[0], Vec3::splat(0.9));
    assert_eq!((at[1], at[2]), (Vec3::ZERO, Vec3::ZERO));
}

/// A scratch folder removed on drop.
struct Folder(PathBuf);

impl Drop for Folder {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A quad under a constant white sky seen from above with direct lighting only (no Russian
/// roulette), its diffuse reflectance `reflectance` (an `<rgb>` or a `<texture>`), read from
/// `mesh` (the shape's type and file name).
fn quad_scene(mesh: (&str, &str), reflectance: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="{}"><string name="filename" value="{}"/>
        <bsdf type="diffuse">{reflectance}</bsdf>
    </shape>
</scene>
"#,
        mesh.0, mesh.1
    )
}

/// Renders the scene with the mesh attribute `attribute` as reflectance and with the same colour
/// as `<rgb>`, from the same random numbers: the images agree to rounding (the interpolated
/// coefficients of equal corners equal the corners' up to a few ulps).
fn assert_renders_as_rgb(
    name: &str,
    files: &[(&str, Vec<u8>)],
    mesh: (&str, &str),
    attribute: &str,
    rgb: &str,
) {
    let dir = std::env::temp_dir().join(format!(
        "prism-mesh-attribute-{name}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let folder = Folder(dir);
    for (file, contents) in files {
        std::fs::write(folder.0.join(file), contents).unwrap();
    }
    let attribute = format!(
        r#"<texture type="mesh_attribute" name="reflectance"><string name="name" value="{attribute}"/></texture>"#
    );
    let constant = format!(r#"<rgb name="reflectance" value="{rgb}"/>"#);
    let films: Vec<_> = [attribute.as_str(), constant.as_str()]
        .iter()
        .map(|reflectance| {
            let path = folder.0.join("scene.xml");
            std::fs::write(&path, quad_scene(mesh, reflectance)).unwrap();
            let loaded = load_scene(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
            render_film(&loaded.scene, 16, 5, Some(1))
        })
        .collect();
    assert_same_lit_image(name, &films[0], &films[1]);
}

#[test]
fn a_uniform_ply_colour_renders_as_that_rgb() {
    let mut ply = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nproperty float red\nproperty float green\nproperty float blue\n\
        element face 2\nproperty list uchar int vertex_indices\nend_header\n"
        .to_vec();
    for (x, y) in [(-1, -1), (1, -1), (1, 1), (-1, 1)] {
        ply.extend_from_slice(format!("{x} {y} 0 0.2 0.5 0.8\n").as_bytes());
    }
    ply.extend_from_slice(b"3 0 1 2\n3 0 2 3\n");
    assert_renders_as_rgb(
        "ply",
        &[("quad.ply", ply)],
        ("ply", "quad.ply"),
        "vertex_color",
        "0.2, 0.5, 0.8",
    );
}

#[test]
fn serialized_colours_are_the_vertex_color_attribute() {
    let mut shape = triangle_shape();
    shape.positions = vec![[-2.0, -2.0, 0.0], [2.0, -2.0, 0.0], [0.0, 2.0, 0.0]];
    shape.colors = Some(vec![[0.7, 0.3, 0.1]; 3]);
    let file = serialized_file(&[shape], 4);
    assert_renders_as_rgb(
        "serialized",
        &[("tri.serialized", file)],
        ("serialized", "tri.serialized"),
        "vertex_color",
        "0.7, 0.3, 0.1",
    );
}

/// PLY face colours (`r g b` on the face element) are the `face_color` attribute, one colour
/// for every triangle of a polygon's fan.
#[test]
fn a_uniform_ply_face_colour_renders_as_that_rgb() {
    let mut ply = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
        property float r\nproperty float g\nproperty float b\nend_header\n"
        .to_vec();
    for (x, y) in [(-1, -1), (1, -1), (1, 1), (-1, 1)] {
        ply.extend_from_slice(format!("{x} {y} 0\n").as_bytes());
    }
    ply.extend_from_slice(b"4 0 1 2 3 0.6 0.1 0.3\n");
    assert_renders_as_rgb(
        "ply-face",
        &[("quad.ply", ply)],
        ("ply", "quad.ply"),
        "face_color",
        "0.6, 0.1, 0.3",
    );
}

/// A binary PLY as Mitsuba's `write_ply` names its colours (`color_0 color_1 color_2`, the
/// `vertex_color` attribute), with `ushort` face colours, which Mitsuba reads divided by 65535
/// and decoded from sRGB.
#[test]
fn binary_ply_with_prefixed_vertex_colours_and_integer_face_colours() {
    let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n\
        property float y\nproperty float z\nproperty float color_0\nproperty float color_1\n\
        property float color_2\nelement face 2\nproperty list uchar int vertex_indices\n\
        property ushort red\nproperty ushort green\nproperty ushort blue\nend_header\n"
        .to_vec();
    for (x, y) in [(-1.0f32, -1.0f32), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        for v in [x, y, 0.0, 0.2, 0.5, 0.8] {
            ply.extend_from_slice(&v.to_le_bytes());
        }
    }
    let face_color: [u16; 3] = [32768, 13107, 65535];
    for corners in [[0i32, 1, 2], [0, 2, 3]] {
        ply.push(3);
        for corner in corners {
            ply.extend_from_slice(&corner.to_le_bytes());
        }
        for channel in face_color {
            ply.extend_from_slice(&channel.to_le_bytes());
        }
    }
    let files = [("quad.ply", ply)];
    assert_renders_as_rgb(
        "ply-prefixed",
        &files,
        ("ply", "quad.ply"),
        "vertex_color",
        "0.2, 0.5, 0.8",
    );
    let [r, g, b] = face_color.map(|c| srgb::decode(f32::from(c) / 65535.0));
    assert!((r - 0.214_048_1).abs() < 1e-6, "{r}");
    assert_renders_as_rgb(
        "ply-ushort-face",
        &files,
        ("ply", "quad.ply"),
        "face_color",
        &format!("{r}, {g}, {b}"),
    );
}

/// Mitsuba's `face_weight` of its mesh-attribute test scenes (a PLY face property `weight_0`):
/// an attribute of one channel, read as a number by a `blendbsdf`'s weight and as a grey by a
/// reflectance. Mitsuba 3.9.1 (`scalar_rgb`, a quad under a constant emitter, weight 0.3
/// between diffuse 0.2 and 0.8) renders the blend as 0.38.
#[test]
fn a_one_channel_face_attribute_is_a_number_and_a_grey() {
    let mut ply = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nelement face 2\nproperty list uchar int vertex_indices\n\
        property float weight_0\nend_header\n"
        .to_vec();
    for (x, y) in [(-1, -1), (1, -1), (1, 1), (-1, 1)] {
        ply.extend_from_slice(format!("{x} {y} 0\n").as_bytes());
    }
    ply.extend_from_slice(b"3 0 1 2 0.3\n3 0 2 3 0.3\n");
    let files = [("quad.ply", ply)];
    assert_renders_as_rgb(
        "ply-weight",
        &files,
        ("ply", "quad.ply"),
        "face_weight",
        "0.3, 0.3, 0.3",
    );

    let dir = std::env::temp_dir().join(format!("prism-face-weight-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let folder = Folder(dir);
    std::fs::write(folder.0.join("quad.ply"), &files[0].1).unwrap();
    let films: Vec<_> = [
        r#"<texture type="mesh_attribute" name="weight"><string name="name" value="face_weight"/></texture>"#,
        r#"<float name="weight" value="0.3"/>"#,
    ]
    .iter()
    .map(|weight| {
        let blend = format!(
            r#"<bsdf type="blendbsdf">{weight}<bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf><bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf></bsdf>"#
        );
        let scene = quad_scene(("ply", "quad.ply"), "").replace(
            r#"<bsdf type="diffuse"></bsdf>"#,
            &blend,
        );
        let path = folder.0.join("scene.xml");
        std::fs::write(&path, scene).unwrap();
        let loaded = load_scene(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
        render_film(&loaded.scene, 16, 5, Some(1))
    })
    .collect();
    assert_same_lit_image("face_weight", &films[0], &films[1]);
}

/// Asserts that `attribute`, the quad rendered with a mesh attribute, equals `constant`, the
/// same quad with the attribute's value written in the scene, pixel by pixel (the same random
/// numbers), and that the quad was seen.
fn assert_same_lit_image(name: &str, attribute: &Film, constant: &Film) {
    let mut lit = 0;
    for i in 0..attribute.pixels.len() {
        for c in 0..3 {
            let (a, _) = pixel_mean_and_variance(attribute, i, c);
            let (b, _) = pixel_mean_and_variance(constant, i, c);
            assert!(
                (a - b).abs() <= 1e-5 * b.abs().max(1e-3),
                "{name}: pixel {i}, channel {c}: {a} with the attribute, {b} written out"
            );
            lit += usize::from(b > 0.0);
        }
    }
    assert!(lit > 0, "{name}: the quad was not seen");
}
