//! What a loaded scene is made of, as Mitsuba's `scene.shapes()`, `scene.emitters()`,
//! `scene.sensors()` and `scene.bbox()` show it: each [`Shape`], [`Emitter`] and [`Sensor`]
//! refers to its scene and reads it when asked, so it follows the scene through
//! `params.update()`.

use std::sync::Arc;

use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::{PyIndexError, PyTypeError};
use pyo3::prelude::*;

use crate::scene::Scene;
use prism_core::geometry::{AggregateElement, Primitive, TriangleMesh};
use prism_core::light::{Light, LightSource};
use prism_mitsuba::description::PluginNode;

/// An axis-aligned box, as Mitsuba's `BoundingBox3f`: the points `min` ≤ p ≤ `max`.
#[pyclass(module = "prism_renderer", frozen)]
pub struct BoundingBox3f {
    #[pyo3(get)]
    min: [f32; 3],
    #[pyo3(get)]
    max: [f32; 3],
}

impl BoundingBox3f {
    pub fn new((min, max): (glam::Vec3, glam::Vec3)) -> BoundingBox3f {
        BoundingBox3f {
            min: min.to_array(),
            max: max.to_array(),
        }
    }
}

#[pymethods]
impl BoundingBox3f {
    /// The midpoint of `min` and `max`.
    fn center(&self) -> [f32; 3] {
        std::array::from_fn(|i| 0.5 * (self.min[i] + self.max[i]))
    }

    /// `max − min`.
    fn extents(&self) -> [f32; 3] {
        std::array::from_fn(|i| self.max[i] - self.min[i])
    }

    fn __repr__(&self) -> String {
        format!("BoundingBox3f(min={:?}, max={:?})", self.min, self.max)
    }
}

/// One shape of a scene: a primitive of its geometry (a shape, or an `instance` of a shape
/// group), by its index in `scene.shapes()`.
#[pyclass(module = "prism_renderer", frozen)]
pub struct Shape {
    scene: Py<Scene>,
    #[pyo3(get)]
    index: usize,
}

impl Shape {
    /// Calls `read` with the shape's primitive and the plugin that made it.
    fn with<T>(
        &self,
        py: Python<'_>,
        read: impl FnOnce(&Primitive, &PluginNode) -> PyResult<T>,
    ) -> PyResult<T> {
        let scene = self.scene.try_borrow(py)?;
        let primitives = &scene.loaded.scene.world.geometry.primitives;
        let (Some(primitive), Some(plugin)) = (
            primitives.get(self.index),
            scene.loaded.shape_plugins.get(self.index),
        ) else {
            return Err(PyIndexError::new_err(format!(
                "the scene no longer has a shape {}",
                self.index
            )));
        };
        read(primitive, plugin)
    }

    /// Calls `read` with the shape's mesh; a TypeError for a shape that is not one.
    fn with_mesh<T>(&self, py: Python<'_>, read: impl FnOnce(&TriangleMesh) -> T) -> PyResult<T> {
        self.with(py, |primitive, plugin| match primitive.mesh() {
            Some(mesh) => Ok(read(mesh)),
            None => Err(PyTypeError::new_err(format!(
                "{} is not a triangle mesh",
                plugin.describe()
            ))),
        })
    }
}

#[pymethods]
impl Shape {
    /// The shape's name: its `id`, else the name `traverse` gives it (its key in a dictionary,
    /// or `shape_0`, `shape_1`, … in document order), so that `f"{shape.id()}.to_world"` is a
    /// key of `traverse(scene)`.
    fn id(&self, py: Python<'_>) -> PyResult<String> {
        let scene = self.scene.try_borrow(py)?;
        let plugin = scene.loaded.shape_plugins.get(self.index).ok_or_else(|| {
            PyIndexError::new_err(format!("the scene no longer has a shape {}", self.index))
        })?;
        Ok(name_of(&scene, plugin))
    }

    /// The plugin's type: `obj`, `ply`, `sphere`, `rectangle`, `instance`, ….
    fn plugin_type(&self, py: Python<'_>) -> PyResult<String> {
        self.with(py, |_, plugin| Ok(plugin.plugin_type.clone()))
    }

    /// The box around the shape in world space (around its motion, for a moving one).
    fn bbox(&self, py: Python<'_>) -> PyResult<BoundingBox3f> {
        self.with(py, |primitive, _| {
            Ok(BoundingBox3f::new(AggregateElement::bounds(primitive)))
        })
    }

    /// The surface area in world units (0 for curves).
    fn surface_area(&self, py: Python<'_>) -> PyResult<f32> {
        self.with(py, |primitive, _| Ok(primitive.area()))
    }

    /// Whether the shape is a triangle mesh (`obj`, `ply`, `serialized`, `rectangle`, `cube`, …).
    fn is_mesh(&self, py: Python<'_>) -> PyResult<bool> {
        self.with(py, |primitive, _| Ok(primitive.mesh().is_some()))
    }

    /// Whether an area light lies on the shape.
    fn is_emitter(&self, py: Python<'_>) -> PyResult<bool> {
        let scene = self.scene.try_borrow(py)?;
        let info = scene.loaded.scene.world.shape_info.get(self.index);
        Ok(info.is_some_and(|info| info.light.is_some()))
    }

    /// A mesh's vertex positions in world space, (V, 3) float32; TypeError for other shapes.
    fn vertex_positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let values: Vec<f32> = self.with_mesh(py, |mesh| {
            mesh.positions().iter().flat_map(|p| p.to_array()).collect()
        })?;
        let rows = values.len() / 3;
        let array = Array2::from_shape_vec((rows, 3), values).expect("three per vertex");
        Ok(array.into_pyarray(py).into_any())
    }

    /// A mesh's triangles as indices of `vertex_positions`, (F, 3) uint32; TypeError for other
    /// shapes.
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let values: Vec<u32> = self.with_mesh(py, |mesh| {
            mesh.triangles().iter().flatten().copied().collect()
        })?;
        let rows = values.len() / 3;
        let array = Array2::from_shape_vec((rows, 3), values).expect("three per triangle");
        Ok(array.into_pyarray(py).into_any())
    }

    /// A mesh's vertex count; TypeError for other shapes.
    fn vertex_count(&self, py: Python<'_>) -> PyResult<usize> {
        self.with_mesh(py, |mesh| mesh.positions().len())
    }

    /// A mesh's triangle count; TypeError for other shapes.
    fn face_count(&self, py: Python<'_>) -> PyResult<usize> {
        self.with_mesh(py, |mesh| mesh.triangles().len())
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let id = self.id(py)?;
        self.with(py, |_, plugin| {
            Ok(format!("Shape({}, {:?})", plugin.describe(), id))
        })
    }
}

/// One light of a scene, by its index in `scene.emitters()`.
#[pyclass(module = "prism_renderer", frozen)]
pub struct Emitter {
    scene: Py<Scene>,
    #[pyo3(get)]
    index: usize,
}

impl Emitter {
    fn with<T>(&self, py: Python<'_>, read: impl FnOnce(&Light) -> T) -> PyResult<T> {
        let scene = self.scene.try_borrow(py)?;
        let light = (scene.loaded.scene.world.lights.get(self.index)).ok_or_else(|| {
            PyIndexError::new_err(format!("the scene no longer has an emitter {}", self.index))
        })?;
        Ok(read(light))
    }
}

#[pymethods]
impl Emitter {
    /// The emitter's name: its `id`, else the name `traverse` gives it (`light.emitter` for
    /// the emitter of a shape `light`, `emitter` for the scene's one), so that
    /// `f"{emitter.id()}.radiance.value"` is a key of `traverse(scene)`.
    fn id(&self, py: Python<'_>) -> PyResult<String> {
        let scene = self.scene.try_borrow(py)?;
        let plugin = scene
            .loaded
            .emitter_plugins
            .get(self.index)
            .ok_or_else(|| {
                PyIndexError::new_err(format!("the scene no longer has an emitter {}", self.index))
            })?;
        Ok(name_of(&scene, plugin))
    }

    /// Whether the light is at infinity (`constant`, `envmap`, `sunsky`), seen by rays that
    /// leave the scene.
    fn is_environment(&self, py: Python<'_>) -> PyResult<bool> {
        self.with(py, Light::is_environment)
    }

    /// The index in `scene.shapes()` of the shape an area light lies on; None for other lights.
    fn shape(&self, py: Python<'_>) -> PyResult<Option<usize>> {
        let scene = self.scene.try_borrow(py)?;
        let infos = &scene.loaded.scene.world.shape_info;
        let shapes = scene.loaded.scene.world.geometry.primitives.len();
        Ok((infos.iter().take(shapes)).position(|info| info.light == Some(self.index as u32)))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("Emitter({:?})", self.id(py)?))
    }
}

/// One sensor of a scene, by its index in `scene.sensors()` (document order).
#[pyclass(module = "prism_renderer", frozen)]
pub struct Sensor {
    scene: Py<Scene>,
    #[pyo3(get)]
    index: usize,
}

#[pymethods]
impl Sensor {
    /// The sensor's `id`, or None.
    fn id(&self, py: Python<'_>) -> PyResult<Option<String>> {
        let scene = self.scene.try_borrow(py)?;
        Ok((scene.loaded.sensors().get(self.index)).and_then(|sensor| sensor.id.clone()))
    }

    /// The film's size in pixels, (width, height), as Mitsuba's `sensor.film().size()`.
    fn film_size(&self, py: Python<'_>) -> PyResult<(u32, u32)> {
        let scene = self.scene.try_borrow(py)?;
        let sensor = (scene.loaded.sensors().get(self.index)).ok_or_else(|| {
            PyIndexError::new_err(format!("the scene no longer has a sensor {}", self.index))
        })?;
        let size = sensor.film().size;
        Ok((size.x, size.y))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("Sensor({}, id={:?})", self.index, self.id(py)?))
    }
}

/// The name `traverse` gives `plugin` of `scene`; its `id` or class if it is not found.
fn name_of(scene: &Scene, plugin: &Arc<PluginNode>) -> String {
    crate::parameters::listing::plugin_name(scene.description(), plugin)
        .or_else(|| plugin.id.clone())
        .unwrap_or_else(|| plugin.class.tag().to_string())
}

/// The shapes of `scene`, in the order of its geometry's primitives (document order).
pub fn shapes(scene: &Bound<'_, Scene>) -> Vec<Shape> {
    let count = scene.borrow().loaded.scene.world.geometry.primitives.len();
    (0..count)
        .map(|index| Shape {
            scene: scene.clone().unbind(),
            index,
        })
        .collect()
}

/// The lights of `scene`, in the order it builds them: those shapes carry, in the shapes'
/// order, then those of the scene's `<emitter>`s.
pub fn emitters(scene: &Bound<'_, Scene>) -> Vec<Emitter> {
    let count = scene.borrow().loaded.scene.world.lights.len();
    (0..count)
        .map(|index| Emitter {
            scene: scene.clone().unbind(),
            index,
        })
        .collect()
}

/// The sensors of `scene`, in document order.
pub fn sensors(scene: &Bound<'_, Scene>) -> Vec<Sensor> {
    let count = scene.borrow().loaded.sensors().len();
    (0..count)
        .map(|index| Sensor {
            scene: scene.clone().unbind(),
            index,
        })
        .collect()
}
