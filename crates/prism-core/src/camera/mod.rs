//! Cameras and the other sensors: turning a point on the film (and on the lens, at a time) into
//! a ray and its weight. The projective cameras see through their film; the radiance meter
//! measures along one ray, the irradiance meter over a shape, the distant sensor the radiance
//! leaving a target in one direction; the batch sensor puts several side by side.

pub mod batch;
pub mod distant;
pub mod irradiancemeter;
pub mod orthographic;
pub mod perspective;
pub mod radiancemeter;
pub mod shutter;

pub use batch::BatchSensor;
pub use distant::{DistantSensor, DistantTarget};
pub use irradiancemeter::IrradianceMeter;
pub use orthographic::OrthographicCamera;
pub use perspective::PerspectiveCamera;
pub use radiancemeter::RadianceMeter;
pub use shutter::Shutter;

use glam::Vec2;

use crate::dispatch::plugin_class;
use crate::light::BoundingSphere;
use crate::math::Ray;

/// A sensor's ray and its weight: the factor by which the radiance arriving along the ray is
/// multiplied to give the sensor's measurement (1 for cameras; π for the irradiance meter,
/// whose cosine-weighted directions estimate ∫ L cos θ dω).
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub ray: Ray,
    pub weight: f32,
}

impl CameraRay {
    /// A ray of weight one.
    #[inline]
    pub fn unweighted(ray: Ray) -> CameraRay {
        CameraRay { ray, weight: 1.0 }
    }
}

plugin_class! {
    /// What every sensor answers: the ray through a point of its film.
    pub trait CameraModel {
        /// The ray through the film position `film` (in pixels of the full film, origin
        /// top-left), the lens position `lens` ∈ [0, 1)² (a sensor without a lens may use it
        /// for another sampling dimension), at time `time`, with its weight.
        fn generate_ray(&self, film: Vec2, lens: Vec2, time: f32) -> CameraRay;

        /// Tells the sensor the bounding sphere of the scene's geometry, once the scene is
        /// built (Mitsuba's `Sensor::set_scene`); only the distant sensor uses it.
        fn set_scene_bounds(&mut self, bounds: BoundingSphere);
    }

    /// The scene's sensor.
    #[derive(Clone, Debug)]
    pub enum Camera {
        Perspective(PerspectiveCamera),
        Orthographic(OrthographicCamera),
        RadianceMeter(RadianceMeter),
        IrradianceMeter(IrradianceMeter),
        Distant(DistantSensor),
        Batch(BatchSensor),
    }
}

/// The film position `film` (pixels of the full film of `film_size`, origin top-left) on the
/// screen: (1 − 2x/W, 1 − 2y/H), from 1 at the left and top edges to −1 at the right and bottom
/// (Mitsuba's cameras look along +z with +x to the left), and the film's aspect ratio W/H.
#[inline]
pub(crate) fn screen_position(film: Vec2, film_size: Vec2) -> (Vec2, f32) {
    let ndc = film / film_size;
    let aspect = film_size.x / film_size.y;
    (Vec2::new(1.0 - 2.0 * ndc.x, 1.0 - 2.0 * ndc.y), aspect)
}
