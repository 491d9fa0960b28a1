//! Shape plugins: triangle meshes (`obj`, `ply`, `serialized`, `trianglemesh`, `rectangle`,
//! `cube`), quadrics (`sphere`, `disk`, `cylinder`), curves (`linearcurve`, `bsplinecurve`),
//! clouds of ellipsoids (`ellipsoids`), signed distance grids (`sdfgrid`),
//! and the entries of the instancing plugins `shapegroup` and `instance`, which the scene builds
//! ([`super::instancing`]). Any shape whose `to_world` is an `<animation>` moves while the
//! shutter is open: it is built in object space and placed by an [`Instance`].

/// The parameters of a shape: its own, then those every shape takes (`to_world`, `bsdf`,
/// `emitter`, `interior`, `exterior` and `sensor`).
macro_rules! shape_params {
    [$($own:expr),* $(,)?] => {
        &[
            $($own,)*
            $crate::factory::shapes::TO_WORLD,
            $crate::factory::shapes::BSDF,
            $crate::factory::shapes::EMITTER,
            $crate::factory::shapes::INTERIOR,
            $crate::factory::shapes::EXTERIOR,
            $crate::factory::shapes::SENSOR,
        ]
    };
}

mod curves;
mod ellipsoids;
mod groups;
mod meshes;
mod quadrics;
mod sdfgrid;

use crate::description::{NestedPlugin, PluginClass, PluginNode};
use crate::params::Params;
use crate::registry::{Default, ParamKind, ParamSpec, Plugin, Registry, params};
pub use groups::{GROUP_SHAPES, INSTANCE_GROUP, INSTANCE_TO_WORLD};
pub use meshes::{cube, rectangle, transform_mesh};
use prism_core::error::{Error, Result};
use prism_core::geometry::{Instance, Primitive, Shape};
use prism_core::math::Transform;

/// Builds a shape placed by a fixed transform.
type Build = fn(&Params, &Transform) -> Result<Shape>;

/// Every shape, each declared in the module of its kind.
pub static SHAPES: Registry<Build> = Registry {
    class: PluginClass::Shape,
    plugins: &[
        meshes::OBJ,
        meshes::PLY,
        meshes::SERIALIZED,
        meshes::TRIANGLEMESH,
        meshes::RECTANGLE,
        meshes::CUBE,
        quadrics::SPHERE,
        quadrics::DISK,
        quadrics::CYLINDER,
        curves::LINEARCURVE,
        curves::BSPLINECURVE,
        ellipsoids::ELLIPSOIDS,
        sdfgrid::SDFGRID,
        groups::SHAPEGROUP,
        groups::INSTANCE,
    ],
};

params! {
    /// The orientation of meshes and quadrics.
    FLIP_NORMALS = ParamSpec::new("flip_normals", ParamKind::Boolean, Default::Boolean(false), "turn the normals (and the side an area light emits from) inside out");
    /// The transform of every shape, whatever its type.
    pub TO_WORLD = ParamSpec::new("to_world", ParamKind::AnimatedTransform, Default::Text("identity"), "object to world; an `<animation>` of `<transform time=\"t\">` keys (Mitsuba 0.6's syntax) moves the shape during the exposure, interpolated as translation, rotation (slerp) and scale");
    /// The BSDF of every shape.
    pub BSDF = ParamSpec::nested(PluginClass::Bsdf, Default::Text("diffuse 0.5 (black when emitting)"), "what the shape is made of");
    /// The emitter of every shape.
    pub EMITTER = ParamSpec::nested(PluginClass::Emitter, Default::None, "an `area` emitter; or a `point`, `spot`, `projector` or `directional` one, which lights from its own `to_world` (as in Mitsuba 3)");
    /// The medium inside a shape (the side its normals point away from).
    pub INTERIOR = ParamSpec::new("interior", ParamKind::Nested(PluginClass::Medium), Default::None, "a `<medium name=\"interior\">` (or `<ref name=\"interior\" id=\"...\"/>`) inside the shape");
    /// The medium outside a shape.
    pub EXTERIOR = ParamSpec::new("exterior", ParamKind::Nested(PluginClass::Medium), Default::None, "a `<medium name=\"exterior\">` outside the shape");
    /// The sensor a shape carries.
    pub SENSOR = ParamSpec::nested(PluginClass::Sensor, Default::None, "an `irradiancemeter` measuring the irradiance on the shape");
}

/// Whether `plugin` makes shapes that are hit but have no area (nor area sampling): curves,
/// ellipsoids and SDF grids, which Mitsuba 3 gives no surface sampling.
pub fn is_hit_without_area(plugin: &Plugin<Build>) -> bool {
    matches!(
        plugin.name,
        "linearcurve" | "bsplinecurve" | "ellipsoids" | "sdfgrid"
    )
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

/// Checks that a built shape's area is a finite number (a degenerate transform or vertices
/// make it infinite or NaN).
pub fn check_area(area: f32, shape: &NestedPlugin) -> Result<()> {
    if area.is_finite() {
        return Ok(());
    }
    Err(Error::input(
        &shape.location,
        format!(
            "the area of {} is not a finite number",
            shape.node.describe()
        ),
    )
    .with_help("fix the shape's transform or its vertices"))
}
