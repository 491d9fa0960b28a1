//! A writer of Mitsuba serialized meshes (the format `prism_mitsuba::mesh::serialized`
//! reads), for tests that need such files.

use miniz_oxide::deflate::compress_to_vec_zlib;

/// One shape of a serialized file.
#[derive(Clone, Debug, Default)]
pub struct SerializedShape {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub colors: Option<Vec<[f32; 3]>>,
    pub triangles: Vec<[u32; 3]>,
    /// Store the numbers as f64 (flag 0x2000) instead of f32 (flag 0x1000).
    pub double: bool,
}

impl SerializedShape {
    /// The flags word: precision and which optional attributes the shape has.
    pub fn flags(&self) -> u32 {
        let mut flags = if self.double { 0x2000 } else { 0x1000 };
        if self.normals.is_some() {
            flags |= 0x0001;
        }
        if self.uvs.is_some() {
            flags |= 0x0002;
        }
        if self.colors.is_some() {
            flags |= 0x0008;
        }
        flags
    }

    /// The uncompressed stream of the shape in `version` (3 or 4).
    pub fn stream(&self, version: u16) -> Vec<u8> {
        let mut out = self.flags().to_le_bytes().to_vec();
        if version == 4 {
            out.extend_from_slice(self.name.as_bytes());
            out.push(0);
        }
        out.extend_from_slice(&(self.positions.len() as u64).to_le_bytes());
        out.extend_from_slice(&(self.triangles.len() as u64).to_le_bytes());
        let mut numbers = |values: &[f32]| {
            for &v in values {
                if self.double {
                    out.extend_from_slice(&f64::from(v).to_le_bytes());
                } else {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
        };
        numbers(self.positions.as_flattened());
        if let Some(normals) = &self.normals {
            numbers(normals.as_flattened());
        }
        if let Some(uvs) = &self.uvs {
            numbers(uvs.as_flattened());
        }
        if let Some(colors) = &self.colors {
            numbers(colors.as_flattened());
        }
        for index in self.triangles.as_flattened() {
            out.extend_from_slice(&index.to_le_bytes());
        }
        out
    }
}

/// The header of a shape: the format id and `version`.
pub fn shape_header(version: u16) -> Vec<u8> {
    let mut out = 0x041Cu16.to_le_bytes().to_vec();
    out.extend_from_slice(&version.to_le_bytes());
    out
}

/// A serialized file of `shapes` in `version` (3 or 4), with the table of offsets at its end.
pub fn serialized_file(shapes: &[SerializedShape], version: u16) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for shape in shapes {
        offsets.push(out.len() as u64);
        out.extend_from_slice(&shape_header(version));
        out.extend_from_slice(&compress_to_vec_zlib(&shape.stream(version), 6));
    }
    for offset in offsets {
        if version == 4 {
            out.extend_from_slice(&offset.to_le_bytes());
        } else {
            out.extend_from_slice(&(offset as u32).to_le_bytes());
        }
    }
    out.extend_from_slice(&(shapes.len() as u32).to_le_bytes());
    out
}

/// A unit right triangle in the z = 0 plane with every optional attribute.
pub fn triangle_shape() -> SerializedShape {
    SerializedShape {
        name: "triangle".into(),
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        normals: Some(vec![[0.0, 0.0, 1.0]; 3]),
        uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
        colors: Some(vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        triangles: vec![[0, 1, 2]],
        double: false,
    }
}
