//! The sensors of a scene with several `<sensor>`s: Mitsuba builds them all and renders the
//! first, unless `mi.render(scene, sensor=...)` names another by its index or (Prism's
//! `--sensor`) its id. A [`LoadedScene`] keeps every sensor and is seen through one at a time.

use super::scene::LoadedScene;
use prism_core::camera::{Camera, Shutter};
use prism_core::error::{Error, Result};
use prism_core::film::{ExrOutput, LdrOutput};
use prism_core::scene::{FilmSettings, SamplerSettings};

/// One `<sensor>`: what a render through it takes from it.
#[derive(Clone)]
pub struct SceneSensor {
    /// The sensor's `id`, if it has one.
    pub id: Option<String>,
    pub(super) camera: Camera,
    pub(super) shutter: Shutter,
    pub(super) film: FilmSettings,
    pub(super) sampler: SamplerSettings,
    pub(super) seed: u64,
    pub(super) exr_output: ExrOutput,
    pub(super) ldr_output: LdrOutput,
    /// The index of the medium the camera sits in.
    pub(super) medium: Option<u32>,
}

impl SceneSensor {
    /// The sensor's film: its size, crop window and reconstruction.
    pub fn film(&self) -> &FilmSettings {
        &self.film
    }
}

impl LoadedScene {
    /// The scene's sensors, in document order.
    pub fn sensors(&self) -> &[SceneSensor] {
        &self.sensors
    }

    /// The index of the sensor the scene is seen through.
    pub fn selected_sensor(&self) -> usize {
        self.selected
    }

    /// The index of the sensor `choice` names: the one whose `id` it is, else the index it
    /// writes, counted from 0 in document order (`prism render --sensor`).
    pub fn find_sensor(&self, choice: &str) -> Result<usize> {
        if let Some(index) = self
            .sensors
            .iter()
            .position(|sensor| sensor.id.as_deref() == Some(choice))
        {
            return Ok(index);
        }
        if let Ok(index) = choice.trim().parse::<usize>() {
            self.check_sensor_index(index)?;
            return Ok(index);
        }
        let ids: Vec<String> = (self.sensors.iter())
            .filter_map(|sensor| sensor.id.as_ref().map(|id| format!("\"{id}\"")))
            .collect();
        let ids = if ids.is_empty() {
            "no sensor has an id".to_string()
        } else {
            format!("the ids are {}", ids.join(", "))
        };
        Err(
            Error::usage(format!("the scene has no sensor \"{choice}\"")).with_help(format!(
                "give a sensor's id or its index from 0 to {} ({ids})",
                self.sensors.len() - 1
            )),
        )
    }

    fn check_sensor_index(&self, index: usize) -> Result<()> {
        let count = self.sensors.len();
        if index < count {
            return Ok(());
        }
        Err(
            Error::usage(format!("the scene has no sensor {index}")).with_help(format!(
                "its {count} sensor{} are numbered from 0 to {} in document order",
                if count == 1 { "" } else { "s" },
                count - 1
            )),
        )
    }

    /// Sees the scene through sensor `index` from now on: its camera, shutter, film, sampler,
    /// outputs, medium and seed. A wavelength density or a reconstruction set in place of
    /// the film's (see [`crate::fingerprint`]) carries over to the new film. The index joins the
    /// fingerprint (but for the first sensor), so that a render state records it.
    pub fn select_sensor(&mut self, index: usize) -> Result<()> {
        self.check_sensor_index(index)?;
        if index == self.selected {
            return Ok(());
        }
        let previous = &self.sensors[self.selected].film;
        let film = &self.scene.film;
        let wavelengths = (film.wavelength_sampling != previous.wavelength_sampling)
            .then_some(film.wavelength_sampling);
        let reconstruction =
            (film.reconstruction != previous.reconstruction).then_some(film.reconstruction);
        let sensor = self.sensors[index].clone();
        super::integrators::aim_stokes(&mut self.scene.integrator, &sensor.camera);
        self.scene.camera = sensor.camera;
        self.scene.shutter = sensor.shutter;
        self.scene.film = sensor.film;
        self.scene.sampler = sensor.sampler;
        self.scene.exr_output = sensor.exr_output;
        self.scene.ldr_output = sensor.ldr_output;
        self.scene.world.camera_medium = sensor.medium;
        self.seed = sensor.seed;
        self.selected = index;
        self.scene.fingerprint =
            crate::fingerprint::with_sensor(self.description_fingerprint, index);
        if let Some(density) = wavelengths {
            crate::fingerprint::override_wavelengths(&mut self.scene, density);
        }
        if let Some(reconstruction) = reconstruction {
            crate::fingerprint::override_reconstruction(&mut self.scene, reconstruction);
        }
        Ok(())
    }
}
