//! Triangle meshes: read from `obj`, `ply` and `serialized` files, given inline
//! (`trianglemesh`), or the built-in `rectangle` and `cube`.

use super::{Build, FLIP_NORMALS};
use crate::description::PluginNode;
use crate::mesh::{MeshData, load_obj, load_ply, load_serialized};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, params};
use glam::{Vec2, Vec3};
use prism_core::error::{Error, Result};
use prism_core::geometry::shape::MeshAttribute;
use prism_core::geometry::{Shape, TriangleMesh};
use prism_core::math::Transform;

pub(super) const OBJ: Plugin<Build> = Plugin {
    name: "obj",
    origin: Origin::Mitsuba3,
    summary: "A Wavefront OBJ mesh (polygons triangulated as fans; smooth vertex normals \
              computed when the file has none).",
    params: shape_params![FILENAME, FACE_NORMALS, FLIP_TEX_COORDS, FLIP_NORMALS],
    build: |params, to_world| build_mesh_file(params, to_world, MeshFormat::Obj),
};

pub(super) const PLY: Plugin<Build> = Plugin {
    name: "ply",
    origin: Origin::Mitsuba3,
    summary: "A Stanford PLY mesh, ASCII or binary.",
    params: shape_params![FILENAME, FACE_NORMALS, FLIP_NORMALS],
    build: |params, to_world| build_mesh_file(params, to_world, MeshFormat::Ply),
};

pub(super) const SERIALIZED: Plugin<Build> = Plugin {
    name: "serialized",
    origin: Origin::Mitsuba3,
    summary: "A mesh of Mitsuba's compressed serialized format (versions 3 and 4; one \
              file may hold several shapes); smooth vertex normals computed when the \
              shape has none.",
    params: shape_params![FILENAME, SHAPE_INDEX, FACE_NORMALS, FLIP_NORMALS],
    build: |params, to_world| build_mesh_file(params, to_world, MeshFormat::Serialized),
};

pub(super) const TRIANGLEMESH: Plugin<Build> = Plugin {
    name: "trianglemesh",
    origin: Origin::Prism,
    summary: "A triangle mesh given as lists of numbers, as the pbrt-v4 reader writes pbrt's \
              `trianglemesh` (XML has no form for it). Without normals it shades flat; a \
              transform that mirrors space keeps the transformed normal, as pbrt does.",
    params: shape_params![
        VERTEX_POSITIONS,
        FACES,
        VERTEX_NORMALS,
        VERTEX_TEXCOORDS,
        FLIP_NORMALS
    ],
    build: build_inline_mesh,
};

pub(super) const RECTANGLE: Plugin<Build> = Plugin {
    name: "rectangle",
    origin: Origin::Mitsuba3,
    summary: "[−1, 1]² in the z = 0 plane, normal +z.",
    params: shape_params![FLIP_NORMALS],
    build: |params, to_world| {
        Ok(Shape::Mesh(transform_mesh(
            rectangle(),
            to_world,
            params.boolean(&FLIP_NORMALS)?,
            true,
        )))
    },
};

pub(super) const CUBE: Plugin<Build> = Plugin {
    name: "cube",
    origin: Origin::Mitsuba3,
    summary: "[−1, 1]³ with outward normals, each face flat.",
    params: shape_params![FLIP_NORMALS],
    build: |params, to_world| {
        Ok(Shape::Mesh(transform_mesh(
            cube(),
            to_world,
            params.boolean(&FLIP_NORMALS)?,
            true,
        )))
    },
};

params! {
    FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the mesh file");
    SHAPE_INDEX = ParamSpec::new("shape_index", ParamKind::Integer, Default::Integer(0), "which of the file's shapes to load, counted from 0");
    FACE_NORMALS = ParamSpec::new("face_normals", ParamKind::Boolean, Default::Boolean(false), "ignore vertex normals and shade flat");
    VERTEX_POSITIONS = ParamSpec::new("vertex_positions", ParamKind::Numbers, Default::Required, "x, y, z of each vertex");
    FACES = ParamSpec::new("faces", ParamKind::Numbers, Default::Required, "three vertex indices (from 0) per triangle, counter-clockwise seen from the front");
    VERTEX_NORMALS = ParamSpec::new("vertex_normals", ParamKind::Numbers, Default::None, "x, y, z of each vertex's shading normal");
    VERTEX_TEXCOORDS = ParamSpec::new("vertex_texcoords", ParamKind::Numbers, Default::None, "u, v of each vertex");
    FLIP_TEX_COORDS = ParamSpec::new("flip_tex_coords", ParamKind::Boolean, Default::Boolean(true), "flip texture coordinates, v → 1 − v, as Mitsuba's OBJ reader does");
}

/// The mesh file formats.
#[derive(Clone, Copy, PartialEq, Eq)]
enum MeshFormat {
    Obj,
    Ply,
    Serialized,
}

/// A mesh read from a file, placed by `to_world`.
fn build_mesh_file(params: &Params, to_world: &Transform, format: MeshFormat) -> Result<Shape> {
    let node = params.node();
    let flip_normals = params.boolean(&FLIP_NORMALS)?;
    let filename = params.string_opt(&FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"mesh.obj\"/>")
    })?;
    let location = params.location_of(&FILENAME);
    let path = node.resolve_file(filename, location)?;
    let face_normals = params.boolean(&FACE_NORMALS)?;
    // The OBJ reader flips v as Mitsuba's does; `flip_tex_coords="false"` undoes it. PLY and
    // serialized coordinates are used as stored.
    let unflip_tex_coords = format == MeshFormat::Obj && !params.boolean(&FLIP_TEX_COORDS)?;
    let loaded = match format {
        MeshFormat::Obj => load_obj(&path),
        MeshFormat::Ply => load_ply(&path),
        MeshFormat::Serialized => {
            let shape_index = params.integer(&SHAPE_INDEX)?;
            let shape_index = u32::try_from(shape_index).map_err(|_| {
                Error::input(
                    params.location_of(&SHAPE_INDEX),
                    format!("\"shape_index\" must be 0 or more, not {shape_index}"),
                )
            })?;
            load_serialized(&path, shape_index)
        }
    };
    let mut data = loaded.map_err(|e| mesh_error(e, node))?;
    data.validate(&path).map_err(|e| mesh_error(e, node))?;
    if unflip_tex_coords && let Some(uvs) = &mut data.uvs {
        for uv in uvs.iter_mut() {
            uv.y = 1.0 - uv.y;
        }
    }
    if data.triangles.is_empty() {
        return Err(Error::input(
            location,
            format!("the mesh \"{filename}\" has no triangles"),
        ));
    }
    if face_normals {
        data.normals = None;
    } else if data.normals.is_none() {
        data.compute_vertex_normals();
    }
    Ok(Shape::Mesh(transform_mesh(
        data,
        to_world,
        flip_normals,
        false,
    )))
}

/// A mesh given inline, placed by `to_world`.
fn build_inline_mesh(params: &Params, to_world: &Transform) -> Result<Shape> {
    let node = params.node();
    let missing = |spec: &ParamSpec| {
        Error::input(
            &node.location,
            format!("{} needs \"{}\"", node.describe(), spec.name),
        )
    };
    let positions = params
        .numbers_opt(&VERTEX_POSITIONS)?
        .ok_or_else(|| missing(&VERTEX_POSITIONS))?;
    let faces = params.numbers_opt(&FACES)?.ok_or_else(|| missing(&FACES))?;
    let bad = |spec: &ParamSpec, problem: String| {
        Error::input(
            params.location_of(spec),
            format!("\"{}\" of {} {problem}", spec.name, node.describe()),
        )
    };
    if positions.is_empty() || positions.len() % 3 != 0 {
        return Err(bad(
            &VERTEX_POSITIONS,
            format!(
                "has {} numbers, not a positive multiple of 3",
                positions.len()
            ),
        ));
    }
    let vertex_count = positions.len() / 3;
    if faces.is_empty() || faces.len() % 3 != 0 {
        return Err(bad(
            &FACES,
            format!("has {} numbers, not a positive multiple of 3", faces.len()),
        ));
    }
    if let Some(index) = faces
        .iter()
        .find(|&&i| !(i >= 0.0 && i < vertex_count as f64 && i.fract() == 0.0))
    {
        return Err(bad(
            &FACES,
            format!(
                "has the index {index}, not a vertex from 0 to {}",
                vertex_count - 1
            ),
        ));
    }
    let vectors = |values: &[f64]| -> Vec<Vec3> {
        values
            .chunks_exact(3)
            .map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
            .collect()
    };
    let normals = match params.numbers_opt(&VERTEX_NORMALS)? {
        Some(normals) if normals.len() != positions.len() => {
            return Err(bad(
                &VERTEX_NORMALS,
                format!(
                    "has {} numbers, but the mesh has {vertex_count} vertices",
                    normals.len()
                ),
            ));
        }
        normals => normals.map(vectors),
    };
    let uvs = match params.numbers_opt(&VERTEX_TEXCOORDS)? {
        Some(uvs) if uvs.len() != 2 * vertex_count => {
            return Err(bad(
                &VERTEX_TEXCOORDS,
                format!(
                    "has {} numbers, but the mesh has {vertex_count} vertices",
                    uvs.len()
                ),
            ));
        }
        uvs => uvs.map(|uvs| {
            uvs.chunks_exact(2)
                .map(|c| Vec2::new(c[0] as f32, c[1] as f32))
                .collect()
        }),
    };
    let data = MeshData {
        positions: vectors(positions),
        normals,
        uvs,
        colors: None,
        face_colors: None,
        attributes: Vec::new(),
        triangles: faces
            .chunks_exact(3)
            .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32])
            .collect(),
    };
    Ok(Shape::Mesh(transform_mesh(
        data,
        to_world,
        params.boolean(&FLIP_NORMALS)?,
        true,
    )))
}

/// Makes a mesh reading error an input error (the scene names the file) that also says which
/// scene element loaded the mesh; errors without a place in the mesh file get the element's.
pub(super) fn mesh_error(error: Error, node: &PluginNode) -> Error {
    let in_mesh_file = error.location.is_some();
    let mut error = error.at(&node.location);
    if in_mesh_file {
        error.message = format!(
            "{} (mesh of {} at {})",
            error.message,
            node.describe(),
            node.location
        );
    }
    error
}

/// Moves a mesh to world space. Normals go through the inverse transpose; for the built-in
/// meshes (`oriented` = true) a transform that mirrors space also reverses the winding, so the
/// geometric normal stays the transformed +z normal as for Mitsuba's analytic rectangle.
pub fn transform_mesh(
    data: MeshData,
    to_world: &Transform,
    flip_normals: bool,
    oriented: bool,
) -> TriangleMesh {
    let positions = data.positions.iter().map(|&p| to_world.point(p)).collect();
    let normals = data.normals.map(|ns| {
        ns.iter()
            .map(|&n| to_world.normal(n).normalize_or_zero())
            .collect()
    });
    let mut triangles = data.triangles;
    if oriented && to_world.flips_handedness() {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    let mut mesh = TriangleMesh::new(positions, normals, data.uvs, triangles, flip_normals);
    let mut attributes = Vec::new();
    if let Some(colors) = data.colors {
        attributes.push(color_attribute(colors, false));
    }
    if let Some(colors) = data.face_colors {
        attributes.push(color_attribute(colors, true));
    }
    attributes.extend(data.attributes);
    if !attributes.is_empty() {
        mesh.set_attributes(attributes);
    }
    mesh
}

/// Mitsuba's `vertex_color` (the vertices' linear RGB colours) or `face_color` (the
/// triangles') attribute.
fn color_attribute(colors: Vec<Vec3>, per_face: bool) -> MeshAttribute {
    MeshAttribute {
        name: if per_face {
            "face_color"
        } else {
            "vertex_color"
        }
        .to_string(),
        per_face,
        channels: 3,
        values: colors,
    }
}

/// Mitsuba's `rectangle`: [−1, 1]² in the z = 0 plane, normal +z, uv from (0, 0) to (1, 1).
pub fn rectangle() -> MeshData {
    MeshData {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ]),
        colors: None,
        face_colors: None,
        attributes: Vec::new(),
        triangles: vec![[0, 1, 2], [2, 3, 0]],
    }
}

/// Mitsuba's `cube`: [−1, 1]³ with outward normals, four vertices per face so that faces
/// are shaded flat.
pub fn cube() -> MeshData {
    let mut data = MeshData {
        positions: Vec::new(),
        normals: Some(Vec::new()),
        uvs: Some(Vec::new()),
        colors: None,
        face_colors: None,
        attributes: Vec::new(),
        triangles: Vec::new(),
    };
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let n = axes[axis] * sign;
            // Tangents with b × c = n, so the corners below run counter-clockwise around n.
            let (b, c) = if sign > 0.0 {
                (axes[(axis + 1) % 3], axes[(axis + 2) % 3])
            } else {
                (axes[(axis + 2) % 3], axes[(axis + 1) % 3])
            };
            let base = data.positions.len() as u32;
            for (i, (sb, sc)) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .into_iter()
                .enumerate()
            {
                data.positions.push(n + b * sb + c * sc);
                if let Some(normals) = &mut data.normals {
                    normals.push(n);
                }
                if let Some(uvs) = &mut data.uvs {
                    uvs.push(Vec2::new(f32::from(i == 1 || i == 2), f32::from(i >= 2)));
                }
            }
            data.triangles.push([base, base + 1, base + 2]);
            data.triangles.push([base + 2, base + 3, base]);
        }
    }
    data
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DMat4, DVec3};
    use prism_core::geometry::ShapeGeometry;

    #[test]
    fn cube_faces_point_outwards() {
        let mesh = transform_mesh(cube(), &Transform::IDENTITY, false, true);
        assert_eq!(mesh.triangles().len(), 12);
        assert!((mesh.area() - 24.0).abs() < 1e-5);
        for t in 0..12 {
            let [p0, p1, p2] = mesh.vertices(t);
            let n = (p1 - p0).cross(p2 - p0).normalize();
            let centre = (p0 + p1 + p2) / 3.0;
            assert!(n.dot(centre) > 0.0, "triangle {t} faces inwards");
        }
    }

    #[test]
    fn mirrored_rectangle_keeps_the_transformed_normal() {
        let mirror = Transform::new(DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))).unwrap();
        let mesh = transform_mesh(rectangle(), &mirror, false, true);
        let [p0, p1, p2] = mesh.vertices(0);
        assert!((p1 - p0).cross(p2 - p0).normalize().dot(Vec3::Z) > 0.99);
    }
}
