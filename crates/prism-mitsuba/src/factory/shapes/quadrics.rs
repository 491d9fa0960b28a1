//! Shapes given by an equation: the `sphere`, the `disk` and the open `cylinder`.

use super::{Build, FLIP_NORMALS, TO_WORLD};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, params};
use glam::{DMat4, DVec3, Mat3};
use prism_core::error::{Error, Result};
use prism_core::geometry::shape::Cylinder;
use prism_core::geometry::{Disk, Shape, Sphere};
use prism_core::math::Transform;

pub(super) const SPHERE: Plugin<Build> = Plugin {
    name: "sphere",
    origin: Origin::Mitsuba3,
    summary: "A sphere; light sampled by the cone it subtends. `to_world` may rotate, \
              translate and scale uniformly.",
    params: shape_params![CENTER, RADIUS, FLIP_NORMALS],
    build: build_sphere,
};

pub(super) const DISK: Plugin<Build> = Plugin {
    name: "disk",
    origin: Origin::Mitsuba3,
    summary: "The unit disk in the z = 0 plane, normal +z.",
    params: shape_params![FLIP_NORMALS],
    build: |params, to_world| {
        Ok(Shape::Disk(Disk::new(
            *to_world,
            params.boolean(&FLIP_NORMALS)?,
        )))
    },
};

pub(super) const CYLINDER: Plugin<Build> = Plugin {
    name: "cylinder",
    origin: Origin::Mitsuba3,
    summary: "An open tube (no caps) from `p0` to `p1`; (u, v) = (φ/2π, height along \
              the axis, 0 to 1) as in Mitsuba. `to_world` may not make it elliptic or \
              shear it.",
    params: shape_params![P0, P1, CYLINDER_RADIUS, FLIP_NORMALS],
    build: build_cylinder,
};

params! {
    CENTER = ParamSpec::new("center", ParamKind::Point, Default::Text("the origin"), "centre of the sphere");
    RADIUS = ParamSpec::new("radius", ParamKind::Float, Default::Float(1.0), "radius of the sphere");
    P0 = ParamSpec::new("p0", ParamKind::Point, Default::Text("(0, 0, 0)"), "centre of the cylinder's start");
    P1 = ParamSpec::new("p1", ParamKind::Point, Default::Text("(0, 0, 1)"), "centre of the cylinder's end");
    CYLINDER_RADIUS = ParamSpec::new("radius", ParamKind::Float, Default::Float(1.0), "radius of the cylinder");
}

/// A sphere placed by `to_world`, which may only rotate, translate and scale uniformly.
fn build_sphere(params: &Params, to_world: &Transform) -> Result<Shape> {
    let flip_normals = params.boolean(&FLIP_NORMALS)?;
    let center = params.point_opt(&CENTER)?.unwrap_or(DVec3::ZERO);
    let radius = params.float(&RADIUS)?;
    if !(radius > 0.0 && radius.is_finite()) {
        return Err(Error::input(
            params.location_of(&RADIUS),
            format!("the sphere's radius must be positive, not {radius}"),
        ));
    }
    let matrix = to_world.matrix.as_dmat4();
    let axes = [
        matrix.x_axis.truncate(),
        matrix.y_axis.truncate(),
        matrix.z_axis.truncate(),
    ];
    let scale = axes[0].length();
    let uniform = axes
        .iter()
        .all(|a| (a.length() - scale).abs() <= 1e-5 * scale)
        && axes[0].dot(axes[1]).abs() <= 1e-5 * scale * scale
        && axes[1].dot(axes[2]).abs() <= 1e-5 * scale * scale
        && axes[0].dot(axes[2]).abs() <= 1e-5 * scale * scale;
    if !uniform {
        return Err(Error::input(
            params.location_of(&TO_WORLD),
            "a sphere's \"to_world\" may only rotate, translate and scale uniformly",
        )
        .with_help("use a triangle mesh for ellipsoids"));
    }
    let rotation = Mat3::from_cols(
        (axes[0] / scale).as_vec3(),
        (axes[1] / scale).as_vec3(),
        (axes[2] / scale).as_vec3(),
    );
    Ok(Shape::Sphere(Sphere {
        center: matrix.transform_point3(center).as_vec3(),
        radius: (radius * scale) as f32,
        rotation,
        flip_normals,
    }))
}

/// Mitsuba's `cylinder`: the unit tube of the object frame placed by
/// to_world · translate(p0) · frame(p1 − p0) · scale(r, r, |p1 − p0|), where frame(d) turns z
/// into d with Mitsuba's orthonormal basis (Duff et al. 2017, "Building an Orthonormal Basis,
/// Revisited"), so that φ starts where Mitsuba's does.
fn build_cylinder(params: &Params, to_world: &Transform) -> Result<Shape> {
    let flip_normals = params.boolean(&FLIP_NORMALS)?;
    let p0 = params.point_opt(&P0)?.unwrap_or(DVec3::ZERO);
    let p1 = params.point_opt(&P1)?.unwrap_or(DVec3::Z);
    let radius = params.float(&CYLINDER_RADIUS)?;
    if !(radius > 0.0 && radius.is_finite()) {
        return Err(Error::input(
            params.location_of(&CYLINDER_RADIUS),
            format!("the cylinder's radius must be positive, not {radius}"),
        ));
    }
    let axis = p1 - p0;
    let length = axis.length();
    if !(length > 0.0 && length.is_finite()) {
        return Err(Error::input(
            &params.node().location,
            "the cylinder's \"p0\" and \"p1\" are the same point",
        )
        .with_help("give the two ends of its axis"));
    }
    let n = axis / length;
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let s = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let t = DVec3::new(b, sign + n.y * n.y * a, -n.y);
    let frame = DMat4::from_cols(
        (s * radius).extend(0.0),
        (t * radius).extend(0.0),
        (n * length).extend(0.0),
        p0.extend(1.0),
    );
    let matrix = to_world.matrix.as_dmat4() * frame;
    let [x, y, z] = [matrix.x_axis, matrix.y_axis, matrix.z_axis].map(|c| c.truncate());
    let r = x.length();
    let tolerance = 1e-5 * r * (r + z.length());
    let circular = (y.length() - r).abs() <= 1e-5 * r
        && x.dot(y).abs() <= tolerance
        && x.dot(z).abs() <= tolerance
        && y.dot(z).abs() <= tolerance;
    if !circular {
        return Err(Error::input(
            params.location_of(&TO_WORLD),
            "a cylinder's \"to_world\" may not make it elliptic or shear it",
        )
        .with_help("rotate, translate and scale it uniformly (or along its axis only)"));
    }
    let transform = Transform::new(matrix).ok_or_else(|| {
        Error::input(
            params.location_of(&TO_WORLD),
            "the cylinder's \"to_world\" is singular",
        )
    })?;
    Ok(Shape::Cylinder(Cylinder::new(transform, flip_normals)))
}
