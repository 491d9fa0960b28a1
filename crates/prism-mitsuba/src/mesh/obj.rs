//! Wavefront OBJ meshes, parsed by the `tobj` crate with Mitsuba 3's semantics
//! (`src/shapes/obj.cpp`).
//!
//! Format rules as read here:
//! - `v x y z [w]` is a position (divided by w when given; `v x y z r g b` vertex colours are
//!   ignored), `vt u v` a texture coordinate, `vn x y z` a normal.
//! - `f` lists three or more face vertices, each `v`, `v/vt`, `v//vn` or `v/vt/vn`. Indices
//!   start at 1; negative ones count back from the last element read so far (-1 is the latest).
//!   As in Mitsuba, a face may only refer to elements on earlier lines, and index 0 is an error.
//!   Faces are triangulated as a fan around their first vertex; faces of one or two vertices
//!   are ignored, and so are `l` polylines (tobj would read those of three or more points as
//!   faces, Mitsuba skips them).
//! - All objects and groups (`o`, `g`) merge into one mesh, as Mitsuba reads them; materials
//!   (`mtllib`, `usemtl`) are ignored and a missing `.mtl` file is no error. Statements tobj does
//!   not know (`s`, `p`, `vp`, ...) are ignored.
//! - A mesh vertex is a distinct (v, vt, vn) triple. Normals are kept only when every face vertex
//!   names one, texture coordinates likewise (Mitsuba would leave the missing ones undefined).
//! - The text need not be UTF-8: Mitsuba reads the file as bytes, so a Latin-1 comment or
//!   material name is no error. Bytes that are not UTF-8 are read as U+FFFD (which keeps lines
//!   and, one character per byte of a single-byte encoding, columns); where a number is
//!   expected, that is an error on its line.
//! - Texture coordinates are flipped vertically, v -> 1 - v: Mitsuba's default
//!   (`flip_tex_coords`), since OBJ files put v = 0 at the bottom of the image.
//!
//! tobj reports errors without a line. This reader first checks every face line itself (which
//! also keeps tobj away from indices it does not handle safely), and when tobj fails or the mesh
//! holds a number that is not finite, it scans the text for the offending line.

use std::borrow::Cow;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::{MeshData, file_error};
use prism_core::error::{Error, Result, SourceLocation};

/// Parses the OBJ text in `bytes`; `path` only names the file in messages.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<MeshData> {
    let text = String::from_utf8_lossy(bytes);
    let text = text.as_ref();
    check_face_lines(text, path)?;
    let text = text_for_tobj(text);

    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let no_materials = |_: &Path| Err(tobj::LoadError::OpenFileFailed);
    let (models, _) =
        tobj::load_obj_buf(&mut text.as_bytes(), &options, no_materials).map_err(|e| {
            locate_bad_line(&text, path)
                .unwrap_or_else(|| file_error(path, format!("could not read the OBJ file: {e}")))
        })?;

    let mesh = merge(&models);
    if mesh.triangles.is_empty() {
        return Err(file_error(path, "the file has no faces"));
    }
    if let Err(e) = mesh.validate(path) {
        return Err(locate_bad_line(&text, path).unwrap_or(e));
    }
    Ok(mesh)
}

/// All of tobj's models as one mesh, texture coordinates flipped.
fn merge(models: &[tobj::Model]) -> MeshData {
    let vertex_count = |m: &tobj::Mesh| m.positions.len() / 3;
    let has_normals = models
        .iter()
        .all(|m| m.mesh.normals.len() / 3 == vertex_count(&m.mesh));
    let has_uvs = models
        .iter()
        .all(|m| m.mesh.texcoords.len() / 2 == vertex_count(&m.mesh));

    let mut mesh = MeshData {
        normals: has_normals.then(Vec::new),
        uvs: has_uvs.then(Vec::new),
        ..MeshData::default()
    };
    for model in models {
        let m = &model.mesh;
        let offset = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(Vec3::from_slice));
        if let Some(normals) = &mut mesh.normals {
            normals.extend(m.normals.chunks_exact(3).map(Vec3::from_slice));
        }
        if let Some(uvs) = &mut mesh.uvs {
            uvs.extend(
                m.texcoords
                    .chunks_exact(2)
                    .map(|t| Vec2::new(t[0], 1.0 - t[1])),
            );
        }
        mesh.triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]),
        );
    }
    mesh
}

/// The kinds of element a face vertex refers to, in the order of `v/vt/vn`.
const FACE_INDEX_KINDS: [(&str, &str); 3] = [
    ("vertex", "vertices"),
    ("texture coordinate", "texture coordinates"),
    ("normal", "normals"),
];

/// Checks the syntax of every `f` and `l` line, and that each face index refers to an element
/// defined before it.
fn check_face_lines(text: &str, path: &Path) -> Result<()> {
    // How many positions, texture coordinates and normals precede the current line.
    let mut defined = [0usize; 3];
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = match words.next() {
            Some("v") => {
                defined[0] += 1;
                continue;
            }
            Some("vt") => {
                defined[1] += 1;
                continue;
            }
            Some("vn") => {
                defined[2] += 1;
                continue;
            }
            Some(keyword @ ("f" | "l")) => keyword,
            _ => continue,
        };
        let error = |word: &str, message: String| {
            Error::input(&location(path, number, column(line, word)), message)
        };
        let mut vertex_count = 0;
        for word in words {
            vertex_count += 1;
            let Some(indices) = parse_face_vertex(word) else {
                return Err(error(
                    word,
                    format!(
                        "\"{word}\" is not a face vertex: write v, v/vt, v//vn or v/vt/vn with \
                         integer indices"
                    ),
                ));
            };
            if indices[0].is_none() {
                return Err(error(
                    word,
                    format!("face vertex \"{word}\" has no vertex index"),
                ));
            }
            if keyword == "l" {
                continue;
            }
            for ((index, count), (name, plural)) in
                indices.iter().zip(defined).zip(FACE_INDEX_KINDS)
            {
                let Some(index) = *index else { continue };
                if index == 0 {
                    return Err(error(
                        word,
                        format!(
                            "face refers to {name} 0, but OBJ indices start at 1 (negative ones \
                             count back from the last {name})"
                        ),
                    ));
                }
                // Index i > 0 is element i - 1, index -k is element count - k.
                if index.unsigned_abs() > count {
                    return Err(error(
                        word,
                        format!(
                            "face refers to {name} {index}, but the file has {count} {plural} \
                             before this line"
                        ),
                    ));
                }
            }
        }
        if vertex_count == 0 {
            return Err(error(keyword, format!("\"{keyword}\" without vertices")));
        }
    }
    Ok(())
}

/// The text with the lines tobj would misread rewritten, line numbers kept: polylines of three
/// or more points are dropped (tobj reads them as faces), and so are vertex colours (tobj
/// refuses a mesh where only some vertices have one; Mitsuba ignores them).
fn text_for_tobj(text: &str) -> Cow<'_, str> {
    let rewrite = |line: &str| -> Option<String> {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("l") if words.nth(2).is_some() => Some(String::new()),
            Some("v") if words.clone().count() == 6 => {
                Some(format!("v {}", words.take(3).collect::<Vec<_>>().join(" ")))
            }
            _ => None,
        }
    };
    if !text.lines().any(|line| rewrite(line).is_some()) {
        return Cow::Borrowed(text);
    }
    let lines: Vec<Cow<'_, str>> = text
        .lines()
        .map(|line| rewrite(line).map_or(Cow::Borrowed(line), Cow::Owned))
        .collect();
    Cow::Owned(lines.join("\n"))
}

/// The indices of a face vertex `v`, `v/vt`, `v//vn` or `v/vt/vn`, each absent when empty; `None`
/// when it is not of that form (tobj's rules: at most three non-empty parts, each an integer).
fn parse_face_vertex(word: &str) -> Option<[Option<isize>; 3]> {
    let mut indices = [None; 3];
    for (i, part) in word.split('/').enumerate() {
        if !part.is_empty() {
            *indices.get_mut(i)? = Some(part.parse().ok()?);
        }
    }
    Some(indices)
}

/// Finds the first line that tobj refuses, or that puts a number that is not finite into the
/// mesh, and describes it.
fn locate_bad_line(text: &str, path: &Path) -> Option<Error> {
    text.lines().enumerate().find_map(|(number, line)| {
        let (word, message) = line_problem(line)?;
        Some(Error::input(
            &location(path, number, column(line, word)),
            message,
        ))
    })
}

/// What is wrong with one line of OBJ text, if anything, and the word to point at. Mirrors
/// tobj's parsing of `v`, `vt`, `vn` and `usemtl`, and checks the numbers are finite.
fn line_problem(line: &str) -> Option<(&str, String)> {
    let mut words = line.split_whitespace();
    let keyword = words.next()?;
    let (count, what) = match keyword {
        "v" => (3, "vertex coordinate"),
        "vt" => (2, "texture coordinate"),
        "vn" => (3, "normal"),
        "usemtl" => {
            let name = line.split_once(' ').unwrap_or_default().1.trim();
            return name
                .is_empty()
                .then(|| (keyword, "\"usemtl\" without a material name".to_string()));
        }
        _ => return None,
    };

    let mut values = Vec::with_capacity(count);
    for _ in 0..count {
        let Some(word) = words.next() else {
            return Some((keyword, format!("\"{keyword}\" needs {count} numbers")));
        };
        match word.parse::<f32>() {
            Ok(value) => values.push((word, value)),
            Err(_) => return Some((word, format!("\"{word}\" is not a number"))),
        }
    }
    if keyword == "v" {
        let extra: Vec<&str> = words.collect();
        match extra.as_slice() {
            [] | [_, _, _] => {}
            [w] => match w.parse::<f32>() {
                Err(_) => return Some((w, format!("\"{w}\" is not a number"))),
                Ok(0.0) => {
                    return Some((w, "the vertex weight w is zero".to_string()));
                }
                Ok(w_value) => values.iter_mut().for_each(|(_, value)| *value /= w_value),
            },
            [first, ..] => {
                return Some((
                    first,
                    "a vertex is x y z, optionally followed by a weight w or by an r g b colour"
                        .to_string(),
                ));
            }
        }
    }
    let (word, _) = values.iter().find(|(_, value)| !value.is_finite())?;
    Some((word, format!("{what} is not a finite number")))
}

/// The location of a 0-based line `number`.
fn location(path: &Path, number: usize, column: u32) -> SourceLocation {
    let line = u32::try_from(number + 1).unwrap_or(u32::MAX);
    SourceLocation::new(path, line, column)
}

/// The 1-based column of `word`, a slice of `line`.
fn column(line: &str, word: &str) -> u32 {
    let offset = (word.as_ptr() as usize).saturating_sub(line.as_ptr() as usize);
    u32::try_from(offset + 1).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<MeshData> {
        parse_obj(text.as_bytes(), Path::new("mesh.obj"))
    }

    fn error(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

    #[test]
    fn quads_and_polygons_become_fans() {
        let mesh = parse(&format!("{SQUARE}f 1 2 3 4\n")).unwrap();
        assert_eq!(mesh.triangles, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!((mesh.normals, mesh.uvs), (None, None));

        let pentagon = parse(&format!("{SQUARE}v 0.5 2 0\nf 1 2 3 5 4\n")).unwrap();
        assert_eq!(pentagon.triangles, [[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }

    #[test]
    fn face_vertex_forms() {
        let data = format!("{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n");
        let all = parse(&format!("{data}f 1/1/1 2/2/1 3/3/1\n")).unwrap();
        assert_eq!(all.normals.unwrap(), [Vec3::Z; 3]);
        assert_eq!(all.uvs.unwrap().len(), 3);

        let normals_only = parse(&format!("{data}f 1//1 2//1 3//1\n")).unwrap();
        assert!(normals_only.normals.is_some() && normals_only.uvs.is_none());

        let uvs_only = parse(&format!("{data}f 1/1 2/2 3/3\n")).unwrap();
        assert!(uvs_only.normals.is_none() && uvs_only.uvs.is_some());

        // A vertex is a distinct (v, vt, vn) triple: shared corners are shared, a position with
        // two texture coordinates is two vertices.
        let shared = parse(&format!(
            "{data}f 1/1 2/2 3/3\nf 1/1 3/3 4/1\nf 1/2 2/2 3/3\n"
        ))
        .unwrap();
        assert_eq!(shared.positions.len(), 5);
        assert_eq!(shared.triangles, [[0, 1, 2], [0, 2, 3], [4, 1, 2]]);
    }

    #[test]
    fn negative_indices_count_back_from_the_latest_element() {
        let absolute = parse(&format!("{SQUARE}vt 0 0\nvt 1 1\nf 1/1 2/2 3/1 4/2\n")).unwrap();
        let relative = parse(&format!(
            "{SQUARE}vt 0 0\nvt 1 1\nf -4/-2 -3/-1 -2/-2 -1/-1\n"
        ))
        .unwrap();
        assert_eq!(absolute, relative);
        // Relative to the elements read so far, not to the whole file.
        let interleaved =
            parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -3 -1\n").unwrap();
        assert_eq!(interleaved.triangles, [[0, 1, 2], [0, 1, 3]]);
    }

    #[test]
    fn texture_coordinates_are_flipped_vertically() {
        let mesh = parse(&format!(
            "{SQUARE}vt 0.25 0.75\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n"
        ))
        .unwrap();
        let uvs = mesh.uvs.unwrap();
        assert_eq!(
            uvs,
            [
                Vec2::new(0.25, 0.25),
                Vec2::new(1.0, 1.0),
                Vec2::new(0.0, 0.0)
            ]
        );
    }

    #[test]
    fn partial_normals_and_texture_coordinates_are_dropped() {
        let text = format!("{SQUARE}vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf 1 3 4\n");
        let mesh = parse(&text).unwrap();
        assert_eq!(mesh.triangles.len(), 2);
        assert_eq!((mesh.normals, mesh.uvs), (None, None));
    }

    #[test]
    fn objects_groups_and_materials_merge_into_one_mesh() {
        let text = "mtllib missing.mtl\no first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n\
                    g second\nusemtl blue\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 4 5 6\nf 1 2 5\n\
                    o third\nf -1 -2 -3\n";
        let mesh = parse(text).unwrap();
        assert_eq!(mesh.triangles.len(), 4);
        assert_eq!(mesh.positions.len(), 3 + 5 + 3);
        let corners = |i: usize| mesh.triangles[i].map(|v| mesh.positions[v as usize]);
        assert_eq!(
            corners(1),
            [Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)]
        );
        assert_eq!(corners(2), [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0)]);
        assert_eq!(
            corners(3),
            [Vec3::new(0.0, 1.0, 1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::Z]
        );
        mesh.validate(Path::new("mesh.obj")).unwrap();
    }

    #[test]
    fn out_of_range_indices_name_the_line_and_column() {
        let twelve = "v 0 0 0\n".repeat(12);
        let message = error(&format!("{twelve}# a comment\nf 1 2 99\n"));
        assert!(
            message.starts_with(
                "mesh.obj:14:7: face refers to vertex 99, but the file has 12 \
                                 vertices before this line"
            ),
            "{message}"
        );
        let message = error(&format!("{twelve}f 1 2 -13\n"));
        assert!(
            message.starts_with("mesh.obj:13:7: face refers to vertex -13"),
            "{message}"
        );
        let message = error(&format!("{twelve}vt 0 0\nf 1/1 2/2 3/1\n"));
        assert!(
            message.starts_with("mesh.obj:14:7: face refers to texture coordinate 2"),
            "{message}"
        );
        let message = error(&format!("{twelve}f 1//1 2//1 3//1\n"));
        assert!(
            message.contains("mesh.obj:13:3: face refers to normal 1, but the file has 0 normals"),
            "{message}"
        );
        let message = error(&format!("{twelve}f 0 1 2\n"));
        assert!(
            message.starts_with("mesh.obj:13:3: face refers to vertex 0"),
            "{message}"
        );
        // A vertex defined after the face does not count (Mitsuba refuses it too).
        let message = error("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n");
        assert!(
            message.starts_with("mesh.obj:3:7: face refers to vertex 3"),
            "{message}"
        );
    }

    #[test]
    fn numbers_that_are_not_finite_name_the_line() {
        let message = error(&format!("{SQUARE}v 0 nan 0\nf 1 2 5\n"));
        assert!(
            message.starts_with("mesh.obj:5:5: vertex coordinate is not a finite number"),
            "{message}"
        );
        let message = error(&format!("{SQUARE}v 0 0 1e39\nf 1 2 5\n"));
        assert!(
            message.starts_with("mesh.obj:5:7: vertex coordinate"),
            "{message}"
        );
        let message = error(&format!("{SQUARE}vn 0 0 inf\nf 1//1 2//1 3//1\n"));
        assert!(
            message.starts_with("mesh.obj:5:8: normal is not a finite number"),
            "{message}"
        );
        let message = error(&format!("{SQUARE}vt NaN 0\nf 1/1 2/1 3/1\n"));
        assert!(
            message.starts_with("mesh.obj:5:4: texture coordinate is not"),
            "{message}"
        );
        // An unused bad vertex is never read into the mesh, as tobj skips it.
        assert!(parse(&format!("{SQUARE}v nan 0 0\nf 1 2 3\n")).is_ok());
    }

    #[test]
    fn lines_tobj_ignores_or_refuses() {
        // Unknown statements, comments, blank lines, smoothing groups, Windows line ends,
        // point and line elements and two-vertex faces are ignored.
        let text = "# comment\r\nhello world\r\n\r\ns off\r\nvp 0.5\r\nv 0 0 0\r\nv 1 0 0 1\r\n\
                    v 0 1 0 0.5 0.5 0.5\r\np 1\r\nl 1 2\r\nl 1 2 3\r\nf 1 2\r\n  f 1 2 3  \r\n";
        let mesh = parse(text).unwrap();
        assert_eq!(mesh.triangles, [[0, 1, 2]]);

        // The weight w divides the position.
        let weighted = parse("v 2 4 6 2\nv 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap();
        assert_eq!(weighted.positions[0], Vec3::new(1.0, 2.0, 3.0));

        let refused = [
            ("v 1 2\n", "mesh.obj:1:1: \"v\" needs 3 numbers"),
            ("v 0 0 0\nvt a 0\n", "mesh.obj:2:4: \"a\" is not a number"),
            ("v 0 0 0\nvn 0 0\n", "mesh.obj:2:1: \"vn\" needs 3 numbers"),
            ("v 1 2 3 0\n", "mesh.obj:1:9: the vertex weight w is zero"),
            ("v 1 2 3 4 5\n", "mesh.obj:1:9: a vertex is x y z"),
            (
                "v 0 0 0\nusemtl\n",
                "mesh.obj:2:1: \"usemtl\" without a material name",
            ),
            (
                "v 0 0 0\nf 1/1/1/1 1 1\n",
                "mesh.obj:2:3: \"1/1/1/1\" is not a face vertex",
            ),
            (
                "v 0 0 0\nf 1 x 1\n",
                "mesh.obj:2:5: \"x\" is not a face vertex",
            ),
            (
                "v 0 0 0\nf /1 1 1\n",
                "mesh.obj:2:3: face vertex \"/1\" has no vertex index",
            ),
            ("v 0 0 0\n f\n", "mesh.obj:2:2: \"f\" without vertices"),
            (
                "v 0 0 0\nl 1 q\n",
                "mesh.obj:2:5: \"q\" is not a face vertex",
            ),
        ];
        for (text, expected) in refused {
            let message = error(text);
            assert!(message.starts_with(expected), "{text:?}: {message}");
        }
    }

    #[test]
    fn mutated_files_give_valid_meshes_or_errors() {
        let base = format!(
            "{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 1 0\no x\nf 1/1/1 2/2/1 3/3/2 4/1/1\n\
             g y\nf -1/-1/-1 -2//-2 -3/-2\nl 1 2 3\nv 1 2 3 0.5 0.5 0.5\nf 5 1 2\n"
        );
        let alphabet = b"-/0189 \n\rfvtnle.+#x\xff";
        let mut rng = prism_core::sampling::rng::Pcg32::seeded(7);
        for _ in 0..5000 {
            let mut bytes = base.clone().into_bytes();
            for _ in 0..1 + rng.next_bounded(3) {
                let at = rng.next_bounded(bytes.len() as u32) as usize;
                bytes[at] = alphabet[rng.next_bounded(alphabet.len() as u32) as usize];
            }
            if let Ok(mesh) = parse_obj(&bytes, Path::new("mesh.obj")) {
                mesh.validate(Path::new("mesh.obj")).unwrap();
            }
        }
    }

    #[test]
    fn latin1_comments_and_names_are_read_as_mitsuba_reads_them() {
        let text = b"# caf\xe9 cr\xe8me\no pi\xe8ce\nusemtl m\xe9tal\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let mesh = parse_obj(text, Path::new("mesh.obj")).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(mesh.positions[1], Vec3::X);
    }

    #[test]
    fn invalid_text_and_empty_meshes_are_errors() {
        let message = parse_obj(b"v 0 0 0\nv \xff 0 0\n", Path::new("mesh.obj")).unwrap_err();
        assert!(message.to_string().starts_with("mesh.obj:2:"), "{message}");
        let message = error(SQUARE);
        assert_eq!(message, "mesh.obj: the file has no faces");
        assert_eq!(error(""), "mesh.obj: the file has no faces");
    }
}
