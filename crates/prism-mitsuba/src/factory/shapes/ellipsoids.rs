//! Mitsuba 3's `ellipsoids`: a cloud of ellipsoids read from a PLY file
//! ([`crate::mesh::ellipsoids`]) or given as tensors in a scene dictionary, placed as
//! Mitsuba's `EllipsoidsData` places them.

use glam::{DMat3, Vec3, Vec4};

use super::meshes::mesh_error;
use super::{Build, TO_WORLD};
use crate::mesh::ellipsoids::{EllipsoidsData, load_ellipsoids};
use crate::params::{Params, Tensor};
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
              quaternion w, x, y, z), or from Mitsuba's tensors in a scene dictionary (`data`, \
              or `centers`, `scales` and `quaternions`), intersected exactly, back faces \
              culled, the normal the implicit surface's gradient (as Mitsuba). Each \
              ellipsoid's radii are its scales times `scale_factor`, `extent` and `to_world`'s \
              mean stretch; `to_world` moves the centres and turns the ellipsoids (a PLY file's \
              only, as in Mitsuba). No area emitter (Mitsuba gives ellipsoids no surface \
              sampling). Other tensors (per-ellipsoid attributes such as `sh_coeffs`) are read \
              past, as the file's extra properties are.",
    params: shape_params![
        ELLIPSOIDS_FILENAME,
        DATA,
        CENTERS,
        SCALES,
        QUATERNIONS,
        OPACITIES,
        EXTENT,
        EXTENT_ADAPTIVE_CLAMPING,
        SCALE_FACTOR
    ],
    build: build_ellipsoids,
};

params! {
    ELLIPSOIDS_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::None, "the PLY file of the ellipsoids; or give `data`, or `centers`, `scales` and `quaternions`");
    DATA = ParamSpec::new("data", ParamKind::Tensor, Default::None, "(N, 10) or (10 N): per ellipsoid its centre x, y, z, its scales (the radii before the extent) and its rotation as a quaternion x, y, z, w (Mitsuba's layout)");
    CENTERS = ParamSpec::new("centers", ParamKind::Tensor, Default::None, "(N, 3): the centres, with `scales` and `quaternions`");
    SCALES = ParamSpec::new("scales", ParamKind::Tensor, Default::None, "(N, 3): the scales (the radii before the extent)");
    QUATERNIONS = ParamSpec::new("quaternions", ParamKind::Tensor, Default::None, "(N, 4): the rotations as quaternions x, y, z, w");
    OPACITIES = ParamSpec::new("opacities", ParamKind::Tensor, Default::None, "(N, 1) or (N): the opacities `extent_adaptive_clamping` uses, with tensor data (a PLY file gives its own)");
    EXTENT = ParamSpec::new("extent", ParamKind::Float, Default::Float(3.0), "a factor on every ellipsoid's radii (the support of a Gaussian of standard deviations the scales)");
    EXTENT_ADAPTIVE_CLAMPING = ParamSpec::new("extent_adaptive_clamping", ParamKind::Boolean, Default::Boolean(false), "multiply the extent by √(2 ln(opacity/0.01))/3 per ellipsoid (needs the file's opacities; an ellipsoid of opacity at most 0.01 then vanishes, as in Mitsuba)");
    SCALE_FACTOR = ParamSpec::new("scale_factor", ParamKind::Float, Default::Float(1.0), "a factor on the file's scales");
}

/// The ellipsoids of the file or tensors, placed by `to_world`: centres through the whole
/// transform, rotations turned by its rotation and radii scaled by the mean of its stretch's
/// diagonal (Mitsuba's `transform_decompose`), each radius times `scale_factor` and the extent.
fn build_ellipsoids(params: &Params, to_world: &Transform) -> Result<Shape> {
    let node = params.node();
    let (data, filename) = match params.string_opt(&ELLIPSOIDS_FILENAME)? {
        Some(filename) => {
            for spec in [&DATA, &CENTERS, &SCALES, &QUATERNIONS, &OPACITIES] {
                if params.has(spec) {
                    return Err(Error::input(
                        params.location_of(spec),
                        format!("\"{}\" cannot be given with a \"filename\"", spec.name),
                    )
                    .with_help("give the ellipsoids one way (as Mitsuba requires)"));
                }
            }
            let path = node.resolve_file(filename, params.location_of(&ELLIPSOIDS_FILENAME))?;
            let data = load_ellipsoids(&path).map_err(|e| mesh_error(e, node))?;
            (data, format!("\"{filename}\""))
        }
        None => (tensor_data(params)?, "the tensors".to_string()),
    };
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
                     {filename} give none"
                ),
            )
            .with_help(
                "give the file an `opacity` property (Gaussian splatting's layout) or an \
                 `opacities` one, or the tensors an `opacities` tensor, or leave the clamping off",
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
                format!("ellipsoid {i} of {filename} is not finite once placed and scaled"),
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
                format!("the ellipsoids of {filename} are not valid: {reason}"),
            )
        })
}

/// The ellipsoids of Mitsuba's tensor parameters: `data` (N × 10: centre, scales, quaternion
/// x, y, z, w), or `centers`, `scales` and `quaternions`; with `opacities` where given. As in
/// Mitsuba, they take no `to_world` and no `scale_factor` (a PLY file's only), and other
/// tensors are attributes, read past.
fn tensor_data(params: &Params) -> Result<EllipsoidsData> {
    let node = params.node();
    for spec in [&TO_WORLD, &SCALE_FACTOR] {
        if params.has(spec) {
            return Err(Error::input(
                params.location_of(spec),
                format!(
                    "\"{}\" applies to ellipsoids read from a PLY file only (as in Mitsuba)",
                    spec.name
                ),
            )
            .with_help("place and scale the tensors' ellipsoids before giving them"));
        }
    }
    params.undeclared_tensors();
    let mut data = EllipsoidsData::default();
    match (params.tensor_opt(&DATA)?, params.tensor_opt(&CENTERS)?) {
        (Some(_), Some(_)) => {
            return Err(Error::input(
                params.location_of(&CENTERS),
                "\"centers\" cannot be given with \"data\"",
            )
            .with_help("give the ellipsoids one way (as Mitsuba requires)"));
        }
        (None, None) => {
            return Err(Error::input(
                &node.location,
                format!(
                    "{} needs a \"filename\", a \"data\" tensor or \"centers\", \"scales\" \
                     and \"quaternions\" tensors",
                    node.describe()
                ),
            )
            .with_help("add <string name=\"filename\" value=\"ellipsoids.ply\"/>"));
        }
        (Some(tensor), None) => {
            for spec in [&SCALES, &QUATERNIONS] {
                if params.has(spec) {
                    return Err(Error::input(
                        params.location_of(spec),
                        format!("\"{}\" cannot be given with \"data\"", spec.name),
                    )
                    .with_help("give the ellipsoids one way (as Mitsuba requires)"));
                }
            }
            let location = params.location_of(&DATA);
            let rows = rows_of(&tensor, 10).ok_or_else(|| {
                Error::input(
                    location,
                    format!(
                        "the \"data\" tensor has shape {:?}; it must be (N, 10) or (10 N)",
                        tensor.shape
                    ),
                )
            })?;
            for row in tensor.values.chunks_exact(10).take(rows) {
                let v: Vec<f32> = row.iter().map(|&x| x as f32).collect();
                data.centers.push(Vec3::new(v[0], v[1], v[2]));
                data.scales.push(Vec3::new(v[3], v[4], v[5]));
                data.quaternions.push(Vec4::new(v[6], v[7], v[8], v[9]));
            }
        }
        (None, Some(centers)) => {
            let mut columns = Vec::new();
            for (spec, tensor, width) in [
                (&CENTERS, Some(centers), 3),
                (&SCALES, params.tensor_opt(&SCALES)?, 3),
                (&QUATERNIONS, params.tensor_opt(&QUATERNIONS)?, 4),
            ] {
                let location = params.location_of(spec);
                let tensor = tensor.ok_or_else(|| {
                    Error::input(
                        location,
                        "\"centers\" needs \"scales\" and \"quaternions\" too",
                    )
                })?;
                if tensor.shape.len() != 2 || tensor.shape[1] != width {
                    return Err(Error::input(
                        location,
                        format!(
                            "the \"{}\" tensor has shape {:?}; it must be (N, {width})",
                            spec.name, tensor.shape
                        ),
                    ));
                }
                columns.push(tensor);
            }
            let count = columns[0].shape[0];
            if columns.iter().any(|c| c.shape[0] != count) {
                return Err(Error::input(
                    params.location_of(&CENTERS),
                    "\"centers\", \"scales\" and \"quaternions\" must have as many rows",
                ));
            }
            let at = |c: usize, i: usize| columns[c].values[i] as f32;
            for i in 0..count {
                data.centers
                    .push(Vec3::new(at(0, 3 * i), at(0, 3 * i + 1), at(0, 3 * i + 2)));
                data.scales
                    .push(Vec3::new(at(1, 3 * i), at(1, 3 * i + 1), at(1, 3 * i + 2)));
                data.quaternions.push(Vec4::new(
                    at(2, 4 * i),
                    at(2, 4 * i + 1),
                    at(2, 4 * i + 2),
                    at(2, 4 * i + 3),
                ));
            }
        }
    }
    let location = params.location_of(if params.has(&DATA) { &DATA } else { &CENTERS });
    for (i, ((center, scales), q)) in data
        .centers
        .iter()
        .zip(&data.scales)
        .zip(&data.quaternions)
        .enumerate()
    {
        let reason = if !(center.is_finite() && scales.is_finite() && q.is_finite()) {
            "has a number that is not finite"
        } else if scales.min_element() <= 0.0 {
            "has a scale that is not positive"
        } else if *q == Vec4::ZERO {
            "has a zero quaternion"
        } else {
            continue;
        };
        return Err(Error::input(location, format!("ellipsoid {i} {reason}")));
    }
    if let Some(tensor) = params.tensor_opt(&OPACITIES)? {
        let count = data.centers.len();
        if rows_of(&tensor, 1) != Some(count) {
            return Err(Error::input(
                params.location_of(&OPACITIES),
                format!(
                    "the \"opacities\" tensor has shape {:?}; it must be ({count}, 1) or ({count})",
                    tensor.shape
                ),
            ));
        }
        if tensor.values.iter().any(|v| v.is_nan()) {
            return Err(Error::input(
                params.location_of(&OPACITIES),
                "an opacity is not a number",
            ));
        }
        data.opacities = Some(tensor.values.iter().map(|&v| v as f32).collect());
    }
    Ok(data)
}

/// The rows of `tensor` read as rows of `width` numbers: N for a shape (N, width) or (N ·
/// width); None for any other shape.
fn rows_of(tensor: &Tensor, width: usize) -> Option<usize> {
    match *tensor.shape.as_slice() {
        [n, w] if w == width => Some(n),
        [length] if length % width == 0 => Some(length / width),
        _ => None,
    }
}
