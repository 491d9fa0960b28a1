//! Mitsuba 3's `batch` sensor: several sensors rendered side by side into one film, each into
//! its own column block of width W/n (n sensors, W the film's width).
//!
//! ```xml
//! <sensor type="batch">
//!     <sensor type="perspective"> ... </sensor>
//!     <sensor type="perspective"> ... </sensor>
//!     <film type="hdrfilm"><integer name="width" value="512"/> ... </film>
//! </sensor>
//! ```
//!
//! As Mitsuba 3's `batch.cpp`, a film position x picks sensor i = ⌊x / w⌋ (w = W/n, clamped to
//! the sensors there are) and becomes x − i·w on that sensor's film of w × H pixels; the batch's
//! film, sampler and shutter replace those of the sensors it holds.

use glam::{Vec2, Vec3};

use super::{Camera, CameraModel, CameraRay, ImportanceSample};
use crate::light::BoundingSphere;

#[derive(Clone, Debug)]
pub struct BatchSensor {
    /// The sensors, left to right, each seeing a film of `sub_width` × H pixels.
    pub sensors: Vec<Camera>,
    /// The width of each sensor's block of the film, in pixels.
    pub sub_width: f32,
}

impl CameraModel for BatchSensor {
    #[inline]
    fn generate_ray(&self, film: Vec2, lens: Vec2, time: f32) -> CameraRay {
        let last = self.sensors.len() - 1;
        let index = ((film.x / self.sub_width).floor().max(0.0) as usize).min(last);
        let on_sensor = Vec2::new(film.x - index as f32 * self.sub_width, film.y);
        self.sensors[index].generate_ray(on_sensor, lens, time)
    }

    fn set_scene_bounds(&mut self, bounds: BoundingSphere) {
        for sensor in &mut self.sensors {
            sensor.set_scene_bounds(bounds);
        }
    }

    /// None: a point may be seen by several of the sensors; the particle tracer refuses a batch.
    fn sample_importance(&self, _p: Vec3, _u: Vec2, _time: f32) -> Option<ImportanceSample> {
        None
    }
}
