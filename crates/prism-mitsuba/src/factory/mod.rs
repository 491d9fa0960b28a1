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
use prism_core::geometry::{Geometry, Primitive};
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

/// Builds the scene described by the root `<scene>` node.
pub fn build_scene(root: &PluginNode) -> Result<LoadedScene> {
    let params = Params::new(root, SCENE);
    let mut materials: Vec<Material> = Vec::new();
    let mut material_ids: HashMap<*const PluginNode, u32> = HashMap::new();
    let mut shapes = Vec::new();
    let mut shape_info = Vec::new();
    let mut lights = Vec::new();
    let mut textures = textures::TextureCache::default();

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
        let (plugin, shape_params) = shapes::shape_params(&child.node)?;
        let shape = shapes::build_shape(plugin, &shape_params)?;
        if shape.area() == 0.0 || !shape.area().is_finite() {
            return Err(Error::input(
                &child.location,
                format!("{} has no area", child.node.describe()),
            )
            .with_help("remove degenerate shapes or fix their transform"));
        }
        let shape_index = shapes.len() as u32;
        let emitter = shape_params.single_child(&shapes::EMITTER)?;
        let material = match shape_params.single_child(&shapes::BSDF)? {
            Some(bsdf) => {
                let key = Arc::as_ptr(&bsdf.node);
                match material_ids.get(&key) {
                    Some(&index) => index,
                    None => {
                        materials.push(materials::build_material(&bsdf.node, &mut textures)?);
                        let index = (materials.len() - 1) as u32;
                        material_ids.insert(key, index);
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
        shape_params.finish()?;
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
