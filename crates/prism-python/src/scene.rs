//! Loading scenes: from a Mitsuba XML file with `-D`-style defines, or from Mitsuba's
//! dictionary form; both build through prism-mitsuba's factory, with its checks and messages.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::dict::dict_of;
use crate::error::{IntoPyResult, to_py};
use prism_core::error::Error;
use prism_core::film::Reconstruction;
use prism_core::spectrum::WavelengthSampling;
use prism_mitsuba::fingerprint::{override_reconstruction, override_wavelengths};
use prism_mitsuba::{LoadedScene, load_scene, load_scene_dict, load_scene_str};

/// A scene ready to render. Its settings that `prism render` can override from the command
/// line are properties that may be set (not while the scene renders).
#[pyclass(module = "prism_renderer")]
pub struct Scene {
    pub loaded: LoadedScene,
}

#[pymethods]
impl Scene {
    /// The film's width in pixels.
    #[getter]
    fn width(&self) -> u32 {
        self.loaded.scene.film.size.x
    }

    /// The film's height in pixels.
    #[getter]
    fn height(&self) -> u32 {
        self.loaded.scene.film.size.y
    }

    /// The sampler's samples per pixel (`sample_count`).
    #[getter]
    fn spp(&self) -> u32 {
        self.loaded.scene.sampler.samples_per_pixel
    }

    /// The sampler's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.loaded.seed
    }

    /// The density the wavelengths are drawn from (the film's `wavelength_sampling`); setting
    /// it is `prism render --wavelengths`.
    #[getter]
    fn wavelengths(&self) -> &'static str {
        self.loaded.scene.film.wavelength_sampling.name()
    }

    #[setter]
    fn set_wavelengths(&mut self, py: Python<'_>, name: &str) -> PyResult<()> {
        let density = named(
            py,
            "wavelength density",
            name,
            WavelengthSampling::from_name,
            &WavelengthSampling::NAMES,
        )?;
        override_wavelengths(&mut self.loaded.scene, density);
        Ok(())
    }

    /// How samples become pixel values (the film's `reconstruction`): `filter_mis` or `pixel`;
    /// setting it is `prism render --reconstruction`.
    #[getter]
    fn reconstruction(&self) -> &'static str {
        self.loaded.scene.film.reconstruction.name()
    }

    #[setter]
    fn set_reconstruction(&mut self, py: Python<'_>, name: &str) -> PyResult<()> {
        let reconstruction = named(
            py,
            "reconstruction",
            name,
            Reconstruction::from_name,
            &Reconstruction::NAMES,
        )?;
        override_reconstruction(&mut self.loaded.scene, reconstruction);
        Ok(())
    }

    /// The index of the sensor the scene is seen through: 0 after loading, then the one the
    /// last render used; `width`, `height`, `spp` and `seed` are its.
    #[getter]
    fn sensor(&self) -> usize {
        self.loaded.selected_sensor()
    }

    /// The `id` of every sensor (None for one without), in document order.
    #[getter]
    fn sensor_ids(&self) -> Vec<Option<String>> {
        (self.loaded.sensors().iter())
            .map(|sensor| sensor.id.clone())
            .collect()
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({}×{} pixels, {} spp)",
            self.width(),
            self.height(),
            self.spp()
        )
    }
}

/// Loads the Mitsuba XML scene at `path`, with `defines` as `(name, value)` pairs for its
/// `$name` parameters (the command line's `-D name=value`).
#[pyfunction]
#[pyo3(signature = (path, defines = Vec::new()))]
pub fn load_file(py: Python<'_>, path: PathBuf, defines: Vec<(String, String)>) -> PyResult<Scene> {
    let loaded = py
        .detach(|| load_scene(&path, &defines))
        .into_py_result(py)?;
    Ok(Scene { loaded })
}

/// Loads a Mitsuba XML scene given as the string `text`, with `defines` as in [`load_file`];
/// relative file names are found from the current folder.
#[pyfunction]
#[pyo3(signature = (text, defines = Vec::new()))]
pub fn load_string(
    py: Python<'_>,
    text: String,
    defines: Vec<(String, String)>,
) -> PyResult<Scene> {
    let loaded = py
        .detach(|| load_scene_str(&text, &defines))
        .into_py_result(py)?;
    Ok(Scene { loaded })
}

/// Loads a scene given in Mitsuba's dictionary form.
#[pyfunction]
pub fn load_dict(py: Python<'_>, scene: &Bound<'_, PyDict>) -> PyResult<Scene> {
    let root = dict_of(scene, "scene")?;
    let loaded = py.detach(|| load_scene_dict(&root)).into_py_result(py)?;
    Ok(Scene { loaded })
}

/// The setting called `name`, read by `from_name`; else a usage error that names the `what` and
/// lists the `names` there are.
fn named<T>(
    py: Python<'_>,
    what: &str,
    name: &str,
    from_name: fn(&str) -> Option<T>,
    names: &[&str],
) -> PyResult<T> {
    from_name(name).ok_or_else(|| {
        to_py(
            py,
            &Error::usage(format!("no {what} is called \"{name}\""))
                .with_help(format!("choose one of {}", names.join(", "))),
        )
    })
}
