//! The volume `inlinegrid`: a single-channel grid given as a list of numbers, as the pbrt-v4
//! reader writes pbrt's `uniformgrid` medium (XML has no form for it). It is read as
//! `gridvolume` reads a `.vol` file's grid: over the unit cube placed by `to_world`, interpolated
//! trilinearly between voxel centres and clamped at its faces.

use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, Range, params};
use prism_core::error::{Error, Result};
use prism_core::math::Transform;
use prism_core::medium::{GridFilter, GridVolume, Volume};

pub(super) const INLINE_GRID: Plugin<fn(&Params, Range) -> Result<Volume>> = Plugin {
    name: "inlinegrid",
    origin: Origin::Prism,
    summary: "A single-channel grid given as a list of numbers, x fastest, then y, then z, \
              as the pbrt-v4 reader writes pbrt's `uniformgrid` (XML has no form for it); \
              over the unit cube placed by `to_world`, interpolated trilinearly between voxel \
              centres and clamped at its faces, as `gridvolume`.",
    params: &[VALUES, RES_X, RES_Y, RES_Z, TO_WORLD],
    build: build_inline_grid,
};

params! {
    VALUES = ParamSpec::new("values", ParamKind::Numbers, Default::Required, "the voxels' values, finite and at least 0, x fastest");
    RES_X = ParamSpec::new("resolution_x", ParamKind::Integer, Default::Integer(1), "voxels along x");
    RES_Y = ParamSpec::new("resolution_y", ParamKind::Integer, Default::Integer(1), "voxels along y");
    RES_Z = ParamSpec::new("resolution_z", ParamKind::Integer, Default::Integer(1), "voxels along z");
    TO_WORLD = ParamSpec::new("to_world", ParamKind::Transform, Default::Text("identity"), "from the unit cube [0, 1]³ to the world");
}

fn build_inline_grid(params: &Params, range: Range) -> Result<Volume> {
    let node = params.node();
    let values = params.numbers_opt(&VALUES)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs its \"values\"", node.describe()),
        )
    })?;
    let location = params.location_of(&VALUES);
    let mut resolution = [0usize; 3];
    for (axis, spec) in [&RES_X, &RES_Y, &RES_Z].into_iter().enumerate() {
        let count = params.integer(spec)?;
        resolution[axis] = usize::try_from(count)
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| {
                Error::input(
                    params.location_of(spec),
                    format!("a grid needs at least one voxel along each axis, not {count}"),
                )
            })?;
    }
    let expected = resolution.iter().try_fold(1usize, |n, &r| n.checked_mul(r));
    if expected != Some(values.len()) {
        return Err(Error::input(
            location,
            format!(
                "the grid has {} values, but {} × {} × {} voxels",
                values.len(),
                resolution[0],
                resolution[1],
                resolution[2]
            ),
        ));
    }
    if let Some(bad) = values
        .iter()
        .find(|v| !(v.is_finite() && **v >= 0.0 && **v <= f64::from(f32::MAX)))
    {
        return Err(Error::input(
            location,
            format!("the grid holds the value {bad}; its values must be finite and at least 0"),
        ));
    }
    let to_world = Transform::new(params.transform(&TO_WORLD)?).ok_or_else(|| {
        Error::input(
            params.location_of(&TO_WORLD),
            format!(
                "the grid of {} is placed by a singular transform",
                node.describe()
            ),
        )
    })?;
    let data = values.iter().map(|&v| v as f32).collect();
    let grid = GridVolume::new(resolution, data, to_world, GridFilter::Trilinear)
        .expect("the values were checked");
    if range == Range::Albedo && grid.max_value() > 1.0 {
        return Err(Error::input(
            location,
            format!(
                "the albedo grid reaches {}, above 1: the medium would scatter more light than it removes",
                grid.max_value()
            ),
        ));
    }
    Ok(Volume::Grid(Box::new(grid)))
}
