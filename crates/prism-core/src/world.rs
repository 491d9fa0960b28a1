//! The world an integrator renders: the geometry, what each shape is made of, and the lights.
//! It knows nothing of cameras, films or integrators; [`crate::scene::Scene`] adds those.

use crate::bsdf::Material;
use crate::geometry::{Geometry, SurfaceInteraction};
use crate::light::{BoundingSphere, Light, LightBounds, LightSource};
use crate::medium::{Medium, MediumInterface};

/// What a shape is made of and whether it emits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapeInfo {
    /// Index into [`World::materials`].
    pub material: u32,
    /// Index into [`World::lights`] of the area light on this shape.
    pub light: Option<u32>,
}

/// The geometry, materials and lights of a scene.
pub struct World {
    pub geometry: Geometry,
    /// One entry per primitive of `geometry`.
    pub shape_info: Vec<ShapeInfo>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// Each light's power (see [`Light::power`]), from which integrators build their light
    /// samplers.
    pub light_powers: Vec<f32>,
    /// Each light's place (see [`Light::bounds`]), for choosing lights by importance.
    pub light_bounds: Vec<Option<LightBounds>>,
    /// Each light's `sampling_weight` (1 unless the scene says otherwise), which scales its
    /// probability of being chosen (see [`crate::light::sampler`]).
    pub light_sampling_weights: Vec<f32>,
    /// Index into `lights` of the environment (`constant` or `envmap`), which rays that leave
    /// the scene see; a scene has at most one.
    pub environment: Option<u32>,
    /// The participating media; shapes and the camera refer to them by index.
    pub media: Vec<Medium>,
    /// One entry per primitive of `geometry` when some shape bounds a medium, else empty.
    pub medium_interfaces: Vec<MediumInterface>,
    /// The medium the camera sits in.
    pub camera_medium: Option<u32>,
}

impl World {
    /// A world from its parts. Lights at infinity learn the geometry's bounding sphere (before
    /// their powers are taken, which depend on it); the first environment light (the factory
    /// allows only one) is the one escaped rays see.
    pub fn new(
        geometry: Geometry,
        shape_info: Vec<ShapeInfo>,
        materials: Vec<Material>,
        mut lights: Vec<Light>,
    ) -> World {
        let bounds = BoundingSphere::around_box(geometry.bounds());
        for light in &mut lights {
            light.set_scene_bounds(bounds);
        }
        let light_powers = lights
            .iter()
            .map(|l| l.power(&geometry.primitives))
            .collect();
        let light_bounds = lights
            .iter()
            .map(|l| l.bounds(&geometry.primitives))
            .collect();
        let light_sampling_weights = vec![1.0; lights.len()];
        World {
            environment: lights
                .iter()
                .position(Light::is_environment)
                .map(|i| i as u32),
            geometry,
            shape_info,
            materials,
            lights,
            light_powers,
            light_bounds,
            media: Vec::new(),
            medium_interfaces: Vec::new(),
            camera_medium: None,
            light_sampling_weights,
        }
    }

    /// What the surface hit `si` is made of.
    #[inline]
    pub fn material(&self, si: &SurfaceInteraction) -> &Material {
        &self.materials[self.shape_info[si.shape as usize].material as usize]
    }

    /// The media on the two sides of primitive `shape`.
    #[inline]
    pub fn medium_interface(&self, shape: u32) -> MediumInterface {
        self.medium_interfaces
            .get(shape as usize)
            .copied()
            .unwrap_or_default()
    }

    /// The world with the lights' sampling weights (one per light, each finite and at
    /// least 0) in place of the default 1.
    pub fn with_sampling_weights(mut self, weights: Vec<f32>) -> World {
        assert_eq!(
            weights.len(),
            self.lights.len(),
            "one sampling weight per light"
        );
        assert!(
            weights.iter().all(|w| w.is_finite() && *w >= 0.0),
            "sampling weights are finite and at least 0"
        );
        self.light_sampling_weights = weights;
        self
    }
}
