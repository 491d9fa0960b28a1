//! Mitsuba 3's `ellipsoids`: a cloud of ellipsoids read from a PLY file
//! ([`crate::mesh::ellipsoids`]), placed as Mitsuba's `EllipsoidsData` places them.

use glam::DMat3;

use super::meshes::mesh_error;
use super::{Build, TO_WORLD};
use crate::mesh::ellipsoids::load_ellipsoids;
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::error::{Error, Result};
use prism_core::geometry::Shape;
use prism_core::geometry::shape::{Ellipsoid, Ellipsoids};
use prism_core::math::Transform;
use prism_core::math::animated::polar_decomposition;

pub(super) const ELLIPSOIDS: Plugin<Build> = Plugin {
    name: "ellipsoids",
    origin: Origin::Mitsuba3,
    summary: "A cloud of anisotropic ellipsoids from a PLY file in 3D Gaussian splatting's \
              layout (`x y z nx ny nz`, extras, `scale_0..2` as logarithms, `rot_0..3` a \
              quaternion w, x, y, z), intersected exactly, back faces culled, the normal the \
              implicit surface's gradient (as Mitsuba). Each ellipsoid's radii are its \
              scales times `scale_factor`, `extent` and `to_world`'s mean stretch; \
              `to_world` moves the centres and turns the ellipsoids. No area emitter (Mitsuba \
              gives ellipsoids no surface sampling); Mitsuba's tensor forms (`data`, \
              `centers`, …) have no XML form and are not read.",
    params: shape_params![
        ELLIPSOIDS_FILENAME,
        EXTENT,
        EXTENT_ADAPTIVE_CLAMPING,
        SCALE_FACTOR
    ],
    build: build_ellipsoids,
};

params! {
    ELLIPSOIDS_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the PLY file of the ellipsoids");
    EXTENT = ParamSpec::new("extent", ParamKind::Float, Default::Float(3.0), "a factor on every ellipsoid's radii (the support of a Gaussian of standard deviations the scales)");
    EXTENT_ADAPTIVE_CLAMPING = ParamSpec::new("extent_adaptive_clamping", ParamKind::Boolean, Default::Boolean(false), "multiply the extent by √(2 ln(opacity/0.01))/3 per ellipsoid (needs the file's opacities; an ellipsoid of opacity at most 0.01 then vanishes, as in Mitsuba)");
    SCALE_FACTOR = ParamSpec::new("scale_factor", ParamKind::Float, Default::Float(1.0), "a factor on the file's scales");
}

/// The ellipsoids of the file, placed by `to_world`: centres through the whole transform,
/// rotations turned by its rotation and radii scaled by the mean of its stretch's diagonal
/// (Mitsuba's `transform_decompose`), each radius times `scale_factor` and the extent.
fn build_ellipsoids(params: &Params, to_world: &Transform) -> Result<Shape> {
    let node = params.node();
    let filename = params.string_opt(&ELLIPSOIDS_FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help(
            "add <string name=\"filename\" value=\"ellipsoids.ply\"/> (Mitsuba's tensor \
             parameters have no XML form)",
        )
    })?;
    let path = node.resolve_file(filename, params.location_of(&ELLIPSOIDS_FILENAME))?;
    let data = load_ellipsoids(&path).map_err(|e| mesh_error(e, node))?;
    let positive = |spec: &ParamSpec| -> Result<f32> {
        let value = params.float(spec)?;
        if value > 0.0 && value.is_finite() {
            Ok(value as f32)
        } else {
            Err(Error::input(
                params.location_of(spec),
                format!("\"{}\" must be a positive number, not {value}", spec.name),
            ))
        }
    };
    let extent = positive(&EXTENT)?;
    let scale_factor = positive(&SCALE_FACTOR)?;
    let extents: Vec<f32> = if params.boolean(&EXTENT_ADAPTIVE_CLAMPING)? {
        let opacities = data.opacities.as_ref().ok_or_else(|| {
            Error::input(
                params.location_of(&EXTENT_ADAPTIVE_CLAMPING),
                format!(
                    "\"extent_adaptive_clamping\" needs the ellipsoids' opacities, and \
                     \"{filename}\" has none"
                ),
            )
            .with_help(
                "give the file an `opacity` property (Gaussian splatting's layout) or an \
                 `opacities` one, or leave the clamping off",
            )
        })?;
        opacities
            .iter()
            .map(|&opacity| (2.0 * (opacity / 0.01).ln()).sqrt() * extent / 3.0)
            .collect()
    } else {
        vec![extent; data.centers.len()]
    };
    let linear = DMat3::from_mat4(to_world.matrix.as_dmat4());
    let (turn, stretch) = polar_decomposition(linear);
    let mean_stretch = (stretch.x_axis.x + stretch.y_axis.y + stretch.z_axis.z).abs() / 3.0;
    let turn = turn.as_mat3();
    let mut ellipsoids = Vec::with_capacity(data.centers.len());
    for (i, &extent) in extents.iter().enumerate() {
        // An adaptive extent that is not positive (an opacity at most 0.01) leaves Mitsuba an
        // ellipsoid of zero or NaN radii, which no ray hits: it is left out.
        if !(extent > 0.0) {
            continue;
        }
        let q = data.quaternions[i].normalize();
        let radii = data.scales[i] * (scale_factor * mean_stretch as f32 * extent);
        let ellipsoid = Ellipsoid {
            center: to_world.point(data.centers[i]),
            radii,
            rotation: turn * Ellipsoid::rotation_of_quaternion(q.x, q.y, q.z, q.w),
        };
        if !(ellipsoid.center.is_finite() && radii.is_finite()) {
            return Err(Error::input(
                params.location_of(&TO_WORLD),
                format!("ellipsoid {i} of \"{filename}\" is not finite once placed and scaled"),
            ));
        }
        ellipsoids.push(ellipsoid);
    }
    let count = ellipsoids.len();
    Ellipsoids::new(ellipsoids)
        .map(Shape::Ellipsoids)
        .ok_or_else(|| {
            let reason = if count == 0 {
                "none of its ellipsoids is left (every opacity is at most 0.01)"
            } else {
                "an ellipsoid's rotation or radii are degenerate"
            };
            Error::input(
                params.location_of(&ELLIPSOIDS_FILENAME),
                format!("the ellipsoids of \"{filename}\" are not valid: {reason}"),
            )
        })
}
