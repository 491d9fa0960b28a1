//! The scene builder: reads the sections of the root `<scene>` (integrator, sensors, shapes,
//! emitters, and the BSDFs, textures, samplers and media declared to be referenced by id) into
//! a renderable [`Scene`], each object built once however often it is referenced.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::sync::Arc;

use super::instancing::ShapeGroups;
use super::sensor::SensorSettings;
use super::sensor_choice::SceneSensor;
use super::textures::TextureCache;
use super::{integrators, lights, materials, media, sensor, shapes, textures};
use crate::description::{NestedPlugin, PluginClass, PluginNode, Warning};
use crate::params::Params;
use crate::registry::{Default, ParamSpec, params};
use prism_core::bsdf::Material;
use prism_core::camera::{Camera, CameraModel};
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::geometry::{Geometry, Primitive, Shape};
use prism_core::integrator::{Integrator, PathIntegrator};
use prism_core::light::{BoundingSphere, Light};
use prism_core::medium::{Medium, MediumInterface};
use prism_core::scene::Scene;
use prism_core::texture::TextureUse;
use prism_core::world::{ShapeInfo, World};

/// A renderable scene and the settings its file gives for rendering it.
pub struct LoadedScene {
    /// The scene, seen through the selected sensor (the first until [`Self::select_sensor`]).
    pub scene: Scene,
    /// The selected sensor's sampler's `seed` parameter.
    pub seed: u64,
    /// Parameters of the file that Prism reads but ignores (Mitsuba 0.6 forms), and where
    /// Mitsuba would render the file otherwise, one warning each, in the order they were read.
    pub warnings: Vec<Warning>,
    /// The `<shape>` (or `instance`) of the description that made each primitive of the
    /// world's geometry, in the primitives' order.
    pub shape_plugins: Vec<Arc<PluginNode>>,
    /// The `<emitter>` of the description that made each of the world's lights, in the
    /// lights' order.
    pub emitter_plugins: Vec<Arc<PluginNode>>,
    /// Every `<sensor>`, in document order (Mitsuba loads them all and renders the first unless
    /// told otherwise).
    pub(super) sensors: Vec<SceneSensor>,
    /// The index of the sensor `scene` is seen through.
    pub(super) selected: usize,
    /// The fingerprint of the scene's description, before any choice of sensor or override.
    pub(super) description_fingerprint: u64,
}

params! {
    INTEGRATOR = ParamSpec::nested(PluginClass::Integrator, Default::Text("`path`"), "the integrator");
    SENSOR = ParamSpec::nested(PluginClass::Sensor, Default::Required, "the cameras: Prism renders the first, or the one `prism render --sensor` names (an id or an index from 0)");
    SHAPES = ParamSpec::nested(PluginClass::Shape, Default::None, "the shapes");
    EMITTERS = ParamSpec::nested(PluginClass::Emitter, Default::None, "lights; an `area` emitter here is attached to the shape that references its id");
    BSDFS = ParamSpec::nested(PluginClass::Bsdf, Default::None, "BSDFs declared to be referenced by id");
    TEXTURES = ParamSpec::nested(PluginClass::Texture, Default::None, "textures declared to be referenced by id");
    SAMPLERS = ParamSpec::nested(PluginClass::Sampler, Default::None, "samplers declared to be referenced by id from the sensor");
    MEDIA = ParamSpec::nested(PluginClass::Medium, Default::None, "media declared to be referenced by id");
}
/// What the `<scene>` element holds.
const SCENE: &[ParamSpec] = &[
    INTEGRATOR, SENSOR, SHAPES, EMITTERS, BSDFS, TEXTURES, SAMPLERS, MEDIA,
];

/// Builds the scene described by the root `<scene>` node, section by section; each section
/// reports its errors in the order Mitsuba would.
pub fn build_scene(root: &PluginNode) -> Result<LoadedScene> {
    build_scene_with_geometry(root, &mut None)
}

/// The hierarchy of a scene built before from the description being built, or from an edit of
/// it with the same plugins.
#[derive(Debug)]
pub enum KeptGeometry {
    /// Built from the same shapes (no parameter of a `<shape>`, shape group or instance
    /// changed): used as it is.
    Unchanged(Geometry),
    /// Built from the shapes before a shape's parameters changed: refit to the shapes read
    /// where they are the same primitives moved, else built again ([`Geometry::refit`]).
    Moved(Geometry),
}

impl KeptGeometry {
    pub fn into_geometry(self) -> Geometry {
        match self {
            KeptGeometry::Unchanged(geometry) | KeptGeometry::Moved(geometry) => geometry,
        }
    }
}

/// Builds the scene as [`build_scene`] does, but from the hierarchy `geometry` holds rather
/// than one built from scratch over the shapes, taken from it when the build succeeds (and
/// left there when it fails).
pub fn build_scene_with_geometry(
    root: &PluginNode,
    geometry: &mut Option<KeptGeometry>,
) -> Result<LoadedScene> {
    let params = Params::new(root, SCENE);
    let integrator_child = params.single_child(&INTEGRATOR)?;
    let integrator = integrator(integrator_child)?;
    let mut sensors = top_level_sensors(&params)?;
    let mut builder = SceneBuilder::default();
    builder.shapes(&params)?;
    sensors.append(&mut builder.shape_sensors);
    let sensors = in_document_order(root, sensors)?;
    builder.emitters(&params)?;
    builder.declared_bsdfs(&params)?;
    builder.declared_textures(&params)?;
    for child in params.children(&SAMPLERS) {
        // Checked even when no sensor references it.
        sensor::sampler::build_sampler(&child.node)?;
    }
    let mut scene_sensors = Vec::with_capacity(sensors.len());
    let mut warnings = Vec::new();
    let integrator_location = integrator_child.map_or(&root.location, |c| &c.location);
    for (id, sensor) in sensors {
        check_band_names(&integrator, &sensor, integrator_location)?;
        check_connectable(&integrator, &sensor, integrator_location)?;
        let medium = match &sensor.medium {
            Some(node) => Some(builder.media.index(&NestedPlugin {
                name: None,
                node: node.clone(),
                location: node.location.clone(),
            })?),
            None => None,
        };
        warnings.extend(sensor.warnings);
        scene_sensors.push(SceneSensor {
            id,
            camera: sensor.camera,
            shutter: sensor.shutter,
            film: sensor.film,
            sampler: sensor.sampler,
            seed: sensor.seed,
            exr_output: sensor.exr_output,
            ldr_output: sensor.ldr_output,
            medium,
        });
    }
    builder.declared_media(&params)?;
    params.finish()?;
    check_renders_media(&integrator, &builder.media)?;
    check_renders_polarization(
        &integrator,
        &builder.materials.materials,
        integrator_location,
    )?;
    check_bdpt_lights(&integrator, &builder.lights, &builder.light_locations)?;
    let delta_light_warning = integrator_child.and_then(|child| {
        integrators::direct_delta_light_warning(&child.node, &integrator, &builder.lights)
    });
    warnings.extend(delta_light_warning);
    let geometry = geometry.take();
    Ok(builder.finish(root, integrator, scene_sensors, warnings, geometry))
}

/// The scene's integrator, `path` by default.
fn integrator(child: Option<&NestedPlugin>) -> Result<Integrator> {
    match child {
        Some(child) => {
            let integrator = integrators::build_integrator(&child.node)?;
            integrators::check_channel_names(&integrator, &child.location)?;
            Ok(integrator)
        }
        None => Ok(Integrator::Path(PathIntegrator::default())),
    }
}

/// A sensor of the scene with its id, and the child of the `<scene>` that declares it (the
/// `<sensor>` itself, or the `<shape>` that carries it).
struct DeclaredSensor {
    declared_by: *const PluginNode,
    id: Option<String>,
    settings: SensorSettings,
}

/// The `<sensor>`s at the top level of the scene.
fn top_level_sensors(params: &Params) -> Result<Vec<DeclaredSensor>> {
    (params.children(&SENSOR).iter())
        .map(|child| {
            Ok(DeclaredSensor {
                declared_by: Arc::as_ptr(&child.node),
                id: child.node.id.clone(),
                settings: sensor::build_sensor(&child.node)?,
            })
        })
        .collect()
}

/// The scene's sensors with their ids, in document order, as Mitsuba lists them (a sensor
/// carried by a shape stands where its shape does); a scene needs one.
fn in_document_order(
    root: &PluginNode,
    mut sensors: Vec<DeclaredSensor>,
) -> Result<Vec<(Option<String>, SensorSettings)>> {
    if sensors.is_empty() {
        return Err(Error::input(&root.location, "the scene has no <sensor>")
            .with_help("add a <sensor type=\"perspective\"> with a film and a sampler"));
    }
    let position = |declared_by: *const PluginNode| {
        (root.children.iter()).position(|child| Arc::as_ptr(&child.node) == declared_by)
    };
    sensors.sort_by_key(|sensor| position(sensor.declared_by));
    Ok(sensors.into_iter().map(|s| (s.id, s.settings)).collect())
}

/// A spectral film's channels must not take the names of the integrator (at `location`).
fn check_band_names(
    integrator: &Integrator,
    sensor: &SensorSettings,
    location: &SourceLocation,
) -> Result<()> {
    let names = integrator.aov_names();
    match (sensor.film.bands.iter()).find(|band| names.contains(&band.name)) {
        Some(band) => Err(Error::input(
            location,
            format!(
                "the spectral film's channel \"{}\" would replace the integrator's",
                band.name
            ),
        )
        .with_help("rename the spectrum or the integrator's channel")),
        None => Ok(()),
    }
}

/// The ptracer and bdpt integrators connect light subpaths to a camera: a sensor of one ray or one
/// direction (`radiancemeter`, `distant`), a surface's meter (`irradiancemeter`) or a `batch`
/// cannot take it (an error at the integrator, `location`).
fn check_connectable(
    integrator: &Integrator,
    sensor: &SensorSettings,
    location: &SourceLocation,
) -> Result<()> {
    let name = match integrator {
        Integrator::Particle(_) => "ptracer",
        Integrator::Bdpt(_) => "bdpt",
        Integrator::Vcm(_) => "vcm",
        _ => return Ok(()),
    };
    let kind = match &sensor.camera {
        Camera::RadianceMeter(_) => "radiancemeter",
        Camera::IrradianceMeter(_) => "irradiancemeter",
        Camera::Distant(_) => "distant",
        Camera::Batch(_) => "batch",
        Camera::Perspective(_) | Camera::Orthographic(_) => return Ok(()),
    };
    Err(Error::input(
        location,
        format!("the {name} integrator cannot connect light paths to a {kind} sensor"),
    )
    .with_help("render it with <integrator type=\"path\">, or use a perspective, thinlens or orthographic sensor"))
}

/// The distrib, ptracer, bdpt, sppm and guided_path integrators estimate no participating
/// media: a scene with media and any of them is an error at the first medium.
fn check_renders_media(integrator: &Integrator, media: &MediaCache) -> Result<()> {
    let name = match integrator {
        Integrator::Distribution(_) => "distrib",
        Integrator::Particle(_) => "ptracer",
        Integrator::Bdpt(_) => "bdpt",
        Integrator::Sppm(_) => "sppm",
        Integrator::Guided(_) => "guided_path",
        Integrator::Vcm(_) => "vcm",
        _ => return Ok(()),
    };
    if let Some(location) = &media.first {
        return Err(Error::input(
            location,
            format!("the {name} integrator does not render participating media"),
        )
        .with_help(
            "render scenes with media with <integrator type=\"volpath\"> or \"volpathmis\"",
        ));
    }
    Ok(())
}

/// A scene with a polarizing BSDF renders polarized with `path`, `volpath` and `volpathmis`
/// (and `stokes`); `direct`, whose light from unpolarized emitters scatters once, gives the
/// polarized intensity exactly (S₀ = M₀₀ L), and `depth` and `aov` trace no light. The other
/// integrators that follow light over several vertices carry no polarization, so that light
/// through two polarizers would come out wrong: such a scene is an error at the integrator.
fn check_renders_polarization(
    integrator: &Integrator,
    materials: &[Material],
    location: &SourceLocation,
) -> Result<()> {
    let name = match integrator {
        Integrator::Distribution(_) => "distrib",
        Integrator::Particle(_) => "ptracer",
        Integrator::Bdpt(_) => "bdpt",
        Integrator::Sppm(_) => "sppm",
        Integrator::Guided(_) => "guided_path",
        Integrator::Vcm(_) => "vcm",
        Integrator::Moment(_) => "moment",
        _ => return Ok(()),
    };
    if !materials.iter().any(Material::is_polarizing) {
        return Ok(());
    }
    Err(Error::input(
        location,
        format!(
            "the {name} integrator does not render polarized light, and the scene has a \
             polarizing BSDF (polarizer, retarder, circular or measured_polarized)"
        ),
    )
    .with_help(
        "render it with <integrator type=\"path\"> or \"volpath\" (polarized, as Mitsuba's \
         *_polarized variants render them; nested in <integrator type=\"stokes\"> for the \
         Stokes vector)",
    ))
}

/// The bdpt and vcm integrators start light subpaths on area and point lights only: any other
/// light is an error where it was declared.
fn check_bdpt_lights(
    integrator: &Integrator,
    lights: &[Light],
    locations: &[SourceLocation],
) -> Result<()> {
    let name = match integrator {
        Integrator::Bdpt(_) => "bdpt",
        Integrator::Vcm(_) => "vcm",
        _ => return Ok(()),
    };
    for (light, location) in lights.iter().zip(locations) {
        let kind = match light {
            Light::Area(_) | Light::Point(_) => continue,
            Light::Spot(_) => "spot",
            Light::Projector(_) => "projector",
            Light::Directional(_) => "directional",
            Light::Constant(_) => "constant",
            Light::Envmap(_) => "envmap",
            Light::EqualAreaEnvmap(_) => "equal_area_envmap",
            Light::Sunsky(_) => "sunsky",
            Light::DirectionalArea(_) => "directionalarea",
        };
        return Err(Error::input(
            location,
            format!("the {name} integrator does not start light paths on a {kind} emitter"),
        )
        .with_help(format!(
            "{name} takes area and point emitters; render this scene with <integrator type=\"path\">"
        )));
    }
    Ok(())
}

/// The parts of the world read so far.
#[derive(Default)]
struct SceneBuilder {
    materials: MaterialCache,
    textures: TextureCache,
    media: MediaCache,
    shapes: Vec<Primitive>,
    shape_plugins: Vec<Arc<PluginNode>>,
    shape_info: Vec<ShapeInfo>,
    medium_interfaces: Vec<MediumInterface>,
    lights: Vec<Light>,
    emitter_plugins: Vec<Arc<PluginNode>>,
    /// Where each light was declared.
    light_locations: Vec<SourceLocation>,
    sampling_weights: Vec<f32>,
    /// The area emitters attached to shapes, with where each was attached (an emitter declared
    /// at the top level with an id reaches its shape by a `<ref>`).
    attached_emitters: HashMap<*const PluginNode, SourceLocation>,
    /// The sensors shapes carry (irradiance meters).
    shape_sensors: Vec<DeclaredSensor>,
}

impl SceneBuilder {
    /// The `<shape>` section: shape groups, instances and shapes, in document order.
    fn shapes(&mut self, params: &Params) -> Result<()> {
        let mut groups = ShapeGroups::default();
        for child in params.children(&SHAPES) {
            let Self {
                materials,
                textures,
                media,
                ..
            } = self;
            let mut member = |member: &Params| materials.group_member(member, textures, media);
            match child.node.plugin_type.as_str() {
                "shapegroup" => {
                    groups.group(&child.node, &mut member)?;
                }
                "instance" => {
                    let index = self.shapes.len();
                    if let Some(instance) = groups.instance(&child.node, index, &mut member)? {
                        self.shapes.push(instance.primitive);
                        self.shape_plugins.push(child.node.clone());
                        self.shape_info.push(instance.info);
                        self.medium_interfaces.push(MediumInterface::default());
                    }
                }
                _ => self.shape(child)?,
            }
        }
        groups.assign_shape_ids(
            &mut self.shapes,
            &mut self.shape_info,
            &mut self.medium_interfaces,
        );
        Ok(())
    }

    /// One shape, with its material, its area light and its media.
    fn shape(&mut self, child: &NestedPlugin) -> Result<()> {
        let (plugin, shape_params) = shapes::shape_params(&child.node)?;
        let mut shape = shapes::build_shape(plugin, &shape_params)?;
        let area = shape.area();
        shapes::check_area(area, child)?;
        let shape_index = self.shapes.len() as u32;
        let emitter = shape_params.single_child(&shapes::EMITTER)?;
        // Curves, ellipsoids and SDF grids are hit but have no area sampling in Mitsuba, which
        // refuses to make curves emit (and never samples an emitter on the others); Prism
        // refuses them all.
        let no_area = shapes::is_hit_without_area(plugin);
        if no_area && let Some(emitter) = &emitter {
            return Err(Error::input(
                &emitter.location,
                format!(
                    "{} cannot emit: it has no area sampling (as in Mitsuba 3)",
                    child.node.describe()
                ),
            )
            .with_help("remove the emitter, or light the scene with another shape"));
        }
        // A shape of zero area is never hit, so it contributes nothing; like Mitsuba, Prism
        // reads it (its BSDF included) and renders without it, but an emitter needs an area
        // to send its power from (Mitsuba refuses it too).
        if area == 0.0
            && let Some(emitter) = &emitter
            && !lights::is_delta(&emitter.node)
        {
            return Err(Error::input(
                &emitter.location,
                format!("{} has no area, so it cannot emit", child.node.describe()),
            )
            .with_help("remove the emitter, or fix the shape's transform or its vertices"));
        }
        let material = self.materials.shape_material(
            shape_params.single_child(&shapes::BSDF)?,
            emitter.is_some(),
            &mut self.textures,
        )?;
        let light = match emitter {
            Some(emitter) => self.attach_emitter(&shape, shape_index, emitter)?,
            None => None,
        };
        bind_mesh_attributes(&mut shape, material, &self.textures, &child.node)?;
        let interface = shape_media(&shape_params, &mut self.media)?;
        if let Some(meter) = shape_params.single_child(&shapes::SENSOR)? {
            self.shape_sensors.push(DeclaredSensor {
                declared_by: Arc::as_ptr(&child.node),
                id: meter.node.id.clone(),
                settings: sensor::build_shape_sensor(&meter.node, &child.node, &shape)?,
            });
        }
        shape_params.finish()?;
        if area == 0.0 && !no_area {
            return Ok(());
        }
        self.shapes.push(shape);
        self.shape_plugins.push(child.node.clone());
        self.shape_info.push(ShapeInfo { material, light });
        self.medium_interfaces.push(interface);
        Ok(())
    }

    /// The emitter nested in the shape with index `shape_index`: the index of its area light,
    /// or None for a `directionalarea` or a delta emitter (`point`, `spot`, `projector`, `directional`). Mitsuba 3
    /// lets a shape hold one of those: its radiance on the shape's surface is zero and it lights
    /// the scene from its own `to_world`, as if declared at the top level, while the shape
    /// takes the black default BSDF of emitting shapes; Prism does the same.
    fn attach_emitter(
        &mut self,
        shape: &Primitive,
        shape_index: u32,
        emitter: &NestedPlugin,
    ) -> Result<Option<u32>> {
        self.attach_once(emitter)?;
        if lights::is_delta(&emitter.node) {
            let (light, weight) = lights::build_scene_light(&emitter.node, &mut self.textures)?;
            self.lights.push(light);
            self.emitter_plugins.push(emitter.node.clone());
            self.light_locations.push(emitter.location.clone());
            self.sampling_weights.push(weight);
            return Ok(None);
        }
        if let Primitive::Instance(instance) = shape
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
        let (light, weight) =
            lights::build_area_light(&emitter.node, shape_index, &mut self.textures)?;
        // A `directionalarea` emits along the normal alone, a direction no ray finds, so its
        // shape's surface shows no emission.
        let seen_on_surface = matches!(light, Light::Area(_));
        self.lights.push(light);
        self.emitter_plugins.push(emitter.node.clone());
        self.light_locations.push(emitter.location.clone());
        self.sampling_weights.push(weight);
        Ok(seen_on_surface.then_some((self.lights.len() - 1) as u32))
    }

    /// Records that `emitter` is attached to a shape; an error if it already is to another.
    fn attach_once(&mut self, emitter: &NestedPlugin) -> Result<()> {
        if let Some(first) = self
            .attached_emitters
            .insert(Arc::as_ptr(&emitter.node), emitter.location.clone())
        {
            return Err(Error::input(
                &emitter.location,
                format!(
                    "{} is already attached to the shape at {first}",
                    emitter.node.describe()
                ),
            )
            .with_help(
                "an emitter can be attached to a single shape (as in Mitsuba): \
                 give each shape its own <emitter>",
            ));
        }
        Ok(())
    }

    /// The `<emitter>` section: the lights other than area lights, and the area emitters
    /// declared to be referenced by a shape.
    fn emitters(&mut self, params: &Params) -> Result<()> {
        let mut scene_lights = Vec::new();
        for child in params.children(&EMITTERS) {
            if lights::is_area(&child.node) {
                // An area emitter declared at the top level belongs to the shape that
                // references it; one that no shape references emits nothing (Mitsuba ignores
                // it), but its parameters are still checked.
                if !self
                    .attached_emitters
                    .contains_key(&Arc::as_ptr(&child.node))
                {
                    lights::build_area_light(&child.node, 0, &mut self.textures)?;
                }
                continue;
            }
            let (light, weight) = lights::build_scene_light(&child.node, &mut self.textures)?;
            scene_lights.push((light, weight, child.location.clone()));
            self.emitter_plugins.push(child.node.clone());
        }
        lights::check_single_environment(&scene_lights)?;
        for (light, weight, location) in scene_lights {
            self.lights.push(light);
            self.light_locations.push(location);
            self.sampling_weights.push(weight);
        }
        Ok(())
    }

    /// BSDFs declared at the top level (to be referenced by id) are built even when unused, so
    /// that their errors are reported as Mitsuba would.
    fn declared_bsdfs(&mut self, params: &Params) -> Result<()> {
        for child in params.children(&BSDFS) {
            self.materials.declared(&child.node, &mut self.textures)?;
        }
        Ok(())
    }

    /// Textures declared at the top level (referenced by id from BSDFs) are read even when no
    /// BSDF uses them, so that a missing or corrupt image is reported.
    fn declared_textures(&mut self, params: &Params) -> Result<()> {
        for child in params.children(&TEXTURES) {
            if !self.textures.contains(&child.node) {
                textures::build_texture(&child.node, TextureUse::Scalar, &mut self.textures)?;
            }
        }
        Ok(())
    }

    /// Media declared at the top level are built even when unused, so that their errors are
    /// reported.
    fn declared_media(&mut self, params: &Params) -> Result<()> {
        for child in params.children(&MEDIA) {
            self.media.index(child)?;
        }
        Ok(())
    }

    /// The scene, from the parts read, seen through the first sensor; `geometry`, when given,
    /// is the hierarchy kept from a scene built before (see [`KeptGeometry`]).
    fn finish(
        self,
        root: &PluginNode,
        integrator: Integrator,
        mut sensors: Vec<SceneSensor>,
        warnings: Vec<Warning>,
        geometry: Option<KeptGeometry>,
    ) -> LoadedScene {
        let geometry = match geometry {
            None => Geometry::new(self.shapes),
            Some(KeptGeometry::Unchanged(geometry)) => geometry,
            Some(KeptGeometry::Moved(geometry)) => geometry.refit(self.shapes),
        };
        let mut world = World::new(
            geometry,
            self.shape_info,
            self.materials.materials,
            self.lights,
        )
        .with_sampling_weights(self.sampling_weights);
        if self.medium_interfaces.iter().any(|m| m.is_transition()) {
            world.medium_interfaces = self.medium_interfaces;
        }
        world.media = self.media.media;
        let bounds = BoundingSphere::around_box(world.geometry.bounds());
        for sensor in &mut sensors {
            sensor.camera.set_scene_bounds(bounds);
        }
        let first = sensors[0].clone();
        world.camera_medium = first.medium;
        let polarizing = world.materials.iter().any(|m| m.is_polarizing());
        let mut integrator = integrators::polarized_where_needed(integrator, polarizing);
        integrators::aim_stokes(&mut integrator, &first.camera);
        let mut scene = Scene::new(world, first.camera, first.film, first.sampler, integrator);
        scene.shutter = first.shutter;
        scene.exr_output = first.exr_output;
        scene.ldr_output = first.ldr_output;
        let description_fingerprint = crate::fingerprint::scene_fingerprint(root);
        scene.fingerprint = description_fingerprint;
        LoadedScene {
            scene,
            seed: first.seed,
            warnings,
            shape_plugins: self.shape_plugins,
            emitter_plugins: self.emitter_plugins,
            sensors,
            selected: 0,
            description_fingerprint,
        }
    }
}

/// The scene's materials, each BSDF built once however often it is referenced.
#[derive(Default)]
struct MaterialCache {
    materials: Vec<Material>,
    ids: HashMap<*const PluginNode, u32>,
}

impl MaterialCache {
    /// The index of a shape's material: its BSDF, or the default (black for an emitter, as
    /// Mitsuba's, else diffuse 0.5).
    fn shape_material(
        &mut self,
        bsdf: Option<&NestedPlugin>,
        emits: bool,
        textures: &mut TextureCache,
    ) -> Result<u32> {
        if let Some(bsdf) = bsdf {
            let key = Arc::as_ptr(&bsdf.node);
            if let Some(&index) = self.ids.get(&key) {
                return Ok(index);
            }
            textures.take_used_slots();
            self.materials
                .push(materials::build_material(&bsdf.node, textures)?);
            let index = (self.materials.len() - 1) as u32;
            self.ids.insert(key, index);
            let attributes = textures.take_used_slots();
            textures.set_material_attributes(index, attributes);
            return Ok(index);
        }
        self.materials.push(if emits {
            lights::default_emitter_material()
        } else {
            materials::default_material()
        });
        Ok((self.materials.len() - 1) as u32)
    }

    /// Builds a BSDF declared at the top level, unless a shape has built it already.
    fn declared(&mut self, node: &Arc<PluginNode>, textures: &mut TextureCache) -> Result<()> {
        if let Entry::Vacant(entry) = self.ids.entry(Arc::as_ptr(node)) {
            self.materials
                .push(materials::build_material(node, textures)?);
            entry.insert((self.materials.len() - 1) as u32);
        }
        Ok(())
    }

    /// The material and media of a shape in a `shapegroup`.
    fn group_member(
        &mut self,
        member: &Params,
        textures: &mut TextureCache,
        media: &mut MediaCache,
    ) -> Result<(u32, MediumInterface)> {
        let material = self.shape_material(member.single_child(&shapes::BSDF)?, false, textures)?;
        if let Some((_, name)) = textures.material_attributes(material).first() {
            let node = member.node();
            return Err(Error::input(
                &node.location,
                format!(
                    "{} in a shapegroup has a BSDF that reads the mesh attribute \"{name}\"; \
                     Prism's instanced shapes carry no attributes",
                    node.describe()
                ),
            )
            .with_help("place the mesh directly in the scene instead of through an instance"));
        }
        Ok((material, shape_media(member, media)?))
    }
}

/// The scene's media, each built once however often it is referenced.
#[derive(Default)]
struct MediaCache {
    media: Vec<Medium>,
    ids: HashMap<*const PluginNode, u32>,
    /// Where the first medium is given, for the integrators that refuse media.
    first: Option<SourceLocation>,
}

impl MediaCache {
    /// The index of the medium `child` describes (a `<medium>` or a reference to one).
    fn index(&mut self, child: &NestedPlugin) -> Result<u32> {
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

/// The media on the two sides of a shape (its `interior` and `exterior`).
fn shape_media(shape_params: &Params, media: &mut MediaCache) -> Result<MediumInterface> {
    let mut interface = MediumInterface::default();
    if let Some(child) = shape_params.named_child(&shapes::INTERIOR) {
        interface.interior = Some(media.index(child)?);
    }
    if let Some(child) = shape_params.named_child(&shapes::EXTERIOR) {
        interface.exterior = Some(media.index(child)?);
    }
    Ok(interface)
}

/// Makes the shape's mesh fill the attribute slots its BSDF (`material`)'s `mesh_attribute`
/// textures read; a shape without one of those attributes, or with a colour attribute that a
/// texture reads as a number, is an error (Mitsuba's "invalid attribute requested" and
/// "requested but had size 3", which it reports while rendering).
fn bind_mesh_attributes(
    shape: &mut Primitive,
    material: u32,
    textures: &TextureCache,
    node: &PluginNode,
) -> Result<()> {
    let attributes = textures.material_attributes(material);
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
        let channels = mesh.attribute(name).map(|a| a.channels);
        if channels == Some(3) && textures.reads_as_number(name) {
            return Err(Error::input(
                &node.location,
                format!(
                    "{}'s attribute \"{name}\" is a colour of three channels, which its BSDF \
                     reads as a number (Mitsuba: attribute requested but had size 3)",
                    node.describe()
                ),
            )
            .with_help("read it as a colour, or give the mesh a one-channel attribute"));
        }
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
