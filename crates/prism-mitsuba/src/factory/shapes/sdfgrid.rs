//! Mitsuba 3's `sdfgrid`: a signed distance function sampled on a grid, read from a
//! single-channel `.vol` file ([`prism_core::medium::volume::parse_vol`]).

use glam::UVec3;

use super::Build;
use crate::file_cache;
use crate::params::Params;
use crate::registry::{Choice, Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::error::{Error, Result};
use prism_core::geometry::Shape;
use prism_core::geometry::shape::{SdfGrid, SdfNormals};
use prism_core::math::Transform;
use prism_core::medium::volume::parse_vol;

pub(super) const SDFGRID: Plugin<Build> = Plugin {
    name: "sdfgrid",
    origin: Origin::Mitsuba3,
    summary: "The zero set of a signed distance function sampled on a grid (a \
              single-channel `.vol` file, or Mitsuba's `grid` tensor from a scene dictionary) \
              spanning the unit cube, trilinearly interpolated; each voxel the surface crosses \
              is intersected as a cubic along the ray, from either side (as Mitsuba). Normals \
              are the voxel's gradient; `smooth` shading blends the eight neighbouring \
              voxels'. No (u, v) and no area emitter (as in Mitsuba).",
    params: shape_params![SDF_FILENAME, SDF_GRID, NORMALS],
    build: build_sdfgrid,
};

params! {
    SDF_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::None, "the `.vol` file of the function's values (one channel, at least 2 points per axis; its bounding box is ignored: the grid spans the unit cube, as in Mitsuba); or give `grid`");
    SDF_GRID = ParamSpec::new("grid", ParamKind::Tensor, Default::None, "the function's values as a tensor of shape (z, y, x, 1), x fastest (Mitsuba's layout; scene dictionaries only); or give `filename`");
    NORMALS = ParamSpec::new("normals", ParamKind::Choice(&[Choice::new("smooth", &SdfNormals::Smooth), Choice::new("analytic", &SdfNormals::Analytic)]), Default::Str("smooth"), "the shading normal: `smooth` blends the eight surrounding voxels' gradients trilinearly (continuous across voxels), `analytic` is the gradient of the voxel holding the point");
}

/// The grid of the file or tensor, placed by `to_world`.
fn build_sdfgrid(params: &Params, to_world: &Transform) -> Result<Shape> {
    let node = params.node();
    let normals: SdfNormals = params.choice(&NORMALS)?;
    let (location, resolution, values, source) = match (
        params.string_opt(&SDF_FILENAME)?,
        params.tensor_opt(&SDF_GRID)?,
    ) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of(&SDF_GRID),
                format!("{} has both a \"filename\" and a \"grid\"", node.describe()),
            )
            .with_help("give the values one way"));
        }
        (None, None) => {
            return Err(Error::input(
                &node.location,
                format!("{} needs a \"filename\" or a \"grid\"", node.describe()),
            )
            .with_help(
                "add <string name=\"filename\" value=\"shape.vol\"/> (a \"grid\" tensor \
                     can be given only in a scene dictionary)",
            ));
        }
        (Some(filename), None) => {
            let location = params.location_of(&SDF_FILENAME);
            let path = node.resolve_file(filename, location)?;
            let bytes =
                file_cache::read(&path).map_err(|e| Error::io(&path, &e, "read the SDF grid"))?;
            let invalid =
                |message: String| Error::input(location, format!("\"{filename}\": {message}"));
            let file = parse_vol(&bytes).map_err(invalid)?;
            if file.channels != 1 {
                return Err(invalid(format!(
                    "an SDF grid has one channel, and the file has {}",
                    file.channels
                )));
            }
            (
                location,
                file.resolution,
                file.data,
                format!("\"{filename}\""),
            )
        }
        (None, Some(tensor)) => {
            let location = params.location_of(&SDF_GRID);
            let &[z, y, x, 1] = tensor.shape.as_slice() else {
                return Err(Error::input(
                    location,
                    format!(
                        "the grid tensor has shape {:?}; an SDF grid's is (z, y, x, 1), as \
                             in Mitsuba",
                        tensor.shape
                    ),
                ));
            };
            let values = tensor.values.iter().map(|&v| v as f32).collect();
            (location, [x, y, z], values, "the grid tensor".to_string())
        }
    };
    let invalid = |message: String| Error::input(location, format!("{source}: {message}"));
    let [x, y, z] = resolution;
    if x.min(y).min(z) < 2 {
        return Err(invalid(format!(
            "the grid is {x} × {y} × {z} points; an SDF grid needs at least 2 per axis"
        )));
    }
    if u32::try_from(x.max(y).max(z)).is_err() {
        return Err(invalid(format!(
            "the grid of {x} × {y} × {z} points is too large"
        )));
    }
    if let Some(i) = values.iter().position(|v: &f32| !v.is_finite()) {
        return Err(invalid(format!("value {i} is not a finite number")));
    }
    let resolution = UVec3::new(x as u32, y as u32, z as u32);
    SdfGrid::new(resolution, values, *to_world, normals)
        .map(Shape::SdfGrid)
        .ok_or_else(|| {
            invalid("no voxel holds part of the surface (the values never change sign)".into())
        })
}
