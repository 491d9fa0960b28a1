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

use glam::{Vec2, Vec3};

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

        /// The camera seen from the point `p` at `time`, for connecting a light subpath to it
        /// (Mitsuba's `Sensor::sample_direction`): a point of its lens, drawn with `u` where it
        /// has an aperture, the film position the light from `p` lands on, and the camera's
        /// importance there ([`ImportanceSample`]). The film position may lie off the film:
        /// camera samples of the pixels at its edges reach that far through the reconstruction
        /// filter, so the caller decides which positions reach a pixel. None where `p` is behind
        /// the camera or outside its clip range, or no connection can reach the camera.
        fn sample_importance(&self, p: Vec3, u: Vec2, time: f32) -> Option<ImportanceSample>;
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

/// A connection from a scene point to the camera ([`CameraModel::sample_importance`]).
///
/// With the film's image I_j = ∫ k_j(u) L(u) du over film positions u in pixels (k_j the
/// reconstruction filter around pixel j, ∫ k = 1), a light subpath whose vertex at `p` sends
/// the radiance-weighted value V = β · f · |cos θ_p| towards the camera (β the subpath's
/// throughput, f·|cos θ_p| its scattering there towards `wi`) adds V · `weight` · k_j(film − c_j)
/// to I_j when the image is the sum over W·H light subpaths, W × H the full film's size: the
/// importance is normalised to the whole film, as Mitsuba's is.
#[derive(Clone, Copy, Debug)]
pub struct ImportanceSample {
    /// The position on the full film, in pixels (origin top-left).
    pub film: Vec2,
    /// The point of the lens (or of the orthographic camera's near plane) the light reaches.
    pub p: Vec3,
    /// The unit direction from the scene point towards `p`.
    pub wi: Vec3,
    /// The importance W_e with the camera's end of the geometry term, over the density of the
    /// lens point: 1/(A cos³θ r²) for a perspective camera (A the area of the film on the plane
    /// at distance 1, θ the angle from the optical axis, r the distance), 1/A for an
    /// orthographic one (A the film's area in the scene).
    pub weight: f32,
}

/// The full-film position (pixels, origin top-left) of the screen position `screen` (see
/// [`screen_position`], whose inverse it is); None where it is not finite.
#[inline]
pub(crate) fn film_position(screen: Vec2, film_size: Vec2) -> Option<Vec2> {
    let film = (Vec2::ONE - screen) * 0.5 * film_size;
    film.is_finite().then_some(film)
}
