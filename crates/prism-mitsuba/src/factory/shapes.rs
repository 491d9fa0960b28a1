//! Shape plugins: `obj`, `ply`, `serialized`, `rectangle`, `cube`, `sphere`, `disk`,
//! `cylinder`, `linearcurve` and `bsplinecurve`, and the instancing plugins `shapegroup` and `instance` (built by the scene,
//! [`super::instancing`]). Any shape whose
//! `to_world` is an `<animation>` moves while the shutter is open: it is built in object space
//! and placed by an [`Instance`].

use glam::{DMat4, DVec3, Mat3, Vec2, Vec3};

use crate::description::{PluginClass, PluginNode};
use crate::mesh::curves::{CurveData, load_curves};
use crate::mesh::{MeshData, load_obj, load_ply, load_serialized};
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, Registry};
use prism_core::error::{Error, Result};
use prism_core::geometry::shape::MeshAttribute;
use prism_core::geometry::shape::{BSplineCurve, Cylinder, LinearCurve};
use prism_core::geometry::{Disk, Instance, Primitive, Shape, Sphere, TriangleMesh};
use prism_core::math::Transform;

/// Builds a shape placed by a fixed transform.
type Build = fn(&Params, &Transform) -> Result<Shape>;

pub static SHAPES: Registry<Build> = Registry {
    class: PluginClass::Shape,
    plugins: &[
        Plugin {
            name: "obj",
            origin: Origin::Mitsuba3,
            summary: "A Wavefront OBJ mesh (polygons triangulated as fans; smooth vertex normals \
                      computed when the file has none).",
            params: &[
                FILENAME,
                FACE_NORMALS,
                FLIP_TEX_COORDS,
                FLIP_NORMALS,
                TO_WORLD,
                BSDF,
                EMITTER,
                INTERIOR,
                EXTERIOR,
            ],
            build: |params, to_world| build_mesh_file(params, to_world, MeshFormat::Obj),
        },
        Plugin {
            name: "ply",
            origin: Origin::Mitsuba3,
            summary: "A Stanford PLY mesh, ASCII or binary.",
            params: &[
                FILENAME,
                FACE_NORMALS,
                FLIP_NORMALS,
                TO_WORLD,
                BSDF,
                EMITTER,
                INTERIOR,
                EXTERIOR,
            ],
            build: |params, to_world| build_mesh_file(params, to_world, MeshFormat::Ply),
        },
        Plugin {
            name: "serialized",
            origin: Origin::Mitsuba3,
            summary: "A mesh of Mitsuba's compressed serialized format (versions 3 and 4; one \
                      file may hold several shapes); smooth vertex normals computed when the \
                      shape has none.",
            params: &[
                FILENAME,
                SHAPE_INDEX,
                FACE_NORMALS,
                FLIP_NORMALS,
                TO_WORLD,
                BSDF,
                EMITTER,
                INTERIOR,
                EXTERIOR,
            ],
            build: |params, to_world| build_mesh_file(params, to_world, MeshFormat::Serialized),
        },
        Plugin {
            name: "rectangle",
            origin: Origin::Mitsuba3,
            summary: "[−1, 1]² in the z = 0 plane, normal +z.",
            params: &[FLIP_NORMALS, TO_WORLD, BSDF, EMITTER, INTERIOR, EXTERIOR],
            build: |params, to_world| {
                Ok(Shape::Mesh(transform_mesh(
                    rectangle(),
                    to_world,
                    params.boolean(&FLIP_NORMALS)?,
                    true,
                )))
            },
        },
        Plugin {
            name: "cube",
            origin: Origin::Mitsuba3,
            summary: "[−1, 1]³ with outward normals, each face flat.",
            params: &[FLIP_NORMALS, TO_WORLD, BSDF, EMITTER, INTERIOR, EXTERIOR],
            build: |params, to_world| {
                Ok(Shape::Mesh(transform_mesh(
                    cube(),
                    to_world,
                    params.boolean(&FLIP_NORMALS)?,
                    true,
                )))
            },
        },
        Plugin {
            name: "sphere",
            origin: Origin::Mitsuba3,
            summary: "A sphere; light sampled by the cone it subtends. `to_world` may rotate, \
                      translate and scale uniformly.",
            params: &[
                CENTER,
                RADIUS,
                FLIP_NORMALS,
                TO_WORLD,
                BSDF,
                EMITTER,
                INTERIOR,
                EXTERIOR,
            ],
            build: build_sphere,
        },
        Plugin {
            name: "disk",
            origin: Origin::Mitsuba3,
            summary: "The unit disk in the z = 0 plane, normal +z.",
            params: &[FLIP_NORMALS, TO_WORLD, BSDF, EMITTER, INTERIOR, EXTERIOR],
            build: |params, to_world| {
                Ok(Shape::Disk(Disk::new(
                    *to_world,
                    params.boolean(&FLIP_NORMALS)?,
                )))
            },
        },
        Plugin {
            name: "cylinder",
            origin: Origin::Mitsuba3,
            summary: "An open tube (no caps) from `p0` to `p1`; (u, v) = (φ/2π, height along \
                      the axis, 0 to 1) as in Mitsuba. `to_world` may not make it elliptic or \
                      shear it.",
            params: &[
                P0,
                P1,
                CYLINDER_RADIUS,
                FLIP_NORMALS,
                TO_WORLD,
                BSDF,
                EMITTER,
                INTERIOR,
                EXTERIOR,
            ],
            build: build_cylinder,
        },
        Plugin {
            name: "linearcurve",
            origin: Origin::Mitsuba3,
            summary: "Round linear curves from a text file of control points `x y z radius` (a \
                      blank line between curves): each segment the sweep of a sphere of \
                      linearly varying radius, joints and ends round. `to_world` moves the \
                      points, not the radii (as in Mitsuba); back faces are culled; no area \
                      emitter (Mitsuba gives curves no area sampling).",
            params: &[CURVE_FILENAME, TO_WORLD, BSDF, EMITTER, INTERIOR, EXTERIOR],
            build: build_linear_curve,
        },
        Plugin {
            name: "bsplinecurve",
            origin: Origin::Mitsuba3,
            summary: "Round uniform cubic B-spline curves from a text file of control points \
                      `x y z radius` (a blank line between curves, at least four points each; \
                      n points make n − 3 segments): the sweep of circles of varying radius \
                      orthogonal to the curve, open at both ends (Embree's round B-spline \
                      curves). `to_world` moves the points, not the radii (as in Mitsuba); back \
                      faces are culled; no area emitter (Mitsuba gives curves no area \
                      sampling).",
            params: &[CURVE_FILENAME, TO_WORLD, BSDF, EMITTER, INTERIOR, EXTERIOR],
            build: build_bspline_curve,
        },
        Plugin {
            name: "shapegroup",
            origin: Origin::Mitsuba3,
            summary: "Shapes to be placed by `instance`s, which share their geometry and \
                      hierarchy; renders nothing itself. No emitters, no nested groups or \
                      instances (as in Mitsuba 3).",
            params: &[GROUP_SHAPES],
            build: |params, _| Err(nested_instancing(params, "a shapegroup")),
        },
        Plugin {
            name: "instance",
            origin: Origin::Mitsuba3,
            summary: "A `shapegroup` (by `<ref id=\"...\"/>`) placed by `to_world`; the scene's \
                      hierarchy holds it as one primitive over the group's own.",
            params: &[INSTANCE_GROUP, INSTANCE_TO_WORLD],
            build: |params, _| Err(nested_instancing(params, "an instance")),
        },
    ],
};

const P0: ParamSpec = ParamSpec::new(
    "p0",
    ParamKind::Point,
    Default::Text("(0, 0, 0)"),
    "centre of the cylinder's start",
);
const P1: ParamSpec = ParamSpec::new(
    "p1",
    ParamKind::Point,
    Default::Text("(0, 0, 1)"),
    "centre of the cylinder's end",
);
const CYLINDER_RADIUS: ParamSpec = ParamSpec::new(
    "radius",
    ParamKind::Float,
    Default::Float(1.0),
    "radius of the cylinder",
);

/// The shapes of a `shapegroup`.
pub const GROUP_SHAPES: ParamSpec = ParamSpec::nested(
    PluginClass::Shape,
    Default::None,
    "the group's shapes, each with its BSDF and media",
);
/// The group an `instance` places.
pub const INSTANCE_GROUP: ParamSpec = ParamSpec::nested(
    PluginClass::Shape,
    Default::Required,
    "the `shapegroup` placed, usually `<ref id=\"...\"/>`",
);
/// The transform of an `instance`.
pub const INSTANCE_TO_WORLD: ParamSpec = ParamSpec::new(
    "to_world",
    ParamKind::AnimatedTransform,
    Default::Text("identity"),
    "group to world; an `<animation>` moves the instance during the exposure (Prism; Mitsuba 3 \
     takes a fixed transform)",
);

/// The error for a `shapegroup` or `instance` inside a `shapegroup` (a shape built as a
/// group's member; the scene builds top-level groups and instances itself).
fn nested_instancing(params: &Params, what: &str) -> Error {
    Error::input(
        params.location(),
        format!("{what} cannot be part of a shapegroup: instancing does not nest"),
    )
    .with_help(
        "declare shapegroups and instances at the top level of the scene (as Mitsuba 3 requires)",
    )
}

const FILENAME: ParamSpec = ParamSpec::new(
    "filename",
    ParamKind::String,
    Default::Required,
    "the mesh file",
);
const CURVE_FILENAME: ParamSpec = ParamSpec::new(
    "filename",
    ParamKind::String,
    Default::Required,
    "the curve file",
);
const SHAPE_INDEX: ParamSpec = ParamSpec::new(
    "shape_index",
    ParamKind::Integer,
    Default::Integer(0),
    "which of the file's shapes to load, counted from 0",
);
const FACE_NORMALS: ParamSpec = ParamSpec::new(
    "face_normals",
    ParamKind::Boolean,
    Default::Boolean(false),
    "ignore vertex normals and shade flat",
);
const FLIP_TEX_COORDS: ParamSpec = ParamSpec::new(
    "flip_tex_coords",
    ParamKind::Boolean,
    Default::Boolean(true),
    "flip texture coordinates, v → 1 − v, as Mitsuba's OBJ reader does",
);
const FLIP_NORMALS: ParamSpec = ParamSpec::new(
    "flip_normals",
    ParamKind::Boolean,
    Default::Boolean(false),
    "turn the normals (and the side an area light emits from) inside out",
);
/// The transform of every shape, whatever its type.
pub const TO_WORLD: ParamSpec = ParamSpec::new(
    "to_world",
    ParamKind::AnimatedTransform,
    Default::Text("identity"),
    "object to world; an `<animation>` of `<transform time=\"t\">` keys (Mitsuba 0.6's syntax) \
     moves the shape during the exposure, interpolated as translation, rotation (slerp) and scale",
);
/// The BSDF of every shape.
pub const BSDF: ParamSpec = ParamSpec::nested(
    PluginClass::Bsdf,
    Default::Text("diffuse 0.5 (black when emitting)"),
    "what the shape is made of",
);
/// The emitter of every shape.
pub const EMITTER: ParamSpec =
    ParamSpec::nested(PluginClass::Emitter, Default::None, "an `area` emitter");
/// The medium inside a shape (the side its normals point away from).
pub const INTERIOR: ParamSpec = ParamSpec::new(
    "interior",
    ParamKind::Nested(PluginClass::Medium),
    Default::None,
    "a `<medium name=\"interior\">` (or `<ref name=\"interior\" id=\"...\"/>`) inside the shape",
);
/// The medium outside a shape.
pub const EXTERIOR: ParamSpec = ParamSpec::new(
    "exterior",
    ParamKind::Nested(PluginClass::Medium),
    Default::None,
    "a `<medium name=\"exterior\">` outside the shape",
);
const CENTER: ParamSpec = ParamSpec::new(
    "center",
    ParamKind::Point,
    Default::Text("the origin"),
    "centre of the sphere",
);
const RADIUS: ParamSpec = ParamSpec::new(
    "radius",
    ParamKind::Float,
    Default::Float(1.0),
    "radius of the sphere",
);

/// Whether `plugin` makes curves: shapes that are hit but have no area (nor area sampling).
pub fn is_curve(plugin: &Plugin<Build>) -> bool {
    matches!(plugin.name, "linearcurve" | "bsplinecurve")
}

/// The plugin a `<shape>` names, and its parameters.
pub fn shape_params(node: &PluginNode) -> Result<(&'static Plugin<Build>, Params<'_>)> {
    let plugin = SHAPES.find(node)?;
    Ok((plugin, Params::new(node, plugin.params)))
}

/// Builds a shape (its BSDF and emitter are the caller's business: it marks them used). A shape
/// whose `to_world` is an `<animation>` is built in object space and placed by an [`Instance`];
/// a fixed `to_world` is applied to the shape once.
pub fn build_shape(plugin: &Plugin<Build>, params: &Params) -> Result<Primitive> {
    // A `shapegroup` has no transform: the scene builds it, so it only gets here nested, where
    // its builder refuses it.
    if plugin.params.iter().all(|p| p.name != TO_WORLD.name) {
        return (plugin.build)(params, &Transform::IDENTITY).map(Primitive::Shape);
    }
    let to_world = params.animated_transform(&TO_WORLD)?;
    if to_world.is_animated() {
        let shape = (plugin.build)(params, &Transform::IDENTITY)?;
        return Ok(Primitive::Instance(Instance::new(shape, to_world)));
    }
    (plugin.build)(params, to_world.first()).map(Primitive::Shape)
}

/// The mesh file formats.
#[derive(Clone, Copy, PartialEq, Eq)]
enum MeshFormat {
    Obj,
    Ply,
    Serialized,
}

/// A mesh read from a file, placed by `to_world`.
fn build_mesh_file(params: &Params, to_world: &Transform, format: MeshFormat) -> Result<Shape> {
    let node = params.node();
    let flip_normals = params.boolean(&FLIP_NORMALS)?;
    let filename = params.string_opt(&FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"mesh.obj\"/>")
    })?;
    let location = params.location_of(&FILENAME);
    let path = node.resolve_file(filename, location)?;
    let face_normals = params.boolean(&FACE_NORMALS)?;
    // The OBJ reader flips v as Mitsuba's does; `flip_tex_coords="false"` undoes it. PLY and
    // serialized coordinates are used as stored.
    let unflip_tex_coords = format == MeshFormat::Obj && !params.boolean(&FLIP_TEX_COORDS)?;
    let loaded = match format {
        MeshFormat::Obj => load_obj(&path),
        MeshFormat::Ply => load_ply(&path),
        MeshFormat::Serialized => {
            let shape_index = params.integer(&SHAPE_INDEX)?;
            let shape_index = u32::try_from(shape_index).map_err(|_| {
                Error::input(
                    params.location_of(&SHAPE_INDEX),
                    format!("\"shape_index\" must be 0 or more, not {shape_index}"),
                )
            })?;
            load_serialized(&path, shape_index)
        }
    };
    let mut data = loaded.map_err(|e| mesh_error(e, node))?;
    data.validate(&path).map_err(|e| mesh_error(e, node))?;
    if unflip_tex_coords && let Some(uvs) = &mut data.uvs {
        for uv in uvs.iter_mut() {
            uv.y = 1.0 - uv.y;
        }
    }
    if data.triangles.is_empty() {
        return Err(Error::input(
            location,
            format!("the mesh \"{filename}\" has no triangles"),
        ));
    }
    if face_normals {
        data.normals = None;
    } else if data.normals.is_none() {
        data.compute_vertex_normals();
    }
    Ok(Shape::Mesh(transform_mesh(
        data,
        to_world,
        flip_normals,
        false,
    )))
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

/// Makes a mesh reading error an input error (the scene names the file) that also says which
/// scene element loaded the mesh; errors without a place in the mesh file get the element's.
fn mesh_error(error: Error, node: &PluginNode) -> Error {
    let in_mesh_file = error.location.is_some();
    let mut error = error.at(&node.location);
    if in_mesh_file {
        error.message = format!(
            "{} (mesh of {} at {})",
            error.message,
            node.describe(),
            node.location
        );
    }
    error
}

/// Moves a mesh to world space. Normals go through the inverse transpose; for the built-in
/// meshes (`oriented` = true) a transform that mirrors space also reverses the winding, so the
/// geometric normal stays the transformed +z normal as for Mitsuba's analytic rectangle.
pub fn transform_mesh(
    data: MeshData,
    to_world: &Transform,
    flip_normals: bool,
    oriented: bool,
) -> TriangleMesh {
    let positions = data.positions.iter().map(|&p| to_world.point(p)).collect();
    let normals = data.normals.map(|ns| {
        ns.iter()
            .map(|&n| to_world.normal(n).normalize_or_zero())
            .collect()
    });
    let mut triangles = data.triangles;
    if oriented && to_world.flips_handedness() {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    let mut mesh = TriangleMesh::new(positions, normals, data.uvs, triangles, flip_normals);
    let mut attributes = Vec::new();
    if let Some(colors) = data.colors {
        attributes.push(color_attribute(colors, false));
    }
    if let Some(colors) = data.face_colors {
        attributes.push(color_attribute(colors, true));
    }
    if !attributes.is_empty() {
        mesh.set_attributes(attributes);
    }
    mesh
}

/// Mitsuba's `vertex_color` (the vertices' linear RGB colours) or `face_color` (the
/// triangles') attribute.
fn color_attribute(colors: Vec<Vec3>, per_face: bool) -> MeshAttribute {
    MeshAttribute {
        name: if per_face {
            "face_color"
        } else {
            "vertex_color"
        }
        .to_string(),
        per_face,
        values: colors,
    }
}

/// Mitsuba's `rectangle`: [−1, 1]² in the z = 0 plane, normal +z, uv from (0, 0) to (1, 1).
pub fn rectangle() -> MeshData {
    MeshData {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: Some(vec![Vec3::Z; 4]),
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ]),
        colors: None,
        face_colors: None,
        triangles: vec![[0, 1, 2], [2, 3, 0]],
    }
}

/// Mitsuba's `cube`: [−1, 1]³ with outward normals, four vertices per face so that faces
/// are shaded flat.
pub fn cube() -> MeshData {
    let mut data = MeshData {
        positions: Vec::new(),
        normals: Some(Vec::new()),
        uvs: Some(Vec::new()),
        colors: None,
        face_colors: None,
        triangles: Vec::new(),
    };
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let n = axes[axis] * sign;
            // Tangents with b × c = n, so the corners below run counter-clockwise around n.
            let (b, c) = if sign > 0.0 {
                (axes[(axis + 1) % 3], axes[(axis + 2) % 3])
            } else {
                (axes[(axis + 2) % 3], axes[(axis + 1) % 3])
            };
            let base = data.positions.len() as u32;
            for (i, (sb, sc)) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .into_iter()
                .enumerate()
            {
                data.positions.push(n + b * sb + c * sc);
                if let Some(normals) = &mut data.normals {
                    normals.push(n);
                }
                if let Some(uvs) = &mut data.uvs {
                    uvs.push(Vec2::new(f32::from(i == 1 || i == 2), f32::from(i >= 2)));
                }
            }
            data.triangles.push([base, base + 1, base + 2]);
            data.triangles.push([base + 2, base + 3, base]);
        }
    }
    data
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat4;
    use prism_core::geometry::ShapeGeometry;

    #[test]
    fn cube_faces_point_outwards() {
        let mesh = transform_mesh(cube(), &Transform::IDENTITY, false, true);
        assert_eq!(mesh.triangles().len(), 12);
        assert!((mesh.area() - 24.0).abs() < 1e-5);
        for t in 0..12 {
            let [p0, p1, p2] = mesh.vertices(t);
            let n = (p1 - p0).cross(p2 - p0).normalize();
            let centre = (p0 + p1 + p2) / 3.0;
            assert!(n.dot(centre) > 0.0, "triangle {t} faces inwards");
        }
    }

    #[test]
    fn mirrored_rectangle_keeps_the_transformed_normal() {
        let mirror = Transform::new(DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))).unwrap();
        let mesh = transform_mesh(rectangle(), &mirror, false, true);
        let [p0, p1, p2] = mesh.vertices(0);
        assert!((p1 - p0).cross(p2 - p0).normalize().dot(Vec3::Z) > 0.99);
    }
}
