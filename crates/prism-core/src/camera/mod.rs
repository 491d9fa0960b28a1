//! Cameras: turning a point on the film (and on the lens, at a time) into a ray.

pub mod orthographic;
pub mod perspective;
pub mod shutter;

pub use orthographic::OrthographicCamera;
pub use perspective::PerspectiveCamera;
pub use shutter::Shutter;

use glam::Vec2;

use crate::math::Ray;

/// The scene's camera.
#[derive(Clone, Debug)]
pub enum Camera {
    Perspective(PerspectiveCamera),
    Orthographic(OrthographicCamera),
}

impl Camera {
    /// The ray through the film position `film` (in pixels of the full film, origin top-left),
    /// the lens position `lens` ∈ [0, 1)² (unused without a lens), at time `time`.
    #[inline]
    pub fn generate_ray(&self, film: Vec2, lens: Vec2, time: f32) -> Ray {
        match self {
            Camera::Perspective(camera) => camera.generate_ray(film, lens, time),
            Camera::Orthographic(camera) => camera.generate_ray(film, time),
        }
    }
}
