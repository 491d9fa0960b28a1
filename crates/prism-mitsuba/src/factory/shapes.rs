//! Shape plugins: `obj`, `ply`, `rectangle`, `cube`, `sphere` and `disk`.
//!
//! Parameters shared by all: `to_world` (transform), `flip_normals` (bool); meshes also take
//! `filename`, `face_normals` (bool: ignore vertex normals and shade flat) and, for OBJ,
//! `flip_tex_coords` (bool, default true: the OBJ loader's v → 1 − v, as Mitsuba).

use glam::{DVec3, Mat3, Vec2, Vec3};

use crate::description::PluginNode;
use crate::mesh::{MeshData, load_obj, load_ply};
use crate::params::Params;
use prism_core::error::{Error, Result};
use prism_core::geometry::{Disk, Instance, Primitive, Shape, Sphere, TriangleMesh};
use prism_core::math::Transform;

/// The shape types this factory knows.
pub const SUPPORTED_SHAPES: &[&str] = &["obj", "ply", "rectangle", "cube", "sphere", "disk"];

/// Builds a shape (its BSDF and emitter are the caller's business: it marks them used). A shape
/// whose `to_world` is an `<animation>` is built in object space and placed by an [`Instance`];
/// a fixed `to_world` is applied to the shape once.
pub fn build_shape(params: &Params) -> Result<Primitive> {
    let to_world = params.animated_transform("to_world")?;
    if to_world.is_animated() {
        let shape = build_static_shape(params, &Transform::IDENTITY)?;
        return Ok(Primitive::Instance(Instance::new(shape, to_world)));
    }
    build_static_shape(params, to_world.first()).map(Primitive::Shape)
}

/// Builds a shape placed by the fixed transform `to_world`.
fn build_static_shape(params: &Params, to_world: &Transform) -> Result<Shape> {
    let node = params.node();
    let flip_normals = params.boolean("flip_normals", false)?;
    match node.plugin_type.as_str() {
        "obj" | "ply" => {
            let filename = params.string_opt("filename")?.ok_or_else(|| {
                Error::input(
                    &node.location,
                    format!("{} needs a \"filename\"", node.describe()),
                )
                .with_help("add <string name=\"filename\" value=\"mesh.obj\"/>")
            })?;
            let location = params.location_of("filename");
            let path = node.resolve_file(filename, location)?;
            let face_normals = params.boolean("face_normals", false)?;
            let flip_tex_coords = if node.plugin_type == "obj" {
                params.boolean("flip_tex_coords", true)?
            } else {
                false
            };
            let loaded = if node.plugin_type == "obj" {
                load_obj(&path)
            } else {
                load_ply(&path)
            };
            let mut data = loaded.map_err(|e| mesh_error(e, node))?;
            data.validate(&path).map_err(|e| mesh_error(e, node))?;
            if !flip_tex_coords && let Some(uvs) = &mut data.uvs {
                // The OBJ reader flips v; undo it when the scene asks for raw coordinates.
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
        "rectangle" => Ok(Shape::Mesh(transform_mesh(
            rectangle(),
            to_world,
            flip_normals,
            true,
        ))),
        "cube" => Ok(Shape::Mesh(transform_mesh(
            cube(),
            to_world,
            flip_normals,
            true,
        ))),
        "sphere" => {
            let center = params.point_opt("center")?.unwrap_or(DVec3::ZERO);
            let radius = params.float("radius", 1.0)?;
            if !(radius > 0.0 && radius.is_finite()) {
                return Err(Error::input(
                    params.location_of("radius"),
                    format!("the sphere's radius must be positive, not {radius}"),
                ));
            }
            let matrix = to_world.matrix.as_dmat4();
            let axes = [
                matrix.x_axis.truncate(),
                matrix.y_axis.truncate(),
                matrix.z_axis.truncate(),
            ];
            let scale = axes[0].length();
            let uniform = axes
                .iter()
                .all(|a| (a.length() - scale).abs() <= 1e-5 * scale)
                && axes[0].dot(axes[1]).abs() <= 1e-5 * scale * scale
                && axes[1].dot(axes[2]).abs() <= 1e-5 * scale * scale
                && axes[0].dot(axes[2]).abs() <= 1e-5 * scale * scale;
            if !uniform {
                return Err(Error::input(
                    params.location_of("to_world"),
                    "a sphere's \"to_world\" may only rotate, translate and scale uniformly",
                )
                .with_help("use a triangle mesh for ellipsoids"));
            }
            let rotation = Mat3::from_cols(
                (axes[0] / scale).as_vec3(),
                (axes[1] / scale).as_vec3(),
                (axes[2] / scale).as_vec3(),
            );
            Ok(Shape::Sphere(Sphere {
                center: matrix.transform_point3(center).as_vec3(),
                radius: (radius * scale) as f32,
                rotation,
                flip_normals,
            }))
        }
        "disk" => Ok(Shape::Disk(Disk::new(*to_world, flip_normals))),
        other => Err(
            Error::input(&node.location, format!("unknown shape type \"{other}\"")).with_help(
                format!("supported shape types: {}", SUPPORTED_SHAPES.join(", ")),
            ),
        ),
    }
}

/// Makes a mesh reading error an input error (the scene names the file) that also says which
/// scene element loaded the mesh; errors without a place in the mesh file get the element's.
fn mesh_error(error: Error, node: &PluginNode) -> Error {
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
    TriangleMesh::new(positions, normals, data.uvs, triangles, flip_normals)
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
    use glam::DMat4;

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
