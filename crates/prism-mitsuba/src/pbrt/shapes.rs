//! `Shape`: pbrt-v4's shapes as Mitsuba's, placed by the CTM.
//!
//! `sphere`, `disk` and `cylinder` are whole (pbrt's `zmin`, `zmax`, `phimax` and `innerradius`
//! cut them; Prism's quadrics are whole, so cut ones are refused); `trianglemesh` becomes
//! Prism's inline `trianglemesh`; `bilinearmesh` patches that are flat parallelograms become two
//! triangles each (the same surface and texture coordinates; curved patches are refused);
//! `plymesh` becomes `ply`. `ReverseOrientation` flips the normals, which decides the side an
//! area light emits from.

use glam::{DMat4, DVec3};

use super::builder::{Builder, GraphicsState};
use super::parameters::{FloatParam, Parameter, ParameterList};
use super::{plugin, set};
use crate::description::{PluginClass, PluginNode, PropertyValue};
use prism_core::error::Result;

impl Builder {
    /// The shape `ty` without its material, lights or media.
    pub(super) fn shape(
        &mut self,
        ty: &str,
        list: &ParameterList,
        state: &GraphicsState,
    ) -> Result<PluginNode> {
        let location = &list.location;
        if let Some((alpha, parameter)) = list.float_or_texture("alpha")?
            && alpha != FloatParam::Value(1.0)
        {
            return Err(list.error(
                parameter,
                "cuts the shape out; Prism's pbrt reader does not read alpha",
            ));
        }
        let mut to_world = state.ctm;
        let mut sphere_radius = 1.0;
        let plugin_type = match ty {
            "sphere" => {
                let radius = list.float("radius", 1.0)?;
                sphere_radius = radius;
                whole(list, "zmin", -radius)?;
                whole(list, "zmax", radius)?;
                whole(list, "phimax", 360.0)?;
                "sphere"
            }
            "disk" => {
                let height = list.float("height", 0.0)?;
                let radius = list.float("radius", 1.0)?;
                whole(list, "innerradius", 0.0)?;
                whole(list, "phimax", 360.0)?;
                to_world *= DMat4::from_translation(DVec3::new(0.0, 0.0, height))
                    * DMat4::from_scale(DVec3::new(radius, radius, 1.0));
                "disk"
            }
            "cylinder" => {
                whole(list, "phimax", 360.0)?;
                "cylinder"
            }
            "trianglemesh" | "bilinearmesh" | "plymesh" => ty,
            _ => {
                return Err(list
                    .directive_error("Prism has no shape with this pbrt-v4 model")
                    .with_help("Prism reads sphere, disk, cylinder, trianglemesh, bilinearmesh and plymesh"));
            }
        };
        let mut node = match plugin_type {
            "trianglemesh" => self.triangle_mesh(list)?,
            "bilinearmesh" => self.bilinear_mesh(list)?,
            "plymesh" => {
                let Some((parameter, names)) = list.strings("filename", "string")? else {
                    return Err(list.directive_error("needs a \"string filename\""));
                };
                if names[0].ends_with(".gz") {
                    return Err(list
                        .error(
                            parameter,
                            "names a gzip-compressed PLY file, which Prism does not read",
                        )
                        .with_help("decompress it with gunzip"));
                }
                for name in ["displacement", "edgelength"] {
                    if let Some(parameter) = list.get(name) {
                        return Err(
                            list.error(parameter, "displaces the mesh, which Prism does not do")
                        );
                    }
                }
                let mut node = plugin(PluginClass::Shape, "ply", location, &self.search_paths);
                set(
                    &mut node,
                    "filename",
                    PropertyValue::String(names[0].clone()),
                    &parameter.location,
                );
                node
            }
            "cylinder" => {
                let mut node = plugin(PluginClass::Shape, "cylinder", location, &self.search_paths);
                let zmin = list.float("zmin", -1.0)?;
                let zmax = list.float("zmax", 1.0)?;
                set(
                    &mut node,
                    "p0",
                    PropertyValue::Point(DVec3::new(0.0, 0.0, zmin)),
                    location,
                );
                set(
                    &mut node,
                    "p1",
                    PropertyValue::Point(DVec3::new(0.0, 0.0, zmax)),
                    location,
                );
                set(
                    &mut node,
                    "radius",
                    PropertyValue::Float(list.float("radius", 1.0)?),
                    location,
                );
                node
            }
            "sphere" => {
                let mut node = plugin(PluginClass::Shape, "sphere", location, &self.search_paths);
                set(
                    &mut node,
                    "radius",
                    PropertyValue::Float(sphere_radius),
                    location,
                );
                node
            }
            other => plugin(PluginClass::Shape, other, location, &self.search_paths),
        };
        set(
            &mut node,
            "to_world",
            PropertyValue::Transform(to_world),
            location,
        );
        if state.reverse_orientation {
            set(
                &mut node,
                "flip_normals",
                PropertyValue::Boolean(true),
                location,
            );
        }
        Ok(node)
    }

    /// `trianglemesh`: `P`, `indices` (optional for one triangle), `N`, `uv`.
    fn triangle_mesh(&mut self, list: &ParameterList) -> Result<PluginNode> {
        let location = &list.location;
        let (_, positions, indices) = positions_and_indices(list, 3)?;
        let vertex_count = positions.len() / 3;
        let mut node = plugin(
            PluginClass::Shape,
            "trianglemesh",
            location,
            &self.search_paths,
        );
        set(
            &mut node,
            "vertex_positions",
            PropertyValue::Numbers(positions.to_vec()),
            location,
        );
        set(
            &mut node,
            "faces",
            PropertyValue::Numbers(indices),
            location,
        );
        if let Some((parameter, normals)) = list.array("N", &["normal3"], 3)? {
            if normals.len() != positions.len() {
                return Err(list.error(
                    parameter,
                    format!(
                        "has {} normals for {vertex_count} vertices",
                        normals.len() / 3
                    ),
                ));
            }
            set(
                &mut node,
                "vertex_normals",
                PropertyValue::Numbers(normals.to_vec()),
                location,
            );
        }
        if let Some((parameter, uvs)) = list.array("uv", &["point2"], 2)? {
            if uvs.len() != 2 * vertex_count {
                return Err(list.error(
                    parameter,
                    format!(
                        "has {} coordinates for {vertex_count} vertices",
                        uvs.len() / 2
                    ),
                ));
            }
            set(
                &mut node,
                "vertex_texcoords",
                PropertyValue::Numbers(uvs.to_vec()),
                location,
            );
        }
        for name in ["S", "faceIndices"] {
            if let Some(parameter) = list.get(name) {
                return Err(list.error(parameter, "is not read by Prism"));
            }
        }
        Ok(node)
    }

    /// `bilinearmesh`: each patch (p00, p10, p01, p11) a flat parallelogram, as two triangles.
    fn bilinear_mesh(&mut self, list: &ParameterList) -> Result<PluginNode> {
        let location = &list.location;
        let (p_parameter, positions, indices) = positions_and_indices(list, 4)?;
        let vertex_count = positions.len() / 3;
        let uv = match list.array("uv", &["point2"], 2)? {
            Some((parameter, uvs)) if uvs.len() != 2 * vertex_count => {
                return Err(list.error(
                    parameter,
                    format!(
                        "has {} coordinates for {vertex_count} vertices",
                        uvs.len() / 2
                    ),
                ));
            }
            Some((_, uvs)) => Some(uvs),
            None => None,
        };
        if let Some(parameter) = list.get("N") {
            return Err(list.error(
                parameter,
                "gives normals to bilinear patches, which Prism does not read",
            ));
        }
        let point = |i: f64| {
            let i = i as usize * 3;
            DVec3::new(positions[i], positions[i + 1], positions[i + 2])
        };
        let mut vertices = Vec::with_capacity(indices.len() * 3);
        let mut texcoords = Vec::with_capacity(indices.len() * 2);
        let mut faces = Vec::with_capacity(indices.len() / 4 * 6);
        for (patch, corners) in indices.chunks_exact(4).enumerate() {
            let p = corners.iter().map(|&i| point(i)).collect::<Vec<_>>();
            let gap = p[0] + p[3] - p[1] - p[2];
            let size = (p[1] - p[0]).length().max((p[2] - p[0]).length());
            if gap.length() > 1e-6 * size {
                return Err(list.error(
                    p_parameter,
                    format!("makes patch {patch} curved or not a parallelogram; Prism renders only flat parallelogram patches"),
                ));
            }
            let first = (vertices.len() / 3) as f64;
            for (k, corner) in corners.iter().enumerate() {
                vertices.extend(p[k].to_array());
                match uv {
                    Some(uvs) => {
                        let i = *corner as usize * 2;
                        texcoords.extend([uvs[i], uvs[i + 1]]);
                    }
                    None => texcoords.extend([(k % 2) as f64, (k / 2) as f64]),
                }
            }
            if let Some(uvs) = uv {
                let t = |k: usize| {
                    let i = corners[k] as usize * 2;
                    glam::DVec2::new(uvs[i], uvs[i + 1])
                };
                if (t(0) + t(3) - t(1) - t(2)).length() > 1e-6 * (1.0 + t(0).length()) {
                    let parameter: &Parameter = list.get("uv").expect("given");
                    return Err(list.error(parameter, format!("is not affine over patch {patch}; Prism interpolates texture coordinates linearly")));
                }
            }
            faces.extend([
                first,
                first + 1.0,
                first + 3.0,
                first,
                first + 3.0,
                first + 2.0,
            ]);
        }
        let mut node = plugin(
            PluginClass::Shape,
            "trianglemesh",
            location,
            &self.search_paths,
        );
        set(
            &mut node,
            "vertex_positions",
            PropertyValue::Numbers(vertices),
            location,
        );
        set(&mut node, "faces", PropertyValue::Numbers(faces), location);
        set(
            &mut node,
            "vertex_texcoords",
            PropertyValue::Numbers(texcoords),
            location,
        );
        Ok(node)
    }
}

/// Refuses a parameter that cuts a quadric unless it has the value of the whole shape.
fn whole(list: &ParameterList, name: &str, whole_value: f64) -> Result<()> {
    if list.float(name, whole_value)? != whole_value
        && let Some(parameter) = list.get(name)
    {
        return Err(list.error(parameter, "cuts the shape; Prism's quadrics are whole"));
    }
    Ok(())
}

/// A mesh's `point3 P` and its `integer indices`, `per_face` to a face (optional when the mesh
/// is one face of `per_face` vertices, which are then taken in order), checked against the
/// vertices.
fn positions_and_indices(
    list: &ParameterList,
    per_face: usize,
) -> Result<(&Parameter, &[f64], Vec<f64>)> {
    let Some((p_parameter, positions)) = list.array("P", &["point3"], 3)? else {
        return Err(list.directive_error("needs \"point3 P\""));
    };
    let vertex_count = positions.len() / 3;
    let indices = match list.array("indices", &["integer"], per_face)? {
        Some((parameter, indices)) => {
            check_indices(list, parameter, indices, vertex_count)?;
            indices.to_vec()
        }
        None if vertex_count == per_face => (0..per_face).map(|i| i as f64).collect(),
        None => {
            return Err(list.directive_error(format!(
                "needs \"integer indices\" (more than {per_face} vertices)"
            )));
        }
    };
    Ok((p_parameter, positions, indices))
}

/// Checks that every index names a vertex, before the mesh is built.
fn check_indices(
    list: &ParameterList,
    parameter: &Parameter,
    indices: &[f64],
    vertex_count: usize,
) -> Result<()> {
    match indices
        .iter()
        .find(|&&i| !(i >= 0.0 && i < vertex_count as f64))
    {
        Some(index) => Err(list.error(
            parameter,
            format!("has the index {index}, but there are {vertex_count} vertices"),
        )),
        None => Ok(()),
    }
}
