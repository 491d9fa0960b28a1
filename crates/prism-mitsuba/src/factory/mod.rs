//! The plugin factory: turns a parsed Mitsuba scene description into a renderable [`Scene`].
//!
//! Each plugin class has its registry and builders in its own file (see [`crate::registry`]);
//! a builder reads its declared parameters through [`Params`], so that unknown or misspelled
//! parameters are reported with their location. Objects declared once and referenced many
//! times (a BSDF with an `id`) are built once.

pub mod fov;
mod instancing;
pub mod integrators;
pub mod lights;
pub mod materials;
pub mod media;
pub mod sensor;
pub mod shapes;
pub mod spectra;
pub mod textures;

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::sync::Arc;

use crate::description::{PluginClass, PluginNode};
use crate::params::{Params, Warning};
use crate::registry::{Default, ParamSpec};
use prism_core::bsdf::Material;
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::geometry::{Geometry, Primitive, Shape};
use prism_core::integrator::{Integrator, PathIntegrator};
use prism_core::scene::Scene;
use prism_core::world::{ShapeInfo, World};

/// A renderable scene and the settings its file gives for rendering it.
pub struct LoadedScene {
    pub scene: Scene,
    /// The sampler's `seed` parameter.
    pub seed: u64,
    /// Parameters of the file that Prism reads but ignores (Mitsuba 0.6 forms), one warning
    /// each, in the order they were read.
    pub warnings: Vec<Warning>,
}

const INTEGRATOR: ParamSpec = ParamSpec::nested(
    PluginClass::Integrator,
    Default::Text("`path`"),
    "the integrator",
);
const SENSOR: ParamSpec = ParamSpec::nested(PluginClass::Sensor, Default::Required, "the camera");
const SHAPES: ParamSpec = ParamSpec::nested(PluginClass::Shape, Default::None, "the shapes");
const EMITTERS: ParamSpec = ParamSpec::nested(
    PluginClass::Emitter,
    Default::None,
    "lights; an `area` emitter here is attached to the shape that references its id",
);
const BSDFS: ParamSpec = ParamSpec::nested(
    PluginClass::Bsdf,
    Default::None,
    "BSDFs declared to be referenced by id",
);
const TEXTURES: ParamSpec = ParamSpec::nested(
    PluginClass::Texture,
    Default::None,
    "textures declared to be referenced by id",
);
const SAMPLERS: ParamSpec = ParamSpec::nested(
    PluginClass::Sampler,
    Default::None,
    "samplers declared to be referenced by id from the sensor",
);
const MEDIA: ParamSpec = ParamSpec::nested(
    PluginClass::Medium,
    Default::None,
    "media declared to be referenced by id",
);
/// What the `<scene>` element holds.
const SCENE: &[ParamSpec] = &[
    INTEGRATOR, SENSOR, SHAPES, EMITTERS, BSDFS, TEXTURES, SAMPLERS, MEDIA,
];

/// The scene's media, each built once however often it is referenced.
#[derive(Default)]
struct MediaCache {
    media: Vec<prism_core::medium::Medium>,
    ids: HashMap<*const PluginNode, u32>,
    /// Where the first medium is given, for the integrators that refuse media.
    first: Option<prism_core::error::SourceLocation>,
}

impl MediaCache {
    /// The index of the medium `child` describes (a `<medium>` or a reference to one).
    fn index(&mut self, child: &crate::description::NestedPlugin) -> Result<u32> {
        if child.node.class != PluginClass::Medium {
            return Err(Error::input(
                &child.location,
                format!("expected a <medium> here, not a {}", child.node.describe()),
            )
            .with_help("interior, exterior and the sensor's medium are <medium> elements"));
        }
        let key = Arc::as_ptr(&child.node);
        if let Some(&index) = self.ids.get(&key) {
            return Ok(index);
        }
        self.media.push(media::build_medium(&child.node)?);
        self.first.get_or_insert_with(|| child.location.clone());
        let index = (self.media.len() - 1) as u32;
        self.ids.insert(key, index);
        Ok(index)
    }
}

/// The index of a shape's material: its BSDF, built once however often it is referenced, or
/// the default (black for an emitter, as Mitsuba's, else diffuse 0.5).
fn shape_material(
    bsdf: Option<&crate::description::NestedPlugin>,
    emits: bool,
    materials: &mut Vec<Material>,
    material_ids: &mut HashMap<*const PluginNode, u32>,
    textures: &mut textures::TextureCache,
) -> Result<u32> {
    if let Some(bsdf) = bsdf {
        let key = Arc::as_ptr(&bsdf.node);
        if let Some(&index) = material_ids.get(&key) {
            return Ok(index);
        }
        textures.take_used_slots();
        materials.push(materials::build_material(&bsdf.node, textures)?);
        let index = (materials.len() - 1) as u32;
        material_ids.insert(key, index);
        let attributes = textures.take_used_slots();
        textures.set_material_attributes(index, attributes);
        return Ok(index);
    }
    materials.push(if emits {
        lights::default_emitter_material()
    } else {
        materials::default_material()
    });
    Ok((materials.len() - 1) as u32)
}

/// The media on the two sides of a shape (its `interior` and `exterior`).
fn shape_media(
    shape_params: &Params,
    media: &mut MediaCache,
) -> Result<prism_core::medium::MediumInterface> {
    let mut interface = prism_core::medium::MediumInterface::default();
    if let Some(child) = shape_params.named_child(&shapes::INTERIOR) {
        interface.interior = Some(media.index(child)?);
    }
    if let Some(child) = shape_params.named_child(&shapes::EXTERIOR) {
        interface.exterior = Some(media.index(child)?);
    }
    Ok(interface)
}

/// The material and media of a shape in a `shapegroup`.
fn group_member(
    member: &Params,
    materials: &mut Vec<Material>,
    material_ids: &mut HashMap<*const PluginNode, u32>,
    textures: &mut textures::TextureCache,
    media: &mut MediaCache,
) -> Result<(u32, prism_core::medium::MediumInterface)> {
    let material = shape_material(
        member.single_child(&shapes::BSDF)?,
        false,
        materials,
        material_ids,
        textures,
    )?;
    if let Some((_, name)) = textures.material_attributes(material).first() {
        let node = member.node();
        return Err(Error::input(
            &node.location,
            format!(
                "{} in a shapegroup has a BSDF that reads the mesh attribute \"{name}\"; Prism's \
                 instanced shapes carry no attributes",
                node.describe()
            ),
        )
        .with_help("place the mesh directly in the scene instead of through an instance"));
    }
    Ok((material, shape_media(member, media)?))
}

/// Makes the shape's mesh fill the attribute slots its BSDF's `mesh_attribute` textures read;
/// a shape without one of those attributes is an error (Mitsuba's "invalid attribute
/// requested", which it reports while rendering).
fn bind_mesh_attributes(
    shape: &mut Primitive,
    attributes: &[(u8, String)],
    node: &PluginNode,
) -> Result<()> {
    let Some((_, first)) = attributes.first() else {
        return Ok(());
    };
    let Primitive::Shape(Shape::Mesh(mesh)) = shape else {
        let what = if matches!(shape, Primitive::Instance(_)) {
            "a moving shape"
        } else {
            "a shape that is not a mesh"
        };
        return Err(Error::input(
            &node.location,
            format!(
                "{} has no attribute \"{first}\" (Mitsuba: invalid attribute requested): its \
                 BSDF reads mesh attributes, which {what} does not carry",
                node.describe()
            ),
        )
        .with_help("give the attribute to a ply or serialized mesh that has it"));
    };
    for (slot, name) in attributes {
        if !mesh.bind_attribute(name, *slot) {
            let names: Vec<&str> = mesh.attribute_names().collect();
            let has = if names.is_empty() {
                "it has none".to_string()
            } else {
                format!("it has {}", names.join(", "))
            };
            return Err(Error::input(
                &node.location,
                format!(
                    "{} has no attribute \"{name}\" (Mitsuba: invalid attribute requested); \
                     {has}",
                    node.describe()
                ),
            )
            .with_help(
                "use a mesh with per-vertex colours (PLY red green blue, or serialized colours)",
            ));
        }
    }
    Ok(())
}

/// Builds the scene described by the root `<scene>` node.
pub fn build_scene(root: &PluginNode) -> Result<LoadedScene> {
    let params = Params::new(root, SCENE);
    let mut materials: Vec<Material> = Vec::new();
    let mut material_ids: HashMap<*const PluginNode, u32> = HashMap::new();
    let mut shapes = Vec::new();
    let mut shape_info = Vec::new();
    let mut lights = Vec::new();
    let mut sampling_weights = Vec::new();
    let mut textures = textures::TextureCache::default();
    let mut media = MediaCache::default();
    let mut medium_interfaces = Vec::new();
    let mut groups = instancing::ShapeGroups::default();
    // The area emitters attached to shapes, with where each was attached (an emitter declared
    // at the top level with an id reaches its shape by a `<ref>`).
    let mut attached_emitters: HashMap<*const PluginNode, &SourceLocation> = HashMap::new();

    let integrator = match params.single_child(&INTEGRATOR)? {
        Some(child) => {
            let integrator = integrators::build_integrator(&child.node)?;
            integrators::check_channel_names(&integrator, &child.location)?;
            integrator
        }
        None => Integrator::Path(PathIntegrator::default()),
    };
    let sensors = params.children(&SENSOR);
    let Some(sensor) = sensors.first() else {
        return Err(Error::input(&root.location, "the scene has no <sensor>")
            .with_help("add a <sensor type=\"perspective\"> with a film and a sampler"));
    };
    if let Some(second) = sensors.get(1) {
        return Err(
            Error::input(&second.location, "the scene has more than one <sensor>")
                .with_help("Prism renders one sensor per scene: remove the others"),
        );
    }
    let sensor = sensor::build_sensor(&sensor.node)?;

    for child in params.children(&SHAPES) {
        match child.node.plugin_type.as_str() {
            "shapegroup" => {
                groups.group(&child.node, &mut |member| {
                    group_member(
                        member,
                        &mut materials,
                        &mut material_ids,
                        &mut textures,
                        &mut media,
                    )
                })?;
                continue;
            }
            "instance" => {
                if let Some(instance) =
                    groups.instance(&child.node, shapes.len(), &mut |member| {
                        group_member(
                            member,
                            &mut materials,
                            &mut material_ids,
                            &mut textures,
                            &mut media,
                        )
                    })?
                {
                    shapes.push(instance.primitive);
                    shape_info.push(instance.info);
                    medium_interfaces.push(prism_core::medium::MediumInterface::default());
                }
                continue;
            }
            _ => {}
        }
        let (plugin, shape_params) = shapes::shape_params(&child.node)?;
        let mut shape = shapes::build_shape(plugin, &shape_params)?;
        let area = shape.area();
        if !area.is_finite() {
            return Err(Error::input(
                &child.location,
                format!(
                    "the area of {} is not a finite number",
                    child.node.describe()
                ),
            )
            .with_help("fix the shape's transform or its vertices"));
        }
        let shape_index = shapes.len() as u32;
        let emitter = shape_params.single_child(&shapes::EMITTER)?;
        // Curves are hit but have no area sampling in Mitsuba, which refuses to make them
        // emit; so does Prism.
        let curve = shapes::is_curve(plugin);
        if curve && let Some(emitter) = &emitter {
            return Err(Error::input(
                &emitter.location,
                format!(
                    "{} cannot emit: curves have no area sampling (as in Mitsuba 3)",
                    child.node.describe()
                ),
            )
            .with_help("remove the emitter, or light the curves with another shape"));
        }
        // A shape of zero area is never hit, so it contributes nothing; like Mitsuba, Prism
        // reads it (its BSDF included) and renders without it, but an emitter needs an area
        // to send its power from (Mitsuba refuses it too).
        if area == 0.0
            && let Some(emitter) = &emitter
        {
            return Err(Error::input(
                &emitter.location,
                format!("{} has no area, so it cannot emit", child.node.describe()),
            )
            .with_help("remove the emitter, or fix the shape's transform or its vertices"));
        }
        let material = shape_material(
            shape_params.single_child(&shapes::BSDF)?,
            emitter.is_some(),
            &mut materials,
            &mut material_ids,
            &mut textures,
        )?;
        let light = match emitter {
            Some(emitter) => {
                if let Primitive::Instance(instance) = &shape
                    && !instance.to_world.is_similarity()
                {
                    return Err(Error::input(
                        &emitter.location,
                        "an emitting shape may move, turn and scale uniformly, but not stretch",
                    )
                    .with_help(
                        "animate the emitter with rotations, translations and uniform scales only",
                    ));
                }
                if let Some(first) =
                    attached_emitters.insert(Arc::as_ptr(&emitter.node), &emitter.location)
                {
                    return Err(Error::input(
                        &emitter.location,
                        format!(
                            "{} is already attached to the shape at {first}",
                            emitter.node.describe()
                        ),
                    )
                    .with_help(
                        "an area emitter can be attached to a single shape (as in Mitsuba): \
                         give each shape its own <emitter type=\"area\">",
                    ));
                }
                let (light, weight) =
                    lights::build_area_light(&emitter.node, shape_index, &mut textures)?;
                lights.push(light);
                sampling_weights.push(weight);
                Some((lights.len() - 1) as u32)
            }
            None => None,
        };
        bind_mesh_attributes(
            &mut shape,
            textures.material_attributes(material),
            &child.node,
        )?;
        let interface = shape_media(&shape_params, &mut media)?;
        shape_params.finish()?;
        if area == 0.0 && !curve {
            continue;
        }
        shapes.push(shape);
        shape_info.push(ShapeInfo { material, light });
        medium_interfaces.push(interface);
    }
    groups.assign_shape_ids(&mut shapes, &mut shape_info, &mut medium_interfaces);

    let mut scene_lights = Vec::new();
    for child in params.children(&EMITTERS) {
        if lights::is_area(&child.node) {
            // An area emitter declared at the top level belongs to the shape that references
            // it; one that no shape references emits nothing (Mitsuba ignores it), but its
            // parameters are still checked.
            if !attached_emitters.contains_key(&Arc::as_ptr(&child.node)) {
                lights::build_area_light(&child.node, 0, &mut textures)?;
            }
            continue;
        }
        let (light, weight) = lights::build_scene_light(&child.node, &mut textures)?;
        scene_lights.push((light, weight, child.location.clone()));
    }
    lights::check_single_environment(&scene_lights)?;
    for (light, weight, _) in scene_lights {
        lights.push(light);
        sampling_weights.push(weight);
    }

    // BSDFs declared at the top level (to be referenced by id) are built even when unused, so
    // that their errors are reported as Mitsuba would.
    for child in params.children(&BSDFS) {
        if let Entry::Vacant(entry) = material_ids.entry(Arc::as_ptr(&child.node)) {
            materials.push(materials::build_material(&child.node, &mut textures)?);
            entry.insert((materials.len() - 1) as u32);
        }
    }
    // Textures declared at the top level (referenced by id from BSDFs) are read even when no
    // BSDF uses them, so that a missing or corrupt image is reported.
    for child in params.children(&TEXTURES) {
        if !textures.contains(&child.node) {
            textures::build_texture(
                &child.node,
                prism_core::texture::TextureUse::Scalar,
                &mut textures,
            )?;
        }
    }
    // Samplers declared at the top level (to be referenced by id from the sensor) are checked
    // even when no sensor uses them.
    for child in params.children(&SAMPLERS) {
        sensor::build_sampler(&child.node)?;
    }
    let camera_medium = match &sensor.medium {
        Some(node) => Some(media.index(&crate::description::NestedPlugin {
            name: None,
            node: node.clone(),
            location: node.location.clone(),
        })?),
        None => None,
    };
    // Media declared at the top level are built even when unused, so that their errors are
    // reported.
    for child in params.children(&MEDIA) {
        media.index(child)?;
    }
    params.finish()?;
    if let (Integrator::Distribution(_), Some(location)) = (&integrator, &media.first) {
        return Err(Error::input(
            location,
            "the distrib integrator does not render participating media",
        )
        .with_help(
            "render scenes with media with <integrator type=\"volpath\"> or \"volpathmis\"",
        ));
    }

    let mut world = World::new(Geometry::new(shapes), shape_info, materials, lights)
        .with_sampling_weights(sampling_weights);
    if medium_interfaces.iter().any(|m| m.is_transition()) {
        world.medium_interfaces = medium_interfaces;
    }
    world.media = media.media;
    world.camera_medium = camera_medium;
    let mut scene = Scene::new(
        world,
        sensor.camera,
        sensor.film,
        sensor.sampler,
        integrator,
    );
    scene.shutter = sensor.shutter;
    scene.ldr_output = sensor.ldr_output;
    scene.fingerprint = crate::fingerprint::scene_fingerprint(root);
    Ok(LoadedScene {
        scene,
        seed: sensor.seed,
        warnings: sensor.warnings,
    })
}
