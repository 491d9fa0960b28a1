//! Cameras: turning a point on the film (and on the lens, at a time) into a ray; the radiance
//! meter, a sensor of one ray.

pub mod orthographic;
pub mod perspective;
pub mod radiancemeter;
pub mod shutter;

pub use orthographic::OrthographicCamera;
pub use perspective::PerspectiveCamera;
pub use radiancemeter::RadianceMeter;
pub use shutter::Shutter;

use glam::Vec2;

use crate::dispatch::plugin_class;
use crate::math::Ray;

plugin_class! {
    /// What every camera answers: the ray through a point of its film.
    pub trait CameraModel {
        /// The ray through the film position `film` (in pixels of the full film, origin
        /// top-left), the lens position `lens` ∈ [0, 1)² (unused without a lens), at time
        /// `time`.
        fn generate_ray(&self, film: Vec2, lens: Vec2, time: f32) -> Ray;
    }

    /// The scene's camera.
    #[derive(Clone, Debug)]
    pub enum Camera {
        Perspective(PerspectiveCamera),
        Orthographic(OrthographicCamera),
        RadianceMeter(RadianceMeter),
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
