//! Cameras: turning a point on the film into a ray.

pub mod perspective;

pub use perspective::PerspectiveCamera;

use glam::Vec2;

use crate::math::Ray;

/// The scene's camera.
#[derive(Clone, Debug)]
pub enum Camera {
    Perspective(PerspectiveCamera),
}

impl Camera {
    /// The ray through the film position `film` (in pixels of the full film, origin top-left).
    #[inline]
    pub fn generate_ray(&self, film: Vec2) -> Ray {
        match self {
            Camera::Perspective(camera) => camera.generate_ray(film),
        }
    }
}
