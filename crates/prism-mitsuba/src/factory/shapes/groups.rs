//! The entries of `shapegroup` and `instance`, which the scene builds itself
//! ([`crate::factory::instancing`]): as a member of a group, either is an error.

use super::Build;
use crate::description::PluginClass;
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::error::Error;

pub(super) const SHAPEGROUP: Plugin<Build> = Plugin {
    name: "shapegroup",
    origin: Origin::Mitsuba3,
    summary: "Shapes to be placed by `instance`s, which share their geometry and \
              hierarchy; renders nothing itself. No emitters, no nested groups or \
              instances (as in Mitsuba 3).",
    params: &[GROUP_SHAPES],
    build: |params, _| Err(nested_instancing(params, "a shapegroup")),
};

pub(super) const INSTANCE: Plugin<Build> = Plugin {
    name: "instance",
    origin: Origin::Mitsuba3,
    summary: "A `shapegroup` (by `<ref id=\"...\"/>`) placed by `to_world`; the scene's \
              hierarchy holds it as one primitive over the group's own.",
    params: &[INSTANCE_GROUP, INSTANCE_TO_WORLD],
    build: |params, _| Err(nested_instancing(params, "an instance")),
};

params! {
    /// The shapes of a `shapegroup`.
    pub GROUP_SHAPES = ParamSpec::nested(PluginClass::Shape, Default::None, "the group's shapes, each with its BSDF and media");
    /// The group an `instance` places.
    pub INSTANCE_GROUP = ParamSpec::nested(PluginClass::Shape, Default::Required, "the `shapegroup` placed, usually `<ref id=\"...\"/>`");
    /// The transform of an `instance`.
    pub INSTANCE_TO_WORLD = ParamSpec::new("to_world", ParamKind::AnimatedTransform, Default::Text("identity"), "group to world; an `<animation>` moves the instance during the exposure (Prism; Mitsuba 3 takes a fixed transform)");
}

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
