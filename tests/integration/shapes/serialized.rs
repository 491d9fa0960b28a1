//! Mitsuba serialized meshes: files written by the test writer read back as the meshes they
//! hold, in both versions and precisions, with and without each optional attribute, and any
//! shape of a file with several; and a scene using one builds the mesh it names.

use std::path::Path;

use glam::{Vec2, Vec3};
use prism_mitsuba::mesh::{MeshData, parse_serialized};

use crate::common::serialized::{SerializedShape, serialized_file, triangle_shape};

/// The mesh a reader should return for `shape`.
fn expected(shape: &SerializedShape) -> MeshData {
    let vec3 = |v: &Vec<[f32; 3]>| v.iter().map(|&p| Vec3::from(p)).collect();
    MeshData {
        positions: vec3(&shape.positions),
        normals: shape.normals.as_ref().map(vec3),
        uvs: shape
            .uvs
            .as_ref()
            .map(|uvs| uvs.iter().map(|&uv| Vec2::from(uv)).collect()),
        colors: shape.colors.as_ref().map(vec3),
        face_colors: None,
        attributes: Vec::new(),
        triangles: shape.triangles.clone(),
    }
}

/// A fan of `n` triangles around the origin, numbers that need all of f32's bits.
fn fan(n: u32, z: f32) -> SerializedShape {
    let mut positions = vec![[0.0, 0.0, z]];
    for i in 0..=n {
        let angle = i as f32 * 0.3;
        positions.push([angle.cos() * 1.1, angle.sin() / 3.0, z]);
    }
    SerializedShape {
        name: format!("fan{n}"),
        positions,
        triangles: (1..=n).map(|i| [0, i, i + 1]).collect(),
        ..SerializedShape::default()
    }
}

#[test]
fn every_combination_of_attributes_round_trips() {
    let path = Path::new("mesh.serialized");
    for version in [3, 4] {
        for double in [false, true] {
            for attributes in 0..8 {
                let full = triangle_shape();
                let shape = SerializedShape {
                    normals: full.normals.filter(|_| attributes & 1 != 0),
                    uvs: full.uvs.filter(|_| attributes & 2 != 0),
                    colors: full.colors.filter(|_| attributes & 4 != 0),
                    double,
                    ..full
                };
                let file = serialized_file(std::slice::from_ref(&shape), version);
                let mesh = parse_serialized(&file, 0, path)
                    .unwrap_or_else(|e| panic!("version {version}, {attributes}: {e}"));
                assert_eq!(
                    mesh,
                    expected(&shape),
                    "version {version}, double {double}, attributes {attributes}"
                );
            }
        }
    }
}

#[test]
fn double_precision_is_narrowed_to_the_nearest_f32() {
    let mut shape = fan(3, 0.1);
    shape.double = true;
    // The writer widens f32 values exactly, so reading must give them back unchanged; 0.1 as
    // f64 then f32 is the f32 nearest 0.1.
    let file = serialized_file(std::slice::from_ref(&shape), 4);
    let mesh = parse_serialized(&file, 0, Path::new("m.serialized")).unwrap();
    assert_eq!(mesh, expected(&shape));
    assert_eq!(mesh.positions[0].z, 0.1f32);
}

#[test]
fn each_shape_of_a_file_is_found_through_the_table() {
    let shapes = [fan(1, 0.0), fan(40, 1.0), triangle_shape(), fan(7, -2.0)];
    for version in [3, 4] {
        let file = serialized_file(&shapes, version);
        for (i, shape) in shapes.iter().enumerate() {
            let mesh = parse_serialized(&file, i as u32, Path::new("m.serialized")).unwrap();
            assert_eq!(mesh, expected(shape), "version {version}, shape {i}");
        }
        let error = parse_serialized(&file, 4, Path::new("m.serialized")).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("shape_index 4 is out of range: the file holds 4 shapes (0..3)"),
            "{error}"
        );
    }
}

#[test]
fn a_large_mesh_spans_many_buffers() {
    // 30 000 triangles: several of the reader's 64 KiB buffers of decompressed data.
    let shape = fan(30_000, 0.5);
    let file = serialized_file(std::slice::from_ref(&shape), 4);
    let mesh = parse_serialized(&file, 0, Path::new("m.serialized")).unwrap();
    assert_eq!(mesh, expected(&shape));
}

#[test]
fn a_scene_places_the_shape_it_names() {
    let dir = std::env::temp_dir().join(format!("prism-serialized-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Shape 1 is the unit right triangle; scaled by 2 and 3 it spans [0, 2] x [0, 3].
    let shapes = [fan(5, 0.0), triangle_shape()];
    std::fs::write(dir.join("m.serialized"), serialized_file(&shapes, 4)).unwrap();
    std::fs::write(
        dir.join("scene.xml"),
        r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
    <shape type="serialized">
        <string name="filename" value="m.serialized"/>
        <integer name="shape_index" value="1"/>
        <transform name="to_world"><scale x="2" y="3" z="1"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter>
    </shape>
</scene>
"#,
    )
    .unwrap();
    let loaded = prism_mitsuba::load_scene(&dir.join("scene.xml"), &[]).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let world = &loaded.scene.world;
    assert_eq!(world.lights.len(), 1);
    assert_eq!(world.geometry.primitive_count(), 1);
    let (low, high) = world.geometry.bounds().unwrap();
    assert!(low.abs_diff_eq(Vec3::ZERO, 1e-6), "{low}");
    assert!(high.abs_diff_eq(Vec3::new(2.0, 3.0, 0.0), 1e-6), "{high}");
}
