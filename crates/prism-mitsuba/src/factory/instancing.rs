//! Instancing: Mitsuba's `shapegroup` (shapes declared once, rendering nothing themselves) and
//! `instance` (a group placed by a transform).
//!
//! A group's shapes are built once into one object-space [`Aggregate`], shared through an `Arc`
//! by every instance of it, so a thousand trees cost one tree's memory plus a transform each.
//! Each instance is one primitive of the scene's hierarchy, bounded by its group's box swept by
//! its transform ([`Instance`]). A hit on a group's k-th shape is recorded as shape
//! `first + k`, where the group's shapes take consecutive shape ids after the scene's
//! primitives, so that each keeps its own material and media; every instance of a group shares
//! the ids. As in Mitsuba 3, groups hold no emitters and instancing does not nest.

use std::collections::HashMap;
use std::sync::Arc;

use super::shapes;
use crate::description::PluginNode;
use crate::params::Params;
use prism_core::error::{Error, Result};
use prism_core::geometry::{Aggregate, Instance, Primitive, Shape, ShapeGeometry};
use prism_core::medium::MediumInterface;
use prism_core::world::ShapeInfo;

/// One `shapegroup`: its shapes and, for each, its material and media.
struct ShapeGroup {
    object: Arc<Aggregate<Shape>>,
    members: Vec<(ShapeInfo, MediumInterface)>,
}

/// An instance as the scene takes it: its primitive, and the entry of its primitive in the
/// scene's shape table (never looked up, since hits report the group's shapes; it keeps the
/// table aligned with the primitives).
pub(super) struct PlacedInstance {
    pub primitive: Primitive,
    pub info: ShapeInfo,
}

/// The scene's shape groups, each built once however often it is placed, and its instances.
#[derive(Default)]
pub(super) struct ShapeGroups {
    groups: Vec<ShapeGroup>,
    ids: HashMap<*const PluginNode, usize>,
    /// (primitive index, group) of every instance.
    instances: Vec<(usize, usize)>,
}

impl ShapeGroups {
    /// The index of the group `node` describes, building it on first use; `member` gives a
    /// member shape's material and media from its parameters.
    pub fn group(
        &mut self,
        node: &Arc<PluginNode>,
        member: &mut dyn FnMut(&Params) -> Result<(u32, MediumInterface)>,
    ) -> Result<usize> {
        let key = Arc::as_ptr(node);
        if let Some(&index) = self.ids.get(&key) {
            return Ok(index);
        }
        let (_, params) = shapes::shape_params(node)?;
        let mut members = Vec::new();
        let mut object = Vec::new();
        for child in params.children(&shapes::GROUP_SHAPES) {
            let (plugin, shape_params) = shapes::shape_params(&child.node)?;
            let shape = match shapes::build_shape(plugin, &shape_params)? {
                Primitive::Shape(shape) => shape,
                Primitive::Instance(_) => {
                    return Err(Error::input(
                        &child.location,
                        "a shape of a shapegroup cannot move during the exposure",
                    )
                    .with_help("animate the instances' to_world instead"));
                }
            };
            shapes::check_area(shape.area(), child)?;
            if let Some(emitter) = shape_params.single_child(&shapes::EMITTER)? {
                return Err(Error::input(
                    &emitter.location,
                    "a shape of a shapegroup cannot emit light: emitters are not instanced",
                )
                .with_help(
                    "declare the emitting shape outside the shapegroup (as Mitsuba 3 requires)",
                ));
            }
            let (material, interface) = member(&shape_params)?;
            shape_params.finish()?;
            // A shape of zero area is never hit: read, as at the top level, and left out
            // (curves, ellipsoids and SDF grids, which have no area, excepted).
            if shape.area() == 0.0 && !shapes::is_hit_without_area(plugin) {
                continue;
            }
            object.push(shape);
            members.push((
                ShapeInfo {
                    material,
                    light: None,
                },
                interface,
            ));
        }
        params.finish()?;
        self.groups.push(ShapeGroup {
            object: Arc::new(Aggregate::new(object)),
            members,
        });
        let index = self.groups.len() - 1;
        self.ids.insert(key, index);
        Ok(index)
    }

    /// The instance `node` describes, to become primitive `primitive` of the scene; None for
    /// an instance of an empty group, which renders nothing.
    pub fn instance(
        &mut self,
        node: &Arc<PluginNode>,
        primitive: usize,
        member: &mut dyn FnMut(&Params) -> Result<(u32, MediumInterface)>,
    ) -> Result<Option<PlacedInstance>> {
        let (_, params) = shapes::shape_params(node)?;
        let Some(child) = params.single_child(&shapes::INSTANCE_GROUP)? else {
            return Err(
                Error::input(&node.location, "the instance names no shapegroup")
                    .with_help("give it the group it places: <ref id=\"...\"/>"),
            );
        };
        if child.node.plugin_type != "shapegroup" {
            return Err(Error::input(
                &child.location,
                format!(
                    "an instance places a shapegroup, not {}",
                    child.node.describe()
                ),
            )
            .with_help(
                "declare the shapes in a <shape type=\"shapegroup\" id=\"...\"> and reference it",
            ));
        }
        let to_world = params.animated_transform(&shapes::INSTANCE_TO_WORLD)?;
        params.finish()?;
        let group = self.group(&child.node, member)?;
        let Some(&(info, _)) = self.groups[group].members.first() else {
            return Ok(None);
        };
        self.instances.push((primitive, group));
        Ok(Some(PlacedInstance {
            primitive: Primitive::Instance(Instance::of_group(
                self.groups[group].object.clone(),
                to_world,
                0,
            )),
            info,
        }))
    }

    /// Gives the shapes of every placed group their ids, after the scene's primitives (whose
    /// ids are their indices), and tells each instance its group's first id.
    pub fn assign_shape_ids(
        self,
        primitives: &mut [Primitive],
        shape_info: &mut Vec<ShapeInfo>,
        medium_interfaces: &mut Vec<MediumInterface>,
    ) {
        let mut first_shape: Vec<Option<u32>> = vec![None; self.groups.len()];
        for (primitive, group) in self.instances {
            let first = *first_shape[group].get_or_insert_with(|| {
                let first = shape_info.len() as u32;
                for (info, interface) in &self.groups[group].members {
                    shape_info.push(*info);
                    medium_interfaces.push(*interface);
                }
                first
            });
            if let Primitive::Instance(instance) = &mut primitives[primitive] {
                instance.first_shape = Some(first);
            }
        }
    }
}
