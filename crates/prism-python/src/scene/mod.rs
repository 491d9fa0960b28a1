//! Loading scenes: from a Mitsuba XML file with `-D`-style defines, or from Mitsuba's
//! dictionary form; both build through prism-mitsuba's factory, with its checks and messages.
//! A scene keeps its description and the files it read, to be built again when its
//! parameters change ([`crate::parameters`]).

pub mod introspection;
pub mod ray_queries;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::dict::dict_of;
use crate::error::{IntoPyResult, to_py};
use introspection::{BoundingBox3f, Emitter, Sensor, Shape};
use prism_core::error::{Error, Result};
use prism_core::film::Reconstruction;
use prism_core::geometry::Geometry;
use prism_core::spectrum::WavelengthSampling;
use prism_mitsuba::description::{PluginNode, Warning};
use prism_mitsuba::factory::{KeptGeometry, build_scene_with_geometry};
use prism_mitsuba::file_cache::FileCache;
use prism_mitsuba::fingerprint::{override_reconstruction, override_wavelengths};
use prism_mitsuba::read_scene;
use prism_mitsuba::reader::{SceneDocument, read_scene_str_document};
use prism_mitsuba::{LoadedScene, dict};
use ray_queries::{Rays, SurfaceInteraction};

/// A scene ready to render. Its settings that `prism render` can override from the command
/// line are properties that may be set (not while the scene renders).
#[pyclass(module = "prism_renderer")]
pub struct Scene {
    pub loaded: LoadedScene,
    /// The description the scene was built from.
    description: Arc<PluginNode>,
    /// The reader's warnings about the description, which lead `loaded`'s.
    reader_warnings: Vec<Warning>,
    /// The files the build read, for building the scene again.
    files: FileCache,
    /// The wavelength density and the reconstruction set in place of the film's.
    wavelengths: Option<WavelengthSampling>,
    reconstruction: Option<Reconstruction>,
}

impl Scene {
    /// Builds the scene a reader described.
    fn build(py: Python<'_>, document: SceneDocument) -> PyResult<Scene> {
        let files = FileCache::default();
        let description = document.root;
        let loaded = py
            .detach(|| files.scope(|| build(&description, &mut None, &document.warnings)))
            .into_py_result(py)?;
        Ok(Scene {
            loaded,
            description,
            reader_warnings: document.warnings,
            files,
            wavelengths: None,
            reconstruction: None,
        })
    }

    /// The description the scene was built from.
    pub fn description(&self) -> &Arc<PluginNode> {
        &self.description
    }

    /// Builds the scene again from `description`, an edit of its own with the same plugins,
    /// reading no file again. With `same_shapes` (no parameter of a `<shape>` changed) the
    /// hierarchy over the shapes is kept as it is, else refit to the moved shapes where it can
    /// be ([`KeptGeometry`]). The scene is seen through the same sensor, with the same
    /// overrides; on an error it is left as it was.
    pub fn rebuild(
        &mut self,
        py: Python<'_>,
        description: Arc<PluginNode>,
        same_shapes: bool,
    ) -> PyResult<()> {
        let world = &mut self.loaded.scene.world;
        let kept = std::mem::replace(&mut world.geometry, Geometry::new(Vec::new()));
        let mut geometry = Some(if same_shapes {
            KeptGeometry::Unchanged(kept)
        } else {
            KeptGeometry::Moved(kept)
        });
        let files = &self.files;
        let warnings = &self.reader_warnings;
        let built = py.detach(|| files.scope(|| build(&description, &mut geometry, warnings)));
        let mut loaded = match built {
            Ok(loaded) => loaded,
            Err(error) => {
                if let Some(geometry) = geometry {
                    self.loaded.scene.world.geometry = geometry.into_geometry();
                }
                return Err(to_py(py, &error));
            }
        };
        (loaded.select_sensor(self.loaded.selected_sensor())).into_py_result(py)?;
        if let Some(density) = self.wavelengths {
            override_wavelengths(&mut loaded.scene, density);
        }
        if let Some(reconstruction) = self.reconstruction {
            override_reconstruction(&mut loaded.scene, reconstruction);
        }
        self.loaded = loaded;
        self.description = description;
        Ok(())
    }
}

/// The scene `description` describes, with the hierarchy `geometry` holds if any, its
/// warnings led by the reader's.
fn build(
    description: &PluginNode,
    geometry: &mut Option<KeptGeometry>,
    reader_warnings: &[Warning],
) -> Result<LoadedScene> {
    let mut loaded = build_scene_with_geometry(description, geometry)?;
    loaded
        .warnings
        .splice(0..0, reader_warnings.iter().cloned());
    Ok(loaded)
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
        self.wavelengths = Some(density);
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
        self.reconstruction = Some(reconstruction);
        Ok(())
    }

    /// The index of the sensor the scene is seen through: 0 after loading, then the one the
    /// last render used; `width`, `height`, `spp` and `seed` are its.
    #[getter]
    fn sensor(&self) -> usize {
        self.loaded.selected_sensor()
    }

    /// Whether the hierarchy over the shapes is one refit to moved shapes by an update rather
    /// than one built for them (see `SceneParameters.update`).
    #[getter]
    fn bvh_refit(&self) -> bool {
        self.loaded.scene.world.geometry.is_refit()
    }

    /// The `id` of every sensor (None for one without), in document order.
    #[getter]
    fn sensor_ids(&self) -> Vec<Option<String>> {
        (self.loaded.sensors().iter())
            .map(|sensor| sensor.id.clone())
            .collect()
    }

    /// The closest surface each ray meets, as Mitsuba's `scene.ray_intersect`: for one
    /// [`ray_queries::Ray3f`], or for N rays given as (N, 3) arrays of `origins` and
    /// `directions` with `tmax` None, a number or N numbers.
    #[pyo3(signature = (origins, directions = None, tmax = None))]
    fn ray_intersect(
        &self,
        py: Python<'_>,
        origins: &Bound<'_, PyAny>,
        directions: Option<&Bound<'_, PyAny>>,
        tmax: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<SurfaceInteraction> {
        let rays = Rays::of(origins, directions, tmax)?;
        ray_queries::intersect(py, &self.loaded.scene.world.geometry, rays)
    }

    /// Whether anything blocks each ray before its `tmax`, as Mitsuba's `scene.ray_test`
    /// (shadow rays); the rays as for [`Scene::ray_intersect`].
    #[pyo3(signature = (origins, directions = None, tmax = None))]
    fn ray_test(
        &self,
        py: Python<'_>,
        origins: &Bound<'_, PyAny>,
        directions: Option<&Bound<'_, PyAny>>,
        tmax: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        let rays = Rays::of(origins, directions, tmax)?;
        ray_queries::occluded(py, &self.loaded.scene.world.geometry, rays)
    }

    /// The scene's shapes, in document order.
    fn shapes(slf: &Bound<'_, Self>) -> Vec<Shape> {
        introspection::shapes(slf)
    }

    /// The scene's lights.
    fn emitters(slf: &Bound<'_, Self>) -> Vec<Emitter> {
        introspection::emitters(slf)
    }

    /// The scene's sensors, in document order.
    fn sensors(slf: &Bound<'_, Self>) -> Vec<Sensor> {
        introspection::sensors(slf)
    }

    /// The box around the scene's shapes; an empty scene's is infinite and inverted.
    fn bbox(&self) -> BoundingBox3f {
        let bounds = self.loaded.scene.world.geometry.bounds();
        BoundingBox3f::new(bounds.unwrap_or((glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY)))
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

/// Loads the scene at `path` (Mitsuba XML, or pbrt-v4 when its name ends in `.pbrt`), with
/// `defines` as `(name, value)` pairs for an XML scene's `$name` parameters (the command line's
/// `-D name=value`).
#[pyfunction]
#[pyo3(signature = (path, defines = Vec::new()))]
pub fn load_file(py: Python<'_>, path: PathBuf, defines: Vec<(String, String)>) -> PyResult<Scene> {
    let document = py
        .detach(|| read_scene(&path, &defines))
        .into_py_result(py)?;
    Scene::build(py, document)
}

/// Loads a Mitsuba XML scene given as the string `text`, with `defines` as in [`load_file`];
/// relative file names are found from the current folder, and messages name the text
/// `<string>`.
#[pyfunction]
#[pyo3(signature = (text, defines = Vec::new()))]
pub fn load_string(
    py: Python<'_>,
    text: String,
    defines: Vec<(String, String)>,
) -> PyResult<Scene> {
    let document = py
        .detach(|| read_scene_str_document(&text, Path::new("<string>"), &defines))
        .into_py_result(py)?;
    Scene::build(py, document)
}

/// Loads a scene given in Mitsuba's dictionary form.
#[pyfunction]
pub fn load_dict(py: Python<'_>, scene: &Bound<'_, PyDict>) -> PyResult<Scene> {
    let root = dict_of(scene, "scene")?;
    let description = py
        .detach(|| dict::read_scene_dict(&root))
        .into_py_result(py)?;
    let document = SceneDocument {
        root: description,
        warnings: Vec::new(),
    };
    Scene::build(py, document)
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
