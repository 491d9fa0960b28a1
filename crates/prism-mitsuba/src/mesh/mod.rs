//! Triangle meshes read from files: Wavefront OBJ ([`obj`]), Stanford PLY ([`ply`]) and
//! Mitsuba's compressed format ([`serialized`]); the control points of curve files
//! ([`curves`]) and the PLY files of ellipsoids ([`ellipsoids`]).
//!
//! A reader turns a file into a [`MeshData`] in object space: positions, optional per-vertex
//! normals, texture coordinates and colours, and triangles indexing them. Polygons are triangulated as a
//! fan around their first vertex, as Mitsuba 3 does. Readers never trust their input: every
//! index is checked against the vertex count and every number must be finite, and the errors
//! name the file and, where the format has lines, the line (binary PLY: the byte offset).
//!
//! When a file has no normals, Mitsuba 3 computes smooth vertex normals
//! ([`MeshData::compute_vertex_normals`], `Mesh::recompute_vertex_normals` in
//! `src/render/mesh.cpp`); the scene builder decides when to call it (not with
//! `face_normals="true"`).

pub mod curves;
pub mod ellipsoids;
pub mod obj;
pub mod ply;
pub mod serialized;

use std::f32::consts::PI;
use std::fmt::Display;
use std::path::Path;

use glam::{Vec2, Vec3};

use crate::file_cache;
use prism_core::error::{Error, Result};
use prism_core::geometry::shape::MeshAttribute;

pub use obj::parse_obj;
pub use ply::parse_ply;
pub use serialized::parse_serialized;

/// A triangle mesh as read from a file, before any transform.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    /// One per vertex when present.
    pub normals: Option<Vec<Vec3>>,
    /// One per vertex when present, in Mitsuba's convention (OBJ's `vt` are flipped on reading,
    /// v -> 1 - v).
    pub uvs: Option<Vec<Vec2>>,
    /// One linear RGB colour per vertex when present (Mitsuba's `vertex_color` attribute).
    pub colors: Option<Vec<Vec3>>,
    /// One linear RGB colour per triangle when present (Mitsuba's `face_color` attribute; a
    /// polygon's colour is repeated for each triangle of its fan).
    pub face_colors: Option<Vec<Vec3>>,
    /// Mitsuba's other attributes (`vertex_{prefix}`, `face_{prefix}`: PLY property groups),
    /// per vertex or, a polygon's value repeated for each triangle of its fan, per triangle.
    pub attributes: Vec<MeshAttribute>,
    /// Counter-clockwise seen from the side the face normal points to.
    pub triangles: Vec<[u32; 3]>,
}

/// Reads a Wavefront OBJ file (see [`obj`]).
pub fn load_obj(path: &Path) -> Result<MeshData> {
    file_cache::parsed(path, "obj", || parse_obj(&read_mesh(path)?, path))
}

/// Reads a Stanford PLY file (see [`ply`]).
pub fn load_ply(path: &Path) -> Result<MeshData> {
    file_cache::parsed(path, "ply", || parse_ply(&read_mesh(path)?, path))
}

/// Reads shape `shape_index` of a Mitsuba serialized file (see [`serialized`]).
pub fn load_serialized(path: &Path, shape_index: u32) -> Result<MeshData> {
    file_cache::parsed(path, &format!("serialized shape {shape_index}"), || {
        parse_serialized(&read_mesh(path)?, shape_index, path)
    })
}

/// The bytes of the mesh file at `path` ([`file_cache::read`]).
fn read_mesh(path: &Path) -> Result<std::sync::Arc<[u8]>> {
    file_cache::read(path).map_err(|e| Error::io(path, &e, "read the mesh"))
}

/// An input error about a mesh file where no line and column apply (a binary file, or the
/// mesh as a whole): the file name leads the message, and the referencing scene element can
/// still add its own location with [`Error::at`].
fn file_error(path: &Path, message: impl Display) -> Error {
    Error::usage(format!("{}: {message}", path.display()))
}

/// The vertices or the triangles of the mesh read from `path`, for checking an attribute that
/// has one value per element.
struct Elements<'a> {
    path: &'a Path,
    /// The element's name, singular and plural.
    singular: &'static str,
    plural: &'static str,
    count: usize,
}

impl Elements<'_> {
    /// Checks that `values`, when present, hold one value per element and that all their
    /// numbers are finite; `name` names one value and `names` the attribute in the errors.
    fn check<T: Copy + Into<[f32; N]>, const N: usize>(
        &self,
        name: &str,
        names: &str,
        values: Option<&[T]>,
    ) -> Result<()> {
        let Some(values) = values else {
            return Ok(());
        };
        let (element, elements, count) = (self.singular, self.plural, self.count);
        if values.len() != count {
            return Err(file_error(
                self.path,
                format!("{} {names} for {count} {elements}", values.len()),
            ));
        }
        let finite = |v: T| v.into().iter().all(|c| c.is_finite());
        match values.iter().position(|&v| !finite(v)) {
            Some(i) => Err(file_error(
                self.path,
                format!("the {name} of {element} {i} is not a finite number"),
            )),
            None => Ok(()),
        }
    }
}

impl MeshData {
    /// Checks that every index is in range, that normals and texture coordinates come one per
    /// vertex, and that all numbers are finite. The readers report these problems with a line
    /// number themselves; this is the last line of defence for meshes built any other way.
    pub fn validate(&self, path: &Path) -> Result<()> {
        let vertex_count = self.positions.len();
        for (i, triangle) in self.triangles.iter().enumerate() {
            if let Some(&index) = triangle
                .iter()
                .find(|&&index| index as usize >= vertex_count)
            {
                return Err(file_error(
                    path,
                    format!(
                        "triangle {i} refers to vertex {index}, but the mesh has {vertex_count} \
                         vertices"
                    ),
                ));
            }
        }
        let vertices = Elements {
            path,
            singular: "vertex",
            plural: "vertices",
            count: vertex_count,
        };
        let triangles = Elements {
            path,
            singular: "triangle",
            plural: "triangles",
            count: self.triangles.len(),
        };
        vertices.check("position", "positions", Some(&self.positions))?;
        vertices.check("normal", "normals", self.normals.as_deref())?;
        let uvs = self.uvs.as_deref();
        vertices.check("texture coordinate", "texture coordinates", uvs)?;
        vertices.check("colour", "colours", self.colors.as_deref())?;
        triangles.check("colour", "face colours", self.face_colors.as_deref())?;
        for attribute in &self.attributes {
            let elements = if attribute.per_face {
                &triangles
            } else {
                &vertices
            };
            elements.check("value", &attribute.name, Some(&attribute.values))?;
        }
        Ok(())
    }

    /// The three corners of triangle `i`, or `None` when `i` or one of its indices is out of
    /// range.
    fn corners(&self, i: usize) -> Option<[Vec3; 3]> {
        let [a, b, c] = *self.triangles.get(i)?;
        Some([
            *self.positions.get(a as usize)?,
            *self.positions.get(b as usize)?,
            *self.positions.get(c as usize)?,
        ])
    }

    /// Geometric (face) normal of triangle `i`, normalized: (p1 - p0) x (p2 - p0), so that a
    /// counter-clockwise triangle faces the viewer. Zero for a degenerate triangle (and for an
    /// index out of range).
    pub fn face_normal(&self, i: usize) -> Vec3 {
        match self.corners(i) {
            Some([p0, p1, p2]) => (p1 - p0).cross(p2 - p0).normalize_or_zero(),
            None => Vec3::ZERO,
        }
    }

    /// Smooth vertex normals, replacing any normals: each vertex gets the sum of the face
    /// normals of its triangles, each weighted by the triangle's angle at that vertex
    /// (Thürmer and Wüthrich 1998, "Computing Vertex Normals from Polygonal Facets", JGT 3(1)),
    /// normalized. This is Mitsuba 3's `Mesh::recompute_vertex_normals`; degenerate triangles
    /// contribute nothing.
    ///
    /// Fallback where the sum is zero: Mitsuba picks the arbitrary (1, 0, 0). We take the face
    /// normal of the first non-degenerate triangle using the vertex (this happens where two
    /// coincident faces of opposite orientation share vertices), and +z for a vertex that no
    /// non-degenerate triangle uses, whose normal can never be seen.
    pub fn compute_vertex_normals(&mut self) {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for (i, &indices) in self.triangles.iter().enumerate() {
            let (Some(corners), face_normal) = (self.corners(i), self.face_normal(i)) else {
                continue;
            };
            if face_normal == Vec3::ZERO {
                continue;
            }
            for j in 0..3 {
                let p = corners[j];
                let to_next = (corners[(j + 1) % 3] - p).normalize_or_zero();
                let to_previous = (corners[(j + 2) % 3] - p).normalize_or_zero();
                normals[indices[j] as usize] += face_normal * unit_angle(to_next, to_previous);
            }
        }

        let mut unresolved = false;
        for n in &mut normals {
            *n = n.normalize_or_zero();
            unresolved |= *n == Vec3::ZERO;
        }
        if unresolved {
            for (i, indices) in self.triangles.iter().enumerate() {
                let face_normal = self.face_normal(i);
                for &index in indices {
                    if let Some(n) = normals.get_mut(index as usize)
                        && *n == Vec3::ZERO
                    {
                        *n = face_normal;
                    }
                }
            }
            for n in &mut normals {
                if *n == Vec3::ZERO {
                    *n = Vec3::Z;
                }
            }
        }
        self.normals = Some(normals);
    }
}

/// The angle between two unit vectors, accurate also for nearly parallel and nearly opposite
/// ones, where acos(a . b) loses precision: 2 asin(|a - b| / 2), or pi minus 2 asin(|a + b| / 2).
fn unit_angle(a: Vec3, b: Vec3) -> f32 {
    let half_chord = |v: Vec3| (0.5 * v.length()).min(1.0).asin();
    if a.dot(b) < 0.0 {
        PI - 2.0 * half_chord(a + b)
    } else {
        2.0 * half_chord(a - b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> MeshData {
        MeshData {
            positions: positions.iter().map(|&p| Vec3::from(p)).collect(),
            triangles: triangles.to_vec(),
            ..MeshData::default()
        }
    }

    fn assert_close(a: Vec3, b: Vec3) {
        assert!((a - b).length() < 1e-5, "{a} != {b}");
    }

    #[test]
    fn face_normal_follows_winding_and_is_zero_when_degenerate() {
        let m = mesh(
            &[
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 3.0, 0.0],
                [4.0, 0.0, 0.0],
            ],
            &[[0, 1, 2], [0, 2, 1], [0, 1, 3], [0, 1, 7]],
        );
        assert_close(m.face_normal(0), Vec3::Z);
        assert_close(m.face_normal(1), -Vec3::Z);
        assert_eq!(m.face_normal(2), Vec3::ZERO);
        assert_eq!(m.face_normal(3), Vec3::ZERO);
        assert_eq!(m.face_normal(4), Vec3::ZERO);
    }

    #[test]
    fn vertex_normals_of_a_flat_grid_are_the_plane_normal() {
        // A 3 x 3 grid of vertices in the plane z = 1, split into 8 triangles.
        let mut positions = Vec::new();
        for y in 0..3 {
            for x in 0..3 {
                positions.push([x as f32, y as f32, 1.0]);
            }
        }
        let mut triangles = Vec::new();
        for y in 0..2 {
            for x in 0..2 {
                let i = y * 3 + x;
                triangles.push([i, i + 1, i + 4]);
                triangles.push([i, i + 4, i + 3]);
            }
        }
        let mut m = mesh(&positions, &triangles);
        m.compute_vertex_normals();
        for &n in m.normals.as_ref().unwrap() {
            assert_close(n, Vec3::Z);
        }
    }

    #[test]
    fn vertex_normal_at_a_cube_corner_is_the_diagonal_whatever_the_tessellation() {
        // The corner at the origin of the cube [0, 1]^3, its three faces facing outwards
        // (-x, -y, -z). The -z face is split into two triangles at the corner and the others
        // into one: angle weighting makes the split irrelevant (each face subtends pi/2).
        let o = [0.0, 0.0, 0.0];
        let m_positions = [
            o,
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
        ];
        let triangles = [
            // -z face: two triangles meeting at the corner, each with angle pi/4 there.
            [0, 2, 4],
            [0, 4, 1],
            // -x face: one triangle with angle pi/2 at the corner.
            [0, 3, 2],
            // -y face.
            [0, 1, 3],
        ];
        let mut m = mesh(&m_positions, &triangles);
        m.compute_vertex_normals();
        let normals = m.normals.unwrap();
        assert_close(normals[0], Vec3::splat(-1.0).normalize());
        // Vertex 2 has a right angle in the first -z triangle and pi/4 in the -x triangle.
        assert_close(normals[2], Vec3::new(-1.0, 0.0, -2.0).normalize());
    }

    #[test]
    fn vertex_normal_fallbacks() {
        // Two coincident triangles of opposite orientation cancel at every vertex: each vertex
        // takes the first triangle's normal. Vertex 3 is unused and gets +z.
        let mut m = mesh(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [5.0, 5.0, 5.0],
            ],
            &[[0, 2, 1], [0, 1, 2]],
        );
        m.compute_vertex_normals();
        let normals = m.normals.unwrap();
        for n in &normals[..3] {
            assert_close(*n, -Vec3::Z);
        }
        assert_eq!(normals[3], Vec3::Z);
    }

    #[test]
    fn unit_angle_is_accurate_at_the_extremes() {
        let a = Vec3::X;
        assert!((unit_angle(a, Vec3::Y) - PI / 2.0).abs() < 1e-6);
        assert!((unit_angle(a, -a) - PI).abs() < 1e-6);
        assert_eq!(unit_angle(a, a), 0.0);
        let tiny = Vec3::new(1.0, 1e-4, 0.0).normalize();
        assert!((unit_angle(a, tiny) - 1e-4).abs() < 1e-8);
    }

    #[test]
    fn the_veach_bidir_models_load() {
        let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/veach-bidir/models");
        let entries =
            std::fs::read_dir(&folder).unwrap_or_else(|e| panic!("{}: {e}", folder.display()));
        let mut count = 0;
        for entry in entries {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "obj") {
                let mesh = load_obj(&path).unwrap_or_else(|e| panic!("{e}"));
                mesh.validate(&path).unwrap();
                assert!(!mesh.triangles.is_empty() && mesh.normals.is_some() && mesh.uvs.is_some());
                count += 1;
            }
        }
        assert_eq!(count, 12);
    }

    #[test]
    fn a_missing_file_is_an_io_error() {
        let error = load_ply(Path::new("/nonexistent/mesh.ply")).unwrap_err();
        assert_eq!(error.kind, prism_core::error::ErrorKind::Io);
        assert!(error.message.contains("/nonexistent/mesh.ply"), "{error}");
    }

    #[test]
    fn validate_reports_the_file_and_the_problem() {
        let path = Path::new("broken.obj");
        let m = mesh(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 3]]);
        let message = m.validate(path).unwrap_err().to_string();
        assert!(message.starts_with("broken.obj: "), "{message}");
        assert!(message.contains("refers to vertex 3"), "{message}");

        let mut m = mesh(
            &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, f32::NAN, 0.0]],
            &[[0, 1, 2]],
        );
        let message = m.validate(path).unwrap_err().to_string();
        assert!(message.contains("vertex 2 is not a finite"), "{message}");

        m.positions[2].y = 1.0;
        m.validate(path).unwrap();
        m.uvs = Some(vec![Vec2::ZERO; 2]);
        let message = m.validate(path).unwrap_err().to_string();
        assert!(
            message.contains("2 texture coordinates for 3 vertices"),
            "{message}"
        );
    }
}
