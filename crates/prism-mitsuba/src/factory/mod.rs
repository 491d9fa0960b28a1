//! The plugin factory: turns a parsed Mitsuba scene description into a renderable [`Scene`].
//!
//! Each plugin class has its registry and builders in its own file (see [`crate::registry`]);
//! a builder reads its declared parameters through [`Params`], so that unknown or misspelled
//! parameters are reported with their location. Objects declared once and referenced many
//! times (a BSDF with an `id`) are built once.

pub mod integrators;
pub mod lights;
pub mod materials;
pub mod sensor;
pub mod shapes;
pub mod spectra;
pub mod textures;

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::sync::Arc;

use crate::description::{PluginClass, PluginNode};
use crate::params::Params;
use crate::registry::{Default, ParamSpec};
use prism_core::bsdf::Material;
use prism_core::error::{Error, Result};
use prism_core::geometry::{Geometry, Primitive, Shape};
use prism_core::integrator::{Integrator, PathIntegrator};
use prism_core::scene::Scene;
use prism_core::world::{ShapeInfo, World};

/// A renderable scene and the settings its file gives for rendering it.
pub struct LoadedScene {
    pub scene: Scene,
    /// The sampler's `seed` parameter.
    pub seed: u64,
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
    "lights other than area lights",
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
/// What the `<scene>` element holds.
const SCENE: &[ParamSpec] = &[INTEGRATOR, SENSOR, SHAPES, EMITTERS, BSDFS, TEXTURES];

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
    // The mesh attributes each material's textures read: (slot, name).
    let mut material_attributes: HashMap<u32, Vec<(u8, String)>> = HashMap::new();
    let mut shapes = Vec::new();
    let mut shape_info = Vec::new();
    let mut lights = Vec::new();
    let mut textures = textures::TextureCache::default();

    let integrator = match params.single_child(&INTEGRATOR)? {
        Some(child) => integrators::build_integrator(&child.node)?,
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
        let material = match shape_params.single_child(&shapes::BSDF)? {
            Some(bsdf) => {
                let key = Arc::as_ptr(&bsdf.node);
                match material_ids.get(&key) {
                    Some(&index) => index,
                    None => {
                        textures.take_used_slots();
                        materials.push(materials::build_material(&bsdf.node, &mut textures)?);
                        let index = (materials.len() - 1) as u32;
                        material_ids.insert(key, index);
                        material_attributes.insert(index, textures.take_used_slots());
                        index
                    }
                }
            }
            None if emitter.is_some() => {
                materials.push(lights::default_emitter_material());
                (materials.len() - 1) as u32
            }
            None => {
                materials.push(materials::default_material());
                (materials.len() - 1) as u32
            }
        };
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
                lights.push(lights::build_area_light(&emitter.node, shape_index)?);
                Some((lights.len() - 1) as u32)
            }
            None => None,
        };
        if let Some(attributes) = material_attributes.get(&material) {
            bind_mesh_attributes(&mut shape, attributes, &child.node)?;
        }
        shape_params.finish()?;
        if area == 0.0 {
            continue;
        }
        shapes.push(shape);
        shape_info.push(ShapeInfo { material, light });
    }

    let mut scene_lights = Vec::new();
    for child in params.children(&EMITTERS) {
        scene_lights.push((
            lights::build_scene_light(&child.node)?,
            child.location.clone(),
        ));
    }
    lights::check_single_environment(&scene_lights)?;
    lights.extend(scene_lights.into_iter().map(|(light, _)| light));

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
    params.finish()?;

    let world = World::new(Geometry::new(shapes), shape_info, materials, lights);
    let mut scene = Scene::new(
        world,
        sensor.camera,
        sensor.film,
        sensor.sampler,
        integrator,
    );
    scene.shutter = sensor.shutter;
    scene.fingerprint = crate::fingerprint::scene_fingerprint(root);
    Ok(LoadedScene {
        scene,
        seed: sensor.seed,
    })
}
