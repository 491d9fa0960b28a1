//! Scenes: the renderable [`Scene`], the mesh readers, and the Mitsuba XML reader and plugin
//! factory that build it.

pub mod fingerprint;
pub mod mesh;
pub mod mitsuba;

use glam::UVec2;

use crate::bsdf::Material;
use crate::camera::{Camera, Shutter};
use crate::film::{CropWindow, Filter};
use crate::geometry::Geometry;
use crate::integrator::Integrator;
use crate::integrator::distribution::DirectLights;
use crate::light::{BoundingSphere, Light, LightSampler, LightSelection};
pub use crate::sampling::sampler::SamplerKind;
use crate::spectrum::WavelengthSampling;

/// What a shape is made of and whether it emits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeInfo {
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Index into [`Scene::lights`] of the area light on this shape.
    pub light: Option<u32>,
}

/// Film settings: size, crop window and reconstruction filter.
#[derive(Clone, Debug)]
pub struct FilmSettings {
    pub size: UVec2,
    pub crop: CropWindow,
    pub filter: Filter,
}

/// Which per-pixel sampler to use and how many samples per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SamplerSettings {
    pub kind: SamplerKind,
    pub samples_per_pixel: u32,
}

/// Everything needed to render an image.
pub struct Scene {
    pub geometry: Geometry,
    /// One entry per shape of `geometry`.
    pub shape_info: Vec<ShapeInfo>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub light_sampler: LightSampler,
    /// Index into `lights` of the environment (`constant` or `envmap`), which rays that leave
    /// the scene see; a scene has at most one.
    pub environment: Option<u32>,
    pub camera: Camera,
    pub film: FilmSettings,
    pub sampler: SamplerSettings,
    pub integrator: Integrator,
    pub wavelength_sampling: WavelengthSampling,
    /// When camera rays are taken (the sensor's shutter interval and temporal filter).
    pub shutter: Shutter,
    /// Hash of the scene's description and files (see [`fingerprint`]); 0 for scenes built in
    /// code.
    pub fingerprint: u64,
}

impl Scene {
    /// A scene from its parts. Lights at infinity learn the scene's bounding sphere; the light
    /// sampler is built from the lights' powers as the integrator's light selection asks; the
    /// first environment light (the factory allows only one) is the one escaped rays see.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        geometry: Geometry,
        shape_info: Vec<ShapeInfo>,
        materials: Vec<Material>,
        mut lights: Vec<Light>,
        camera: Camera,
        film: FilmSettings,
        sampler: SamplerSettings,
        integrator: Integrator,
    ) -> Scene {
        let bounds = BoundingSphere::around_box(geometry.bounds());
        for light in &mut lights {
            light.set_scene_bounds(bounds);
        }
        let powers: Vec<f32> = lights
            .iter()
            .map(|l| l.power(&geometry.primitives))
            .collect();
        let selection = match &integrator {
            Integrator::Path(path) => path.light_selection,
            Integrator::Distribution(distrib) => match distrib.lights {
                DirectLights::One(selection) => selection,
                DirectLights::All => LightSelection::Power,
            },
        };
        Scene {
            light_sampler: LightSampler::with_selection(&powers, selection),
            environment: lights
                .iter()
                .position(Light::is_environment)
                .map(|i| i as u32),
            geometry,
            shape_info,
            materials,
            lights,
            camera,
            film,
            sampler,
            integrator,
            wavelength_sampling: WavelengthSampling::default(),
            shutter: Shutter::instant(),
            fingerprint: 0,
        }
    }
}
