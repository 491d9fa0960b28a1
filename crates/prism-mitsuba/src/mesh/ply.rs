//! Stanford PLY meshes (Turk 1994, "The PLY Polygon File Format"), as Mitsuba 3 reads them
//! (`src/shapes/ply.cpp`).
//!
//! A PLY file is a text header followed by a body in one of three formats:
//! ```text
//! ply
//! format binary_little_endian 1.0      (or ascii 1.0, binary_big_endian 1.0)
//! comment any text                     (obj_info lines are comments too)
//! element vertex 8                     (an element name and how many records follow)
//! property float x                     (a scalar property: type and name)
//! property list uchar int vertex_indices   (a list: length type, item type, name)
//! end_header
//! ```
//! The body holds each element's records in header order, each record its properties in order:
//! in ASCII as whitespace-separated numbers, in binary packed without padding, a list as its
//! length followed by its items. Scalar types are `char uchar short ushort int uint float double`,
//! also written `int8 uint8 int16 uint16 int32 uint32 float32 float64`, and Mitsuba's extensions
//! `long ulong half` (also `int64 uint64 float16`).
//!
//! What Prism reads:
//! - Element `vertex`: `x y z` (required), `nx ny nz` (all three, or none is used), and texture
//!   coordinates named `u v`, `texture_u texture_v`, `s t` or `texture_s texture_t` (the first
//!   complete pair, in that order). These must have floating-point types: Mitsuba would rescale
//!   integers to [0, 1], which is never what a position means. Texture coordinates are not
//!   flipped (Mitsuba flips only OBJ's). Vertex colours `r g b`, `red green blue`, `color_0
//!   color_1 color_2`, `color_1 color_2 color_3` or `color_x color_y color_z` (the first
//!   complete triple) become the `vertex_color` attribute, as Mitsuba's `find_other_fields`
//!   names them. Their channels are read as Mitsuba 3.9 reads them: floats as they are, `uchar`
//!   as its value 0–255 (not rescaled, though Mitsuba warns about it: such a colour reads as
//!   values above 1, clamped to 1 when upsampled), other integers divided by their type's
//!   largest value and decoded from sRGB. Other numbers named `{prefix}_{suffix}` become
//!   attributes of 1 or 3 channels as Mitsuba groups them (see `group_attributes`), read like
//!   colours; the rest are skipped.
//! - Element `face`: the list `vertex_indices` (or `vertex_index`) of integer indices into the
//!   vertices; each polygon, of 3 to 65536 vertices, is triangulated as a fan. Face colours and
//!   other attributes, named and read like the vertex ones, become the `face_color` and
//!   `face_{prefix}` attributes, one value per triangle of the fan. Other properties are
//!   skipped.
//! - Other elements are skipped. A file without faces is an error, and so is anything after the
//!   last element (as in Mitsuba).
//!
//! Errors give the header line, the body line for ASCII, or the byte offset for binary bodies.
//! Before anything is allocated, the header's counts are checked against the size of the body,
//! so that a corrupt count fails at once instead of exhausting memory.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::{MeshData, file_error};
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::geometry::shape::MeshAttribute;
use prism_core::image::srgb;

/// The most vertices a face may have; a longer list means a corrupt file.
const MAX_FACE_VERTICES: u64 = 1 << 16;

/// Parses the PLY file in `bytes`; `path` only names the file in messages.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<MeshData> {
    let header = parse_header(bytes, path)?;
    let layout = Layout::new(&header, path)?;
    check_body_size(&header, &layout, bytes.len(), path)?;
    match header.format {
        Format::Ascii => {
            let mut reader = AsciiReader::new(bytes, &header, path);
            read_body(&mut reader, &header, &layout)
        }
        Format::Binary(order) => {
            let mut reader = BinaryReader {
                bytes,
                position: header.body_start,
                value_start: header.body_start,
                order,
                path,
            };
            read_body(&mut reader, &header, &layout)
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The header

/// How the body is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    Binary(ByteOrder),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ByteOrder {
    Little,
    Big,
}

/// The scalar types a property can have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ScalarType {
    Int8,
    UInt8,
    Int16,
    UInt16,
    Int32,
    UInt32,
    Int64,
    UInt64,
    Float16,
    Float32,
    Float64,
}

impl ScalarType {
    fn from_name(name: &str) -> Option<Self> {
        use ScalarType::*;
        Some(match name {
            "char" | "int8" => Int8,
            "uchar" | "uint8" => UInt8,
            "short" | "int16" => Int16,
            "ushort" | "uint16" => UInt16,
            "int" | "int32" => Int32,
            "uint" | "uint32" => UInt32,
            "long" | "int64" => Int64,
            "ulong" | "uint64" => UInt64,
            "half" | "float16" => Float16,
            "float" | "float32" => Float32,
            "double" | "float64" => Float64,
            _ => return None,
        })
    }

    /// Size in bytes in a binary body.
    fn size(self) -> u64 {
        use ScalarType::*;
        match self {
            Int8 | UInt8 => 1,
            Int16 | UInt16 | Float16 => 2,
            Int32 | UInt32 | Float32 => 4,
            Int64 | UInt64 | Float64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(
            self,
            ScalarType::Float16 | ScalarType::Float32 | ScalarType::Float64
        )
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PropertyType {
    Scalar(ScalarType),
    /// A length of an integer type, then that many items.
    List {
        length: ScalarType,
        item: ScalarType,
    },
}

#[derive(Debug)]
struct Property {
    name: String,
    ty: PropertyType,
    /// 1-based header line.
    line: usize,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    /// 1-based header line.
    line: usize,
}

impl Element {
    fn property(&self, name: &str) -> Option<(usize, &Property)> {
        self.properties
            .iter()
            .enumerate()
            .find(|(_, p)| p.name == name)
    }
}

#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body_start: usize,
    /// 1-based line of `end_header`.
    end_line: usize,
}

/// An error at the start of a 1-based line of the header (or ASCII body).
fn line_error(path: &Path, line: usize, message: impl Into<String>) -> Error {
    let line = u32::try_from(line).unwrap_or(u32::MAX);
    Error::input(&SourceLocation::new(path, line, 1), message)
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    if !bytes.starts_with(b"ply") {
        return Err(line_error(
            path,
            1,
            "not a PLY file: the first line must be \"ply\"",
        ));
    }
    let mut offset = 0;
    let mut number = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let rest = bytes.get(offset..).unwrap_or_default();
        if rest.is_empty() {
            return Err(line_error(
                path,
                number,
                "the header ends without an \"end_header\" line",
            ));
        }
        let length = rest
            .iter()
            .position(|&b| b == b'\n')
            .map_or(rest.len(), |i| i + 1);
        let raw = &rest[..length];
        offset += length;
        number += 1;
        let error = |message: String| line_error(path, number, message);

        if number == 1 {
            if raw.trim_ascii_end() != b"ply" {
                return Err(error(
                    "not a PLY file: the first line must be \"ply\"".to_string(),
                ));
            }
            continue;
        }
        let line = std::str::from_utf8(raw)
            .map_err(|_| error("the header line is not valid text".to_string()))?;
        let mut words = line.split_ascii_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let mut word = |what: &str| {
            words
                .next()
                .ok_or_else(|| error(format!("the line ends where {what} should follow")))
        };
        match keyword {
            "comment" | "obj_info" => continue,
            "format" => {
                if format.is_some() {
                    return Err(error("a second \"format\" line".to_string()));
                }
                format = Some(match word("the format")? {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Binary(ByteOrder::Little),
                    "binary_big_endian" => Format::Binary(ByteOrder::Big),
                    other => {
                        return Err(error(format!("unknown format \"{other}\"")).with_help(
                            "the format is ascii, binary_little_endian or binary_big_endian",
                        ));
                    }
                });
                let version = word("the version")?;
                if version != "1.0" {
                    return Err(error(format!(
                        "unknown PLY version \"{version}\"; only 1.0 exists"
                    )));
                }
            }
            "element" => {
                let name = word("the element name")?.to_string();
                let count = word("the element count")?;
                let count = count.parse().map_err(|_| {
                    error(format!(
                        "the element count \"{count}\" is not a whole number"
                    ))
                })?;
                elements.push(Element {
                    name,
                    count,
                    properties: Vec::new(),
                    line: number,
                });
            }
            "property" => {
                let ty = match word("a type")? {
                    "list" => {
                        let length = scalar_type(word("the list's length type")?, number, path)?;
                        if !length.is_integer() {
                            return Err(error(
                                "the length of a list must have an integer type".to_string(),
                            ));
                        }
                        let item = scalar_type(word("the list's item type")?, number, path)?;
                        PropertyType::List { length, item }
                    }
                    name => PropertyType::Scalar(scalar_type(name, number, path)?),
                };
                let name = word("the property name")?.to_string();
                let element = elements
                    .last_mut()
                    .ok_or_else(|| error("a property before any \"element\" line".to_string()))?;
                element.properties.push(Property {
                    name,
                    ty,
                    line: number,
                });
            }
            "end_header" => {}
            other => return Err(error(format!("unknown header keyword \"{other}\""))),
        }
        if let Some(extra) = words.next() {
            return Err(error(format!(
                "unexpected \"{extra}\" at the end of the line"
            )));
        }
        if keyword == "end_header" {
            let format = format.ok_or_else(|| error("the header has no \"format\" line".into()))?;
            return Ok(Header {
                format,
                elements,
                body_start: offset,
                end_line: number,
            });
        }
    }
}

fn scalar_type(name: &str, line: usize, path: &Path) -> Result<ScalarType> {
    ScalarType::from_name(name).ok_or_else(|| {
        line_error(path, line, format!("unknown type \"{name}\"")).with_help(
            "the types are char, uchar, short, ushort, int, uint, float and double (or int8, \
             uint8, int16, uint16, int32, uint32, float32 and float64)",
        )
    })
}

// ---------------------------------------------------------------------------------------------
// What to do with each property

/// The per-vertex attributes Prism reads, and the faces' colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Attribute {
    Position = 0,
    Normal = 1,
    Uv = 2,
    Color = 3,
    FaceColor = 4,
}

/// How to read one property of a record.
#[derive(Clone, Copy, Debug)]
enum Field {
    /// Coordinate `axis` of a vertex attribute (or of the face colour).
    Vertex {
        attribute: Attribute,
        axis: usize,
        ty: ScalarType,
    },
    /// Channel `channel` of the attribute `index` of [`Layout::attributes`].
    Attribute {
        index: usize,
        channel: usize,
        ty: ScalarType,
    },
    /// The vertex indices of a face.
    Indices {
        length: ScalarType,
        item: ScalarType,
    },
    /// A property Prism does not use.
    Skip(PropertyType),
}

/// For each element of the header, the fields of its records.
struct Layout {
    fields: Vec<Vec<Field>>,
    /// Index of the vertex element.
    vertex_element: usize,
    vertex_count: u64,
    has_normals: bool,
    has_uvs: bool,
    has_colors: bool,
    has_face_colors: bool,
    /// Mitsuba's other attributes, found by [`group_attributes`].
    attributes: Vec<AttributeGroup>,
}

/// An attribute of Mitsuba's naming scheme: its name and number of channels (1 or 3), and
/// whether it belongs to the faces.
struct AttributeGroup {
    name: String,
    channels: usize,
    per_face: bool,
}

/// Alternative names of the vertex and face colour channels, in order of preference: Mitsuba's
/// unprefixed `r g b` and `red green blue`, then its prefixed groups that it names
/// `{vertex|face}_color`: the prefix `color` with the suffixes `0 1 2`, `1 2 3` or `x y z`
/// (with `r g b`, Mitsuba names the group `{vertex|face}_color_color`).
const COLOR_NAMES: [[&str; 3]; 5] = [
    ["r", "g", "b"],
    ["red", "green", "blue"],
    ["color_0", "color_1", "color_2"],
    ["color_1", "color_2", "color_3"],
    ["color_x", "color_y", "color_z"],
];

/// Alternative names of the texture coordinate pair, in order of preference.
const UV_NAMES: [[&str; 2]; 4] = [
    ["u", "v"],
    ["texture_u", "texture_v"],
    ["s", "t"],
    ["texture_s", "texture_t"],
];

impl Layout {
    fn new(header: &Header, path: &Path) -> Result<Layout> {
        let single = |name: &str| -> Result<Option<usize>> {
            let mut found = header
                .elements
                .iter()
                .enumerate()
                .filter(|(_, e)| e.name == name);
            let first = found.next().map(|(i, _)| i);
            match found.next() {
                Some((_, second)) => Err(line_error(
                    path,
                    second.line,
                    format!("a second \"{name}\" element"),
                )),
                None => Ok(first),
            }
        };
        let vertex_element = single("vertex")?.ok_or_else(|| {
            line_error(path, header.end_line, "the file has no \"vertex\" element")
        })?;
        let face_element = single("face")?
            .filter(|&i| header.elements[i].count > 0)
            .ok_or_else(|| {
                let line = header
                    .elements
                    .iter()
                    .find(|e| e.name == "face")
                    .map_or(header.end_line, |e| e.line);
                line_error(path, line, "the file has no faces")
            })?;

        let mut fields: Vec<Vec<Field>> = header
            .elements
            .iter()
            .map(|e| e.properties.iter().map(|p| Field::Skip(p.ty)).collect())
            .collect();

        let vertices = &header.elements[vertex_element];
        let faces = &header.elements[face_element];
        let mut read = |attribute: Attribute, names: &[&str]| -> Result<bool> {
            let (element_index, element, kind) = if attribute == Attribute::FaceColor {
                (face_element, faces, "face")
            } else {
                (vertex_element, vertices, "vertex")
            };
            let found: Vec<_> = names.iter().filter_map(|n| element.property(n)).collect();
            if found.len() < names.len() {
                return Ok(false);
            }
            for (axis, &(index, property)) in found.iter().enumerate() {
                let PropertyType::Scalar(ty) = property.ty else {
                    return Err(line_error(
                        path,
                        property.line,
                        format!(
                            "{kind} property \"{}\" must be a number, not a list",
                            property.name
                        ),
                    ));
                };
                if ty.is_integer() && !matches!(attribute, Attribute::Color | Attribute::FaceColor)
                {
                    return Err(line_error(
                        path,
                        property.line,
                        format!(
                            "vertex property \"{}\" has an integer type; Prism reads positions, \
                             normals and texture coordinates as float or double",
                            property.name
                        ),
                    ));
                }
                fields[element_index][index] = Field::Vertex {
                    attribute,
                    axis,
                    ty,
                };
            }
            Ok(true)
        };
        if !read(Attribute::Position, &["x", "y", "z"])? {
            return Err(line_error(
                path,
                vertices.line,
                "the vertex element needs the properties x, y and z",
            ));
        }
        let has_normals = read(Attribute::Normal, &["nx", "ny", "nz"])?;
        let mut has_uvs = false;
        for names in UV_NAMES {
            if read(Attribute::Uv, &names)? {
                has_uvs = true;
                break;
            }
        }

        let mut has_colors = false;
        for names in COLOR_NAMES {
            if read(Attribute::Color, &names)? {
                has_colors = true;
                break;
            }
        }

        let mut has_face_colors = false;
        for names in COLOR_NAMES {
            if read(Attribute::FaceColor, &names)? {
                has_face_colors = true;
                break;
            }
        }

        let (index, property) = faces
            .property("vertex_indices")
            .or_else(|| faces.property("vertex_index"))
            .ok_or_else(|| {
                line_error(
                    path,
                    faces.line,
                    "the face element has no \"vertex_indices\" list",
                )
            })?;
        match property.ty {
            PropertyType::List { length, item } if item.is_integer() => {
                fields[face_element][index] = Field::Indices { length, item };
            }
            _ => {
                return Err(line_error(
                    path,
                    property.line,
                    format!("\"{}\" must be a list of integers", property.name),
                ));
            }
        }

        let mut attributes = Vec::new();
        for (element, kind) in [(vertex_element, "vertex"), (face_element, "face")] {
            let properties = &header.elements[element].properties;
            group_attributes(properties, kind, &mut fields[element], &mut attributes);
        }

        Ok(Layout {
            fields,
            vertex_element,
            vertex_count: vertices.count,
            has_normals,
            has_uvs,
            has_colors,
            has_face_colors,
            attributes,
        })
    }
}

/// The suffixes of Mitsuba's attribute groups: `SUFFIXES[k][scheme]` is the suffix of the
/// k-th property of a group in one of the schemes `x y z w`, `r g b a`, `0 1 2 3`, `1 2 3 4`.
const SUFFIXES: [[u8; 4]; 4] = [*b"xr01", *b"yg12", *b"zb23", *b"wa34"];

/// Mitsuba's `find_other_fields` (`src/shapes/ply.h`): among the properties of an element that
/// Prism does not otherwise read, consecutive numbers `{prefix}_{suffix}` whose suffixes follow
/// one scheme of [`SUFFIXES`] form the attribute `{kind}_{prefix}` (`{kind}_{prefix}_color`
/// for `r g b a`). A group of 1 or 3 properties becomes an attribute of 1 or 3 channels; other
/// groups, a group whose suffixes break the scheme, and a prefix met again after its group are
/// skipped, as Mitsuba skips them (with a warning).
fn group_attributes(
    properties: &[Property],
    kind: &str,
    fields: &mut [Field],
    attributes: &mut Vec<AttributeGroup>,
) {
    struct Group<'a> {
        prefix: &'a str,
        scheme: usize,
        members: Vec<(usize, ScalarType)>,
    }
    let mut kept: Vec<String> = Vec::new();
    let mut group: Option<Group> = None;
    let mut skipped_prefix: Option<&str> = None;
    let mut flush = |group: &mut Option<Group>, fields: &mut [Field], kept: &mut Vec<String>| {
        let Some(Group {
            prefix,
            scheme,
            members,
        }) = group.take()
        else {
            return;
        };
        if members.len() != 1 && members.len() != 3 {
            return;
        }
        let index = attributes.len();
        for (channel, &(property, ty)) in members.iter().enumerate() {
            fields[property] = Field::Attribute { index, channel, ty };
        }
        let color = if scheme == 1 { "_color" } else { "" };
        attributes.push(AttributeGroup {
            name: format!("{kind}_{prefix}{color}"),
            channels: members.len(),
            per_face: kind == "face",
        });
        kept.push(prefix.to_string());
    };
    for (i, property) in properties.iter().enumerate() {
        let (Field::Skip(_), PropertyType::Scalar(ty)) = (fields[i], property.ty) else {
            continue;
        };
        let name = property.name.as_str();
        if let Some(prefix) = skipped_prefix {
            if name.starts_with(prefix) {
                continue;
            }
            skipped_prefix = None;
        }
        let Some((prefix, &[suffix])) = name.rsplit_once('_').map(|(p, s)| (p, s.as_bytes()))
        else {
            flush(&mut group, fields, &mut kept);
            continue;
        };
        if group.as_ref().is_some_and(|g| g.prefix != prefix) {
            flush(&mut group, fields, &mut kept);
        }
        match &mut group {
            None if kept.iter().any(|k| k == prefix) => skipped_prefix = Some(prefix),
            None => {
                if let Some(scheme) = SUFFIXES[0].iter().position(|&c| c == suffix) {
                    group = Some(Group {
                        prefix,
                        scheme,
                        members: vec![(i, ty)],
                    });
                }
            }
            Some(g) => {
                let k = g.members.len();
                if k < SUFFIXES.len() && SUFFIXES[k][g.scheme] == suffix {
                    g.members.push((i, ty));
                } else {
                    group = None;
                    skipped_prefix = Some(prefix);
                }
            }
        }
    }
    flush(&mut group, fields, &mut kept);
}

/// Refuses a header whose counts need more bytes than the body has, before anything is
/// allocated for them. A binary record takes at least the size of its scalars and list lengths
/// (and three indices for a face); an ASCII record at least two bytes (a digit and a
/// separator) per number.
fn check_body_size(header: &Header, layout: &Layout, file_size: usize, path: &Path) -> Result<()> {
    let ascii = header.format == Format::Ascii;
    let size = |ty: ScalarType| if ascii { 2 } else { ty.size() };
    // The last number of an ASCII file needs no separator.
    let available = (file_size.saturating_sub(header.body_start) + usize::from(ascii)) as u64;
    let mut needed: u64 = 0;
    for (element, fields) in header.elements.iter().zip(&layout.fields) {
        let record: u64 = fields
            .iter()
            .map(|field| match *field {
                Field::Vertex { ty, .. } | Field::Attribute { ty, .. } => size(ty),
                Field::Indices { length, item } => size(length) + 3 * size(item),
                Field::Skip(PropertyType::Scalar(ty)) => size(ty),
                Field::Skip(PropertyType::List { length, .. }) => size(length),
            })
            .sum();
        needed = record
            .checked_mul(element.count)
            .and_then(|n| n.checked_add(needed))
            .unwrap_or(u64::MAX);
        if needed > available {
            return Err(line_error(
                path,
                element.line,
                format!(
                    "the header declares {} \"{}\" records, but the file is too short to hold \
                     them: with what precedes them they need at least {needed} bytes, and \
                     {available} bytes follow the header",
                    element.count, element.name
                ),
            ));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// The body

/// A number read from the body, in the kind of its declared type.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Value {
    Signed(i64),
    Unsigned(u64),
    Float(f64),
}

impl Value {
    fn to_f64(self) -> f64 {
        match self {
            Value::Signed(v) => v as f64,
            Value::Unsigned(v) => v as f64,
            Value::Float(v) => v,
        }
    }
}

/// Reads the body's numbers one at a time, whatever its encoding.
trait BodyReader {
    /// The next number, of type `ty`.
    fn read(&mut self, ty: ScalarType) -> Result<Value>;
    /// An error about the number read last.
    fn error(&self, message: String) -> Error;
    /// Checks that nothing follows the last record.
    fn finish(&mut self) -> Result<()>;
}

const TRUNCATED: &str = "the file ends before all the records the header declares";

fn read_body(reader: &mut impl BodyReader, header: &Header, layout: &Layout) -> Result<MeshData> {
    let capacity = |count: u64| usize::try_from(count).unwrap_or(0);
    let vertex_capacity = capacity(layout.vertex_count);
    let mut mesh = MeshData {
        positions: Vec::with_capacity(vertex_capacity),
        normals: layout
            .has_normals
            .then(|| Vec::with_capacity(vertex_capacity)),
        uvs: layout.has_uvs.then(|| Vec::with_capacity(vertex_capacity)),
        colors: layout
            .has_colors
            .then(|| Vec::with_capacity(vertex_capacity)),
        face_colors: layout.has_face_colors.then(Vec::new),
        attributes: layout
            .attributes
            .iter()
            .map(|group| MeshAttribute {
                name: group.name.clone(),
                per_face: group.per_face,
                channels: group.channels as u8,
                values: Vec::new(),
            })
            .collect(),
        triangles: Vec::new(),
    };
    let mut polygon = Vec::new();
    let mut attribute_values = vec![Vec3::ZERO; layout.attributes.len()];
    for (i, (element, fields)) in header.elements.iter().zip(&layout.fields).enumerate() {
        if fields.is_empty() {
            continue;
        }
        if fields.iter().any(|f| matches!(f, Field::Indices { .. })) {
            mesh.triangles.reserve(capacity(element.count));
        }
        for _ in 0..element.count {
            let mut vertex = [[0.0f32; 3]; 5];
            let triangles_before = mesh.triangles.len();
            for field in fields {
                match *field {
                    Field::Vertex {
                        attribute,
                        axis,
                        ty,
                    } => {
                        let value = reader.read(ty)?;
                        let value = match attribute {
                            Attribute::Color | Attribute::FaceColor => color_channel(value, ty),
                            _ => value.to_f64() as f32,
                        };
                        if !value.is_finite() {
                            let what = match attribute {
                                Attribute::Position => "vertex coordinate",
                                Attribute::Normal => "normal",
                                Attribute::Uv => "texture coordinate",
                                Attribute::Color | Attribute::FaceColor => "colour",
                            };
                            return Err(reader.error(format!("{what} is not a finite number")));
                        }
                        vertex[attribute as usize][axis] = value;
                    }
                    Field::Attribute { index, channel, ty } => {
                        let value = color_channel(reader.read(ty)?, ty);
                        if !value.is_finite() {
                            let name = &layout.attributes[index].name;
                            return Err(reader.error(format!("{name} is not a finite number")));
                        }
                        attribute_values[index][channel] = value;
                    }
                    Field::Indices { length, item } => {
                        read_polygon(reader, length, item, layout.vertex_count, &mut polygon)?;
                        if let Some((&first, rest)) = polygon.split_first() {
                            let fan = rest.windows(2).map(|pair| [first, pair[0], pair[1]]);
                            mesh.triangles.extend(fan);
                        }
                    }
                    Field::Skip(ty) => skip(reader, ty)?,
                }
            }
            let triangles = mesh.triangles.len() - triangles_before;
            for (attribute, &value) in mesh.attributes.iter_mut().zip(&attribute_values) {
                let value = if attribute.channels == 1 {
                    Vec3::splat(value.x)
                } else {
                    value
                };
                if attribute.per_face {
                    attribute
                        .values
                        .extend(std::iter::repeat_n(value, triangles));
                } else if i == layout.vertex_element {
                    attribute.values.push(value);
                }
            }
            if let Some(face_colors) = &mut mesh.face_colors {
                let color = Vec3::from(vertex[Attribute::FaceColor as usize]);
                face_colors.extend(std::iter::repeat_n(color, triangles));
            }
            if i == layout.vertex_element {
                let [position, normal, uv, color, _] = vertex;
                mesh.positions.push(Vec3::from(position));
                if let Some(normals) = &mut mesh.normals {
                    normals.push(Vec3::from(normal));
                }
                if let Some(uvs) = &mut mesh.uvs {
                    uvs.push(Vec2::new(uv[0], uv[1]));
                }
                if let Some(colors) = &mut mesh.colors {
                    colors.push(Vec3::from(color));
                }
            }
        }
    }
    reader.finish()?;
    Ok(mesh)
}

/// A colour channel as Mitsuba 3.9 reads it (measured with its `scalar_rgb` variant): a float
/// as it is; an integer other than `uchar` divided by its type's largest value and decoded from
/// sRGB (`mitsuba::PLYMesh` marks integer properties normalised and gamma-encoded); a `uchar`
/// as its value 0–255, not rescaled.
fn color_channel(value: Value, ty: ScalarType) -> f32 {
    use ScalarType::*;
    let largest = match ty {
        Int8 => i8::MAX as f64,
        Int16 => i16::MAX as f64,
        UInt16 => u16::MAX as f64,
        Int32 => i32::MAX as f64,
        UInt32 => u32::MAX as f64,
        Int64 => i64::MAX as f64,
        UInt64 => u64::MAX as f64,
        UInt8 | Float16 | Float32 | Float64 => return value.to_f64() as f32,
    };
    srgb::decode((value.to_f64() / largest) as f32)
}

/// Reads a number of an integer type that must not be negative.
fn read_unsigned(reader: &mut impl BodyReader, ty: ScalarType, what: &str) -> Result<u64> {
    match reader.read(ty)? {
        Value::Unsigned(v) => Ok(v),
        Value::Signed(v) => {
            u64::try_from(v).map_err(|_| reader.error(format!("{what} {v} is negative")))
        }
        Value::Float(v) => Err(reader.error(format!("{what} {v} is not an integer"))),
    }
}

/// Reads one face's vertex index list into `polygon`.
fn read_polygon(
    reader: &mut impl BodyReader,
    length: ScalarType,
    item: ScalarType,
    vertex_count: u64,
    polygon: &mut Vec<u32>,
) -> Result<()> {
    let n = read_unsigned(reader, length, "the face's vertex count")?;
    if n < 3 {
        return Err(reader.error(format!("a face of {n} vertices; a face needs at least 3")));
    }
    if n > MAX_FACE_VERTICES {
        return Err(reader.error(format!(
            "a face of {n} vertices; Prism accepts at most {MAX_FACE_VERTICES}"
        )));
    }
    polygon.clear();
    for _ in 0..n {
        let index = read_unsigned(reader, item, "vertex index")?;
        match u32::try_from(index) {
            Ok(index) if u64::from(index) < vertex_count => polygon.push(index),
            _ => {
                return Err(reader.error(format!(
                    "face refers to vertex {index}, but the file has {vertex_count} vertices \
                     (the first is 0)"
                )));
            }
        }
    }
    Ok(())
}

fn skip(reader: &mut impl BodyReader, ty: PropertyType) -> Result<()> {
    match ty {
        PropertyType::Scalar(ty) => {
            reader.read(ty)?;
        }
        PropertyType::List { length, item } => {
            for _ in 0..read_unsigned(reader, length, "list length")? {
                reader.read(item)?;
            }
        }
    }
    Ok(())
}

/// An ASCII body: numbers separated by whitespace, read as a stream of words (line breaks
/// between records are customary, not required).
struct AsciiReader<'a> {
    bytes: &'a [u8],
    position: usize,
    /// 1-based line and byte offset of the line start, at `position`.
    line: usize,
    line_start: usize,
    /// Line and column of the word read last.
    word_line: usize,
    word_column: usize,
    path: &'a Path,
}

impl<'a> AsciiReader<'a> {
    fn new(bytes: &'a [u8], header: &Header, path: &'a Path) -> Self {
        AsciiReader {
            bytes,
            position: header.body_start,
            line: header.end_line + 1,
            line_start: header.body_start,
            word_line: header.end_line,
            word_column: 1,
            path,
        }
    }

    /// The next whitespace-separated word.
    fn word(&mut self) -> Option<&'a [u8]> {
        let bytes = self.bytes;
        while let Some(&b) = bytes.get(self.position) {
            if !b.is_ascii_whitespace() {
                break;
            }
            self.position += 1;
            if b == b'\n' {
                self.line += 1;
                self.line_start = self.position;
            }
        }
        let start = self.position;
        while bytes
            .get(self.position)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.position += 1;
        }
        self.word_line = self.line;
        self.word_column = start - self.line_start + 1;
        bytes.get(start..self.position).filter(|w| !w.is_empty())
    }
}

/// A word for a message: short, and readable whatever bytes it holds.
fn quote(word: &[u8]) -> String {
    let text = String::from_utf8_lossy(word);
    match text.char_indices().nth(24) {
        Some((cut, _)) => format!("\"{}...\"", &text[..cut]),
        None => format!("\"{text}\""),
    }
}

impl BodyReader for AsciiReader<'_> {
    fn read(&mut self, ty: ScalarType) -> Result<Value> {
        let word = self.word().ok_or_else(|| self.error(TRUNCATED.into()))?;
        let text = std::str::from_utf8(word).unwrap_or_default();
        let (min, max): (i64, u64) = match ty {
            ScalarType::Int8 => (i8::MIN.into(), i8::MAX as u64),
            ScalarType::UInt8 => (0, u8::MAX.into()),
            ScalarType::Int16 => (i16::MIN.into(), i16::MAX as u64),
            ScalarType::UInt16 => (0, u16::MAX.into()),
            ScalarType::Int32 => (i32::MIN.into(), i32::MAX as u64),
            ScalarType::UInt32 => (0, u32::MAX.into()),
            ScalarType::Int64 => (i64::MIN, i64::MAX as u64),
            ScalarType::UInt64 => (0, u64::MAX),
            ScalarType::Float16 | ScalarType::Float32 | ScalarType::Float64 => {
                return text
                    .parse()
                    .map(Value::Float)
                    .map_err(|_| self.error(format!("{} is not a number", quote(word))));
            }
        };
        let value = if min < 0 {
            text.parse::<i64>()
                .ok()
                .filter(|&v| v >= min && v <= max as i64)
                .map(Value::Signed)
        } else {
            text.parse::<u64>()
                .ok()
                .filter(|&v| v <= max)
                .map(Value::Unsigned)
        };
        value.ok_or_else(|| {
            self.error(format!(
                "{} is not an integer from {min} to {max}",
                quote(word)
            ))
        })
    }

    fn error(&self, message: String) -> Error {
        let line = u32::try_from(self.word_line).unwrap_or(u32::MAX);
        let column = u32::try_from(self.word_column).unwrap_or(u32::MAX);
        Error::input(&SourceLocation::new(self.path, line, column), message)
    }

    fn finish(&mut self) -> Result<()> {
        match self.word() {
            Some(word) => Err(self.error(format!(
                "unexpected {} after the last record the header declares",
                quote(word)
            ))),
            None => Ok(()),
        }
    }
}

/// A binary body: numbers packed in the given byte order.
struct BinaryReader<'a> {
    bytes: &'a [u8],
    position: usize,
    /// Where the number read last starts.
    value_start: usize,
    order: ByteOrder,
    path: &'a Path,
}

impl BinaryReader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        self.value_start = self.position;
        let bytes = self
            .bytes
            .get(self.position..)
            .and_then(|rest| rest.first_chunk::<N>())
            .ok_or_else(|| self.error(TRUNCATED.into()))?;
        self.position += N;
        Ok(*bytes)
    }
}

/// Decodes the next number of Rust type `$t` in the reader's byte order.
macro_rules! decode {
    ($reader:expr, $t:ty) => {{
        let bytes = $reader.take::<{ size_of::<$t>() }>()?;
        match $reader.order {
            ByteOrder::Little => <$t>::from_le_bytes(bytes),
            ByteOrder::Big => <$t>::from_be_bytes(bytes),
        }
    }};
}

impl BodyReader for BinaryReader<'_> {
    fn read(&mut self, ty: ScalarType) -> Result<Value> {
        use Value::*;
        Ok(match ty {
            ScalarType::Int8 => Signed(decode!(self, i8).into()),
            ScalarType::UInt8 => Unsigned(decode!(self, u8).into()),
            ScalarType::Int16 => Signed(decode!(self, i16).into()),
            ScalarType::UInt16 => Unsigned(decode!(self, u16).into()),
            ScalarType::Int32 => Signed(decode!(self, i32).into()),
            ScalarType::UInt32 => Unsigned(decode!(self, u32).into()),
            ScalarType::Int64 => Signed(decode!(self, i64)),
            ScalarType::UInt64 => Unsigned(decode!(self, u64)),
            ScalarType::Float16 => Float(f16_to_f32(decode!(self, u16)).into()),
            ScalarType::Float32 => Float(decode!(self, f32).into()),
            ScalarType::Float64 => Float(decode!(self, f64)),
        })
    }

    fn error(&self, message: String) -> Error {
        file_error(
            self.path,
            format!("at byte {}: {message}", self.value_start),
        )
    }

    fn finish(&mut self) -> Result<()> {
        let extra = self.bytes.len().saturating_sub(self.position);
        if extra > 0 {
            self.value_start = self.position;
            return Err(self.error(format!(
                "{extra} bytes follow the last record the header declares"
            )));
        }
        Ok(())
    }
}

/// An IEEE 754 half-precision number, exactly.
fn f16_to_f32(bits: u16) -> f32 {
    let sign = if bits & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((bits >> 10) & 0x1f);
    let mantissa = f32::from(bits & 0x3ff);
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        _ => (1.0 + mantissa / 1024.0) * 2f32.powi(exponent - 15),
    }
}

#[cfg(test)]
mod tests {
    use std::time::Instant;

    use super::*;

    fn parse(bytes: &[u8]) -> Result<MeshData> {
        parse_ply(bytes, Path::new("mesh.ply"))
    }

    fn error(bytes: &[u8]) -> String {
        parse(bytes).unwrap_err().to_string()
    }

    /// A file with the given header lines (between `format` and `end_header`) and a body of
    /// (type, value) pairs, encoded in `format`.
    fn ply(format: &str, header: &str, values: &[(&str, f64)]) -> Vec<u8> {
        let mut bytes = format!("ply\nformat {format} 1.0\n{header}end_header\n").into_bytes();
        let big = format == "binary_big_endian";
        for &(ty, v) in values {
            macro_rules! put {
                ($t:ty) => {
                    bytes.extend_from_slice(&if big {
                        (v as $t).to_be_bytes()
                    } else {
                        (v as $t).to_le_bytes()
                    })
                };
            }
            match (format, ty) {
                ("ascii", _) => bytes.extend_from_slice(format!("{v} ").as_bytes()),
                (_, "char") => put!(i8),
                (_, "uchar") => put!(u8),
                (_, "short") => put!(i16),
                (_, "ushort") => put!(u16),
                (_, "int") => put!(i32),
                (_, "uint") => put!(u32),
                (_, "float") => put!(f32),
                (_, "double") => put!(f64),
                _ => panic!("no type {ty}"),
            }
        }
        bytes
    }

    /// A unit square (a quad) and a triangle on it, with normals, texture coordinates, a
    /// colour, a face flag and an extra element holding a list.
    fn square(format: &str, float: &str, length: &str, index: &str) -> Vec<u8> {
        let header = format!(
            "comment a square\nelement vertex 4\nproperty {float} x\nproperty {float} y\n\
             property {float} z\nproperty uchar red\nproperty float nx\nproperty float ny\n\
             property float nz\nproperty float u\nproperty float v\nelement face 2\n\
             property list {length} {index} vertex_indices\nproperty uchar flags\n\
             element edge 2\nproperty list int int vertex_pair\nproperty float crease\n"
        );
        let mut values = Vec::new();
        for [x, y] in [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]] {
            values.extend([(float, x), (float, y), (float, 0.0), ("uchar", 200.0)]);
            values.extend([("float", 0.0), ("float", 0.0), ("float", 1.0)]);
            values.extend([("float", x), ("float", y)]);
        }
        values.push((length, 4.0));
        values.extend([0.0, 1.0, 2.0, 3.0].map(|i| (index, i)));
        values.extend([("uchar", 7.0), (length, 3.0)]);
        values.extend([3.0, 1.0, 2.0].map(|i| (index, i)));
        values.push(("uchar", 1.0));
        values.extend([("int", 2.0), ("int", 0.0), ("int", 1.0), ("float", 0.5)]);
        values.extend([
            ("int", 3.0),
            ("int", 0.0),
            ("int", 1.0),
            ("int", 2.0),
            ("float", 1.5),
        ]);
        ply(format, &header, &values)
    }

    fn expected_square() -> MeshData {
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        MeshData {
            positions: corners.iter().map(|&[x, y]| Vec3::new(x, y, 0.0)).collect(),
            normals: Some(vec![Vec3::Z; 4]),
            uvs: Some(corners.iter().map(|&c| Vec2::from(c)).collect()),
            colors: None,
            face_colors: None,
            attributes: Vec::new(),
            triangles: vec![[0, 1, 2], [0, 2, 3], [3, 1, 2]],
        }
    }

    const FORMATS: [&str; 3] = ["ascii", "binary_little_endian", "binary_big_endian"];

    #[test]
    fn the_three_formats_read_alike() {
        for format in FORMATS {
            let mesh = parse(&square(format, "float", "uchar", "int")).unwrap();
            assert_eq!(mesh, expected_square(), "{format}");
        }
    }

    #[test]
    fn double_coordinates_and_other_list_types() {
        for format in FORMATS {
            for (float, length, index) in [
                ("double", "uchar", "int"),
                ("double", "int", "uint"),
                ("float", "ushort", "ushort"),
                ("float", "char", "short"),
                ("float", "uint", "uchar"),
            ] {
                let mesh = parse(&square(format, float, length, index)).unwrap();
                assert_eq!(mesh, expected_square(), "{format} {float} {length} {index}");
            }
        }
    }

    /// Face colours become one colour per triangle of each face's fan, wherever the colour
    /// properties stand in the face record and whatever their names and types.
    #[test]
    fn face_colours_repeat_over_each_fan() {
        let vertices = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
            .iter()
            .flat_map(|&[x, y]| [("float", x), ("float", y), ("float", 0.0)])
            .collect::<Vec<_>>();
        let vertex_header = "element vertex 4\nproperty float x\nproperty float y\n\
                             property float z\nelement face 2\n";
        for format in FORMATS {
            // Colours after the indices, as float r g b.
            let header = format!(
                "{vertex_header}property list uchar int vertex_indices\nproperty float r\n\
                 property float g\nproperty float b\n"
            );
            let mut values = vertices.clone();
            values.extend([("uchar", 4.0), ("int", 0.0), ("int", 1.0)]);
            values.extend([("int", 2.0), ("int", 3.0)]);
            values.extend([("float", 0.25), ("float", 0.5), ("float", 0.75)]);
            values.extend([("uchar", 3.0), ("int", 3.0), ("int", 1.0), ("int", 2.0)]);
            values.extend([("float", 1.0), ("float", 0.0), ("float", 0.125)]);
            let mesh = parse(&ply(format, &header, &values)).unwrap();
            assert_eq!(
                mesh.triangles,
                [[0, 1, 2], [0, 2, 3], [3, 1, 2]],
                "{format}"
            );
            let (a, b) = (Vec3::new(0.25, 0.5, 0.75), Vec3::new(1.0, 0.0, 0.125));
            assert_eq!(mesh.face_colors, Some(vec![a, a, b]), "{format}");
            assert_eq!(mesh.colors, None, "{format}");
            mesh.validate(Path::new("mesh.ply")).unwrap();

            // Colours before the indices, as uchar red green blue: values, not rescaled.
            let header = format!(
                "{vertex_header}property uchar red\nproperty uchar green\n\
                 property uchar blue\nproperty list uchar int vertex_indices\n"
            );
            let mut values = vertices.clone();
            values.extend([("uchar", 1.0), ("uchar", 2.0), ("uchar", 255.0)]);
            values.extend([("uchar", 3.0), ("int", 0.0), ("int", 1.0), ("int", 2.0)]);
            values.extend([("uchar", 0.0), ("uchar", 0.0), ("uchar", 0.0)]);
            values.extend([("uchar", 3.0), ("int", 0.0), ("int", 2.0), ("int", 3.0)]);
            let mesh = parse(&ply(format, &header, &values)).unwrap();
            assert_eq!(
                mesh.face_colors,
                Some(vec![Vec3::new(1.0, 2.0, 255.0), Vec3::ZERO]),
                "{format}"
            );
        }
        // A colour that is a list is refused with its header line.
        let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                      element face 1\nproperty list uchar int vertex_indices\n\
                      property list uchar float r\nproperty float g\nproperty float b\n";
        let message = error(&ply("ascii", header, &[]));
        assert!(
            message.contains("mesh.ply:9") && message.contains("face property \"r\""),
            "{message}"
        );
    }

    /// Colour channels of each type read as Mitsuba 3.9.1 reads them. The expected values are
    /// its renders (`scalar_rgb`, a diffuse quad with the colour as its `mesh_attribute`
    /// reflectance, under a constant emitter, 16 spp), divided by the render of a channel of
    /// float value 1: `char` 64 → 0.2177031, `short` 16384 → 0.2140551, `ushort` 32768 →
    /// 0.2140481, `uint` 128 → 2.306681e-9, `int` 128 → 4.613362e-9, `uchar` 128 → 128.0000
    /// and 64 → 64.0000. They agree with the closed form (v / largest, then sRGB decoding) to 1e-6
    /// relative.
    #[test]
    fn integer_colour_channels_read_as_mitsuba_reads_them() {
        let cases: [(&str, [f64; 3], [f32; 3]); 6] = [
            ("char", [64.0, 0.0, 127.0], [0.217_703_1, 0.0, 1.0]),
            ("short", [16384.0, 0.0, 32767.0], [0.214_055_1, 0.0, 1.0]),
            ("ushort", [32768.0, 0.0, 65535.0], [0.214_048_1, 0.0, 1.0]),
            ("uint", [128.0, 0.0, 4294967295.0], [2.306_681e-9, 0.0, 1.0]),
            ("int", [128.0, 0.0, 2147483647.0], [4.613_362e-9, 0.0, 1.0]),
            ("uchar", [128.0, 64.0, 255.0], [128.0, 64.0, 255.0]),
        ];
        for format in FORMATS {
            for (ty, channels, expected) in cases {
                for (kind, names) in [
                    ("vertex", ["r", "g", "b"]),
                    ("face", ["red", "green", "blue"]),
                ] {
                    let color_header = names.map(|n| format!("property {ty} {n}\n")).concat();
                    let (vertex_colors, face_colors) = if kind == "vertex" {
                        (color_header.as_str(), "")
                    } else {
                        ("", color_header.as_str())
                    };
                    let header = format!(
                        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                         {vertex_colors}element face 1\nproperty list uchar int vertex_indices\n\
                         {face_colors}"
                    );
                    let color = channels.map(|c| (ty, c));
                    let mut values = Vec::new();
                    for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] {
                        values.extend([("float", corner[0]), ("float", corner[1]), ("float", 0.0)]);
                        if kind == "vertex" {
                            values.extend(color);
                        }
                    }
                    values.extend([("uchar", 3.0), ("int", 0.0), ("int", 1.0), ("int", 2.0)]);
                    if kind == "face" {
                        values.extend(color);
                    }
                    let mesh = parse(&ply(format, &header, &values)).unwrap();
                    let read = if kind == "vertex" {
                        mesh.colors.unwrap()[2]
                    } else {
                        mesh.face_colors.unwrap()[0]
                    };
                    for (got, want) in read.to_array().into_iter().zip(expected) {
                        assert!(
                            (got - want).abs() <= 2e-6 * want,
                            "{format} {ty} {kind}: {read} against {expected:?}"
                        );
                    }
                }
            }
        }
    }

    /// Mitsuba's prefixed colour groups named `vertex_color` and `face_color`, as its
    /// `write_ply` writes them (`color_0 color_1 color_2`); `color_r color_g color_b` is
    /// Mitsuba's `vertex_color_color`, not a colour Prism reads.
    #[test]
    fn prefixed_colour_groups() {
        for suffixes in [["0", "1", "2"], ["1", "2", "3"], ["x", "y", "z"]] {
            let names = suffixes
                .map(|s| format!("property float color_{s}\n"))
                .concat();
            let header = format!(
                "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                 {names}element face 1\nproperty list uchar int vertex_indices\n{names}"
            );
            let mut values = Vec::new();
            for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] {
                values.extend([("float", corner[0]), ("float", corner[1]), ("float", 0.0)]);
                values.extend([("float", 0.25), ("float", 0.5), ("float", corner[0])]);
            }
            values.extend([("uchar", 3.0), ("int", 0.0), ("int", 1.0), ("int", 2.0)]);
            values.extend([("float", 0.125), ("float", 0.375), ("float", 0.625)]);
            for format in FORMATS {
                let mesh = parse(&ply(format, &header, &values)).unwrap();
                let colors = mesh.colors.as_deref().unwrap();
                assert_eq!(
                    colors[1],
                    Vec3::new(0.25, 0.5, 1.0),
                    "{format} {suffixes:?}"
                );
                assert_eq!(
                    mesh.face_colors,
                    Some(vec![Vec3::new(0.125, 0.375, 0.625)]),
                    "{format} {suffixes:?}"
                );
            }
        }
        let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                      property float color_r\nproperty float color_g\nproperty float color_b\n\
                      element face 1\nproperty list uchar int vertex_indices\n";
        let mut values = Vec::new();
        for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] {
            values.extend([("float", corner[0]), ("float", corner[1]), ("float", 0.0)]);
            values.extend([("float", 0.5); 3]);
        }
        values.extend([("uchar", 3.0), ("int", 0.0), ("int", 1.0), ("int", 2.0)]);
        assert_eq!(parse(&ply("ascii", header, &values)).unwrap().colors, None);
    }

    /// Other properties grouped as Mitsuba's `find_other_fields` groups them.
    #[test]
    fn other_properties_are_grouped_into_attributes_as_mitsuba_does() {
        let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                      property float foo_x\nproperty float foo_y\nproperty float foo_z\n\
                      property float bar_r\nproperty float bar_g\nproperty float bar_b\n\
                      property float two_0\nproperty float two_1\n\
                      property float bad_x\nproperty float bad_z\n\
                      property ushort level_1\nproperty float plain\n\
                      property float foo_0\n\
                      element face 1\nproperty float weight_0\n\
                      property list uchar int vertex_indices\n";
        let mut values = Vec::new();
        for corner in [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] {
            values.extend([("float", corner[0]), ("float", corner[1]), ("float", 0.0)]);
            values.extend([("float", 1.0), ("float", 2.0), ("float", corner[0])]);
            values.extend([("float", 0.5), ("float", 0.25), ("float", 0.125)]);
            values.extend([
                ("float", 7.0),
                ("float", 8.0),
                ("float", 9.0),
                ("float", 9.0),
            ]);
            values.extend([("ushort", 65535.0), ("float", 3.0), ("float", 4.0)]);
        }
        values.extend([("float", 0.3), ("uchar", 3.0), ("int", 0.0), ("int", 1.0)]);
        values.push(("int", 2.0));
        for format in FORMATS {
            let mesh = parse(&ply(format, header, &values)).unwrap();
            let summary: Vec<_> = mesh
                .attributes
                .iter()
                .map(|a| {
                    (
                        a.name.as_str(),
                        a.per_face,
                        a.channels,
                        *a.values.last().unwrap(),
                    )
                })
                .collect();
            assert_eq!(
                summary,
                [
                    ("vertex_foo", false, 3, Vec3::new(1.0, 2.0, 0.0)),
                    ("vertex_bar_color", false, 3, Vec3::new(0.5, 0.25, 0.125)),
                    ("vertex_level", false, 1, Vec3::ONE),
                    ("face_weight", true, 1, Vec3::splat(0.3)),
                ]
                .to_vec(),
                "{format}"
            );
            mesh.validate(Path::new("mesh.ply")).unwrap();
        }
    }

    #[test]
    fn alternative_type_and_property_names() {
        let header = "obj_info scanned\n\nelement vertex 3\nproperty float32 x\nproperty float32 y\n\
                      property float32 z\nproperty float32 s\nproperty float32 t\nproperty float32 nx\n\
                      element face 1\nproperty list uint8 int32 vertex_index\n";
        let mesh = parse(&ply(
            "ascii",
            header,
            &[
                ("", 0.0),
                ("", 0.0),
                ("", 0.0),
                ("", 0.25),
                ("", 0.5),
                ("", 9.0),
            ]
            .iter()
            .chain(&[
                ("", 1.0),
                ("", 0.0),
                ("", 0.0),
                ("", 1.0),
                ("", 0.0),
                ("", 9.0),
            ])
            .chain(&[
                ("", 0.0),
                ("", 1.0),
                ("", 0.0),
                ("", 0.0),
                ("", 1.0),
                ("", 9.0),
            ])
            .chain(&[("", 3.0), ("", 0.0), ("", 1.0), ("", 2.0)])
            .copied()
            .collect::<Vec<_>>(),
        ))
        .unwrap();
        assert_eq!(mesh.triangles, [[0, 1, 2]]);
        assert_eq!(mesh.uvs.unwrap()[0], Vec2::new(0.25, 0.5));
        // nx alone is not a normal.
        assert_eq!(mesh.normals, None);
    }

    #[test]
    fn header_windows_line_ends_and_half_floats() {
        let mut bytes = b"ply\r\nformat binary_little_endian 1.0\r\nelement vertex 3\r\n\
                          property half x\r\nproperty half y\r\nproperty half z\r\n\
                          element face 1\r\nproperty list uchar uint vertex_indices\r\nend_header\r\n"
            .to_vec();
        // 0, 1, 0.5 and -2 as half floats.
        for bits in [[0u16, 0x3c00, 0], [0x3800, 0, 0], [0xc000, 0, 0x3c00]] {
            bits.iter().for_each(|b| bytes.extend(b.to_le_bytes()));
        }
        bytes.push(3);
        [0u32, 1, 2]
            .iter()
            .for_each(|i| bytes.extend(i.to_le_bytes()));
        let mesh = parse(&bytes).unwrap();
        assert_eq!(
            mesh.positions,
            [
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.5, 0.0, 0.0),
                Vec3::new(-2.0, 0.0, 1.0)
            ]
        );
    }

    #[test]
    fn half_floats_convert_exactly() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    #[test]
    fn truncated_binary_files_are_errors_with_the_offset() {
        let bytes = square("binary_little_endian", "float", "uchar", "int");
        let body_start = bytes
            .windows(11)
            .position(|w| w == b"end_header\n")
            .unwrap()
            + 11;
        let message = error(&bytes[..bytes.len() - 2]);
        let last_float = bytes.len() - 4;
        assert_eq!(
            message,
            format!(
                "mesh.ply: at byte {last_float}: the file ends before all the records the \
                 header declares"
            )
        );
        // Every prefix is an error, and none panics; so is every prefix plus a byte.
        for length in 0..bytes.len() {
            assert!(parse(&bytes[..length]).is_err(), "{length}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        let message = error(&longer);
        assert_eq!(
            message,
            format!(
                "mesh.ply: at byte {}: 1 bytes follow the last record the header declares",
                bytes.len()
            )
        );
        assert!(body_start < last_float);
    }

    #[test]
    fn corrupted_files_give_valid_meshes_or_errors() {
        let mut rng = prism_core::sampling::rng::Pcg32::seeded(3);
        for format in FORMATS {
            let base = square(format, "float", "uchar", "int");
            for _ in 0..3000 {
                let mut bytes = base.clone();
                for _ in 0..1 + rng.next_bounded(3) {
                    let at = rng.next_bounded(bytes.len() as u32) as usize;
                    bytes[at] = match rng.next_bounded(4) {
                        0 => 0xff,
                        1 => b"0123456789 -.e\n"[rng.next_bounded(15) as usize],
                        _ => rng.next_u32() as u8,
                    };
                }
                if let Ok(mesh) = parse(&bytes) {
                    mesh.validate(Path::new("mesh.ply")).unwrap();
                }
            }
        }
    }

    #[test]
    fn absurd_counts_are_refused_before_allocating() {
        let start = Instant::now();
        for format in FORMATS {
            let header = "element vertex 1000000000000\nproperty float x\nproperty float y\n\
                          property float z\nelement face 1\nproperty list uchar int vertex_indices\n";
            let message = error(&ply(format, header, &[("float", 0.0); 9]));
            assert!(message.starts_with("mesh.ply:3:1: the header declares 1000000000000 \"vertex\" records, but the file is too short"), "{message}");

            let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                          element face 18446744073709551615\nproperty list uchar int vertex_indices\n";
            let message = error(&ply(format, header, &[("float", 0.0); 9]));
            assert!(
                message
                    .starts_with("mesh.ply:7:1: the header declares 18446744073709551615 \"face\""),
                "{message}"
            );

            // A skipped list claiming four billion items ends with the data.
            let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                          property list uint uchar junk\nelement face 1\n\
                          property list uchar int vertex_indices\n";
            let values = [
                ("float", 0.0),
                ("float", 0.0),
                ("float", 0.0),
                ("uint", 4e9),
            ];
            let face = [("uchar", 3.0), ("int", 0.0), ("int", 1.0), ("int", 2.0)];
            let message = error(&ply(
                format,
                header,
                &[values.repeat(3), face.to_vec()].concat(),
            ));
            let expected = match format {
                "ascii" => "mesh.ply:11:24: \"4000000000\" is not an integer from 0 to 255",
                _ => "the file ends before",
            };
            assert!(message.contains(expected), "{message}");
        }
        assert!(start.elapsed().as_secs_f64() < 1.0);
    }

    #[test]
    fn faces_are_checked() {
        let vertices = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
        let header = format!("{vertices}element face 1\nproperty list uchar int vertex_indices\n");
        let body = "0 0 0\n1 0 0\n0 1 0\n";
        let ascii =
            |faces: &str| format!("ply\nformat ascii 1.0\n{header}end_header\n{body}{faces}");
        let cases = [
            (
                "3 0 1 3\n",
                "mesh.ply:13:7: face refers to vertex 3, but the file has 3 vertices",
            ),
            ("3 0 -1 2\n", "mesh.ply:13:5: vertex index -1 is negative"),
            (
                "2 0 1  \n",
                "mesh.ply:13:1: a face of 2 vertices; a face needs at least 3",
            ),
            (
                "256 0 1 2\n",
                "mesh.ply:13:1: \"256\" is not an integer from 0 to 255",
            ),
            (
                "3 0 1 2 7\n",
                "mesh.ply:13:9: unexpected \"7\" after the last record",
            ),
            (
                "3 0 1  \n",
                "mesh.ply:14:1: the file ends before all the records",
            ),
            (
                "3 0 1\n",
                "mesh.ply:7:1: the header declares 1 \"face\" records, but the file is too short",
            ),
        ];
        for (faces, expected) in cases {
            let message = error(ascii(faces).as_bytes());
            assert!(message.starts_with(expected), "{faces:?}: {message}");
        }

        let header = format!("{vertices}element face 1\nproperty list int int vertex_indices\n");
        let zeros = [("float", 0.0); 9];
        for format in ["binary_little_endian", "binary_big_endian"] {
            let face = |indices: &[f64]| {
                let mut values = zeros.to_vec();
                values.push(("int", indices.len() as f64));
                values.extend(indices.iter().map(|&i| ("int", i)));
                ply(format, &header, &values)
            };
            // The third index follows the length and two indices.
            let third_index = face(&[]).len() + 8;
            let message = error(&face(&[0.0, 1.0, 9.0]));
            assert_eq!(
                message,
                format!(
                    "mesh.ply: at byte {}: face refers to vertex 9, but the file has 3 vertices \
                     (the first is 0)",
                    third_index
                )
            );
            let message = error(&face(&[0.0, -1.0, 2.0]));
            assert!(
                message.ends_with("vertex index -1 is negative"),
                "{message}"
            );
            let mut huge = face(&[]);
            let length = huge.len() - 4;
            let count = ((1u32 << 16) + 1).to_le_bytes();
            let count = if format == "binary_big_endian" {
                ((1u32 << 16) + 1).to_be_bytes()
            } else {
                count
            };
            huge[length..].copy_from_slice(&count);
            huge.extend(vec![0; 4 * ((1 << 16) + 1)]);
            let message = error(&huge);
            assert!(
                message.ends_with("a face of 65537 vertices; Prism accepts at most 65536"),
                "{message}"
            );
        }
    }

    #[test]
    fn ascii_numbers_are_checked_with_their_line() {
        let header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                      element face 1\nproperty list uchar int vertex_indices\n";
        let file = |body: &str| format!("ply\nformat ascii 1.0\n{header}end_header\n{body}");
        let message = error(file("0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n").as_bytes());
        assert!(
            message.starts_with("mesh.ply:11:3: vertex coordinate is not a finite number"),
            "{message}"
        );
        let message = error(file("0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n").as_bytes());
        assert!(
            message.starts_with("mesh.ply:11:3: \"x\" is not a number"),
            "{message}"
        );
        let message = error(file("0 0 0 1 1e39 0 0 1 0 3 0 1 2").as_bytes());
        assert!(
            message.starts_with("mesh.ply:10:9: vertex coordinate is not a finite"),
            "{message}"
        );
        // Records need not be one per line.
        parse(file("0 0 0 1 0 0 0 1 0 3 0 1 2").as_bytes()).unwrap();
    }

    #[test]
    fn header_errors_name_the_line() {
        let vertices = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
        let faces = "element face 1\nproperty list uchar int vertex_indices\n";
        let cases: [(&[u8], &str); 17] = [
            (b"", "mesh.ply:1:1: not a PLY file"),
            (b"PLY\n", "mesh.ply:1:1: not a PLY file"),
            (b"plyx\n", "mesh.ply:1:1: not a PLY file"),
            (b"ply\nformat ascii 1.0\n", "mesh.ply:2:1: the header ends without an \"end_header\""),
            (b"ply\nformat text 1.0\nend_header\n", "mesh.ply:2:1: unknown format \"text\""),
            (b"ply\nformat ascii 2.0\nend_header\n", "mesh.ply:2:1: unknown PLY version \"2.0\""),
            (b"ply\nformat ascii\nend_header\n", "mesh.ply:2:1: the line ends where the version"),
            (b"ply\nelement vertex 3\nend_header\n", "mesh.ply:3:1: the header has no \"format\" line"),
            (b"ply\nformat ascii 1.0\nproperty float x\n", "mesh.ply:3:1: a property before any"),
            (b"ply\nformat ascii 1.0\nelement vertex -3\n", "mesh.ply:3:1: the element count \"-3\""),
            (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty flaot x\n", "mesh.ply:4:1: unknown type \"flaot\""),
            (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty list float int x\n", "mesh.ply:4:1: the length of a list"),
            (b"ply\nformat ascii 1.0\nelement vertex 3 4\n", "mesh.ply:3:1: unexpected \"4\""),
            (b"ply\nformat ascii 1.0\nvertex 3\n", "mesh.ply:3:1: unknown header keyword \"vertex\""),
            (b"ply\nformat ascii 1.0\nend_header\n", "mesh.ply:3:1: the file has no \"vertex\" element"),
            (b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float y\nelement face 0\nend_header\n", "mesh.ply:5:1: the file has no faces"),
            (b"ply\nformat ascii 1.0\nformat ascii 1.0\n", "mesh.ply:3:1: a second \"format\" line"),
        ];
        for (bytes, expected) in cases {
            let message = error(bytes);
            assert!(
                message.starts_with(expected),
                "{:?}: {message}",
                String::from_utf8_lossy(bytes)
            );
        }

        let file = |header: String| {
            error(format!("ply\nformat ascii 1.0\n{header}end_header\n").as_bytes())
        };
        let message = file(vertices.to_string());
        assert!(
            message.starts_with("mesh.ply:7:1: the file has no faces"),
            "{message}"
        );
        let message = file(format!("{vertices}element face 0\n"));
        assert!(
            message.starts_with("mesh.ply:7:1: the file has no faces"),
            "{message}"
        );
        let message = file(format!("{faces}{vertices}").replace("property float z\n", ""));
        assert!(
            message.starts_with("mesh.ply:5:1: the vertex element needs the properties x, y and z"),
            "{message}"
        );
        let message = file(format!(
            "{vertices}property int nx\nproperty int ny\nproperty int nz\n{faces}"
        ));
        assert!(
            message.starts_with("mesh.ply:7:1: vertex property \"nx\" has an integer type"),
            "{message}"
        );
        let message = file(format!(
            "{vertices}element face 1\nproperty list uchar float vertex_indices\n"
        ));
        assert!(
            message.starts_with("mesh.ply:8:1: \"vertex_indices\" must be a list of integers"),
            "{message}"
        );
        let message = file(format!("{vertices}element face 1\nproperty uchar flags\n"));
        assert!(
            message.starts_with("mesh.ply:7:1: the face element has no \"vertex_indices\" list"),
            "{message}"
        );
        let message = file(format!("{vertices}{faces}{vertices}"));
        assert!(
            message.starts_with("mesh.ply:9:1: a second \"vertex\" element"),
            "{message}"
        );
    }
}
