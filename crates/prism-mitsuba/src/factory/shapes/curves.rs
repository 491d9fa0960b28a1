//! Round curves read from a file of control points: `linearcurve` and `bsplinecurve`.

use super::meshes::mesh_error;
use super::{Build, TO_WORLD};
use crate::mesh::curves::{CurveData, load_curves};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::error::{Error, Result};
use prism_core::geometry::Shape;
use prism_core::geometry::shape::{BSplineCurve, LinearCurve};
use prism_core::math::Transform;

pub(super) const LINEARCURVE: Plugin<Build> = Plugin {
    name: "linearcurve",
    origin: Origin::Mitsuba3,
    summary: "Round linear curves from a text file of control points `x y z radius` (a \
              blank line between curves): each segment the sweep of a sphere of \
              linearly varying radius, joints and ends round. `to_world` moves the \
              points, not the radii (as in Mitsuba); back faces are culled; no area \
              emitter (Mitsuba gives curves no area sampling).",
    params: shape_params![CURVE_FILENAME],
    build: build_linear_curve,
};

pub(super) const BSPLINECURVE: Plugin<Build> = Plugin {
    name: "bsplinecurve",
    origin: Origin::Mitsuba3,
    summary: "Round uniform cubic B-spline curves from a text file of control points \
              `x y z radius` (a blank line between curves, at least four points each; \
              n points make n − 3 segments): the sweep of circles of varying radius \
              orthogonal to the curve, open at both ends (Embree's round B-spline \
              curves). `to_world` moves the points, not the radii (as in Mitsuba); back \
              faces are culled; no area emitter (Mitsuba gives curves no area \
              sampling).",
    params: shape_params![CURVE_FILENAME],
    build: build_bspline_curve,
};

params! {
    CURVE_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the curve file");
}

/// Round linear curves read from a file, their points placed by `to_world` (radii unchanged).
fn build_linear_curve(params: &Params, to_world: &Transform) -> Result<Shape> {
    let (data, filename) = read_curves(params, to_world, 2)?;
    LinearCurve::new(data.points, &data.curves)
        .ok_or_else(|| invalid_curves(params, filename))
        .map(Shape::LinearCurve)
}

/// Round B-spline curves read from a file, their points placed by `to_world` (radii
/// unchanged).
fn build_bspline_curve(params: &Params, to_world: &Transform) -> Result<Shape> {
    let (data, filename) = read_curves(params, to_world, 4)?;
    BSplineCurve::new(&data.points, &data.curves)
        .ok_or_else(|| invalid_curves(params, filename))
        .map(Shape::BSplineCurve)
}

/// The control points of a curve shape's file (curves of at least `min_points` points),
/// placed by `to_world`, and the file's name.
fn read_curves<'a>(
    params: &'a Params,
    to_world: &Transform,
    min_points: usize,
) -> Result<(CurveData, &'a str)> {
    let node = params.node();
    let filename = params.string_opt(&CURVE_FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"curves.txt\"/>")
    })?;
    let path = node.resolve_file(filename, params.location_of(&CURVE_FILENAME))?;
    let mut data = load_curves(&path, min_points).map_err(|e| mesh_error(e, node))?;
    for point in &mut data.points {
        let p = to_world.point(point.truncate());
        if !p.is_finite() {
            return Err(Error::input(
                params.location_of(&TO_WORLD),
                format!("\"to_world\" moves a control point of \"{filename}\" to infinity"),
            ));
        }
        *point = p.extend(point.w);
    }
    Ok((data, filename))
}

/// The error for curves the shape refuses after reading them.
fn invalid_curves(params: &Params, filename: &str) -> Error {
    Error::input(
        params.location_of(&CURVE_FILENAME),
        format!("the curves of \"{filename}\" are not valid"),
    )
}
