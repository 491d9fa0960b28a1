//! Ray queries against a scene's geometry, as Mitsuba's `scene.ray_intersect` and
//! `scene.ray_test`: one [`Ray3f`], or N rays given as (N, 3) arrays of origins and directions.
//! The rays are traced by the renderer's own hierarchy ([`Geometry::intersect`] and
//! [`Geometry::occluded`]), without the GIL and on rayon's threads; each ray's answer depends
//! on that ray alone, so it is the same for any number of threads.

use glam::Vec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike1, PyArrayLike2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

use prism_core::geometry::Geometry;
use prism_core::math::Ray;

/// One ray, as Mitsuba's `mi.Ray3f`: the points `o + t d` for 0 < t < `maxt`, at `time`.
#[pyclass(module = "prism_renderer")]
#[derive(Clone)]
pub struct Ray3f {
    #[pyo3(get, set)]
    o: [f32; 3],
    #[pyo3(get, set)]
    d: [f32; 3],
    #[pyo3(get, set)]
    maxt: f32,
    #[pyo3(get, set)]
    time: f32,
}

#[pymethods]
impl Ray3f {
    #[new]
    #[pyo3(signature = (o, d, maxt = f32::INFINITY, time = 0.0))]
    fn new(o: [f32; 3], d: [f32; 3], maxt: f32, time: f32) -> Ray3f {
        Ray3f { o, d, maxt, time }
    }

    /// The point `o + t d`.
    fn __call__(&self, t: f32) -> [f32; 3] {
        (Vec3::from(self.o) + t * Vec3::from(self.d)).to_array()
    }

    fn __repr__(&self) -> String {
        format!(
            "Ray3f(o={:?}, d={:?}, maxt={}, time={})",
            self.o, self.d, self.maxt, self.time
        )
    }
}

/// What `ray_intersect` found, as Mitsuba's `SurfaceInteraction3f`: for N rays, arrays with one
/// entry per ray; for one [`Ray3f`], that entry alone. Where a ray hit nothing, `t` is
/// infinite, `shape` and `prim_index` are -1 and the other values 0.
#[pyclass(module = "prism_renderer", frozen)]
pub struct SurfaceInteraction {
    /// The distance along the ray, in units of its direction's length.
    #[pyo3(get)]
    t: Py<PyAny>,
    /// The point hit, (N, 3).
    #[pyo3(get)]
    p: Py<PyAny>,
    /// The unit geometric normal, on the side the shape calls outside, (N, 3).
    #[pyo3(get)]
    n: Py<PyAny>,
    /// The unit shading normal (interpolated on smooth meshes), (N, 3).
    #[pyo3(get)]
    sh_n: Py<PyAny>,
    /// The surface's texture coordinates, (N, 2).
    #[pyo3(get)]
    uv: Py<PyAny>,
    /// The index of the shape hit (`scene.shapes()`' order, as the `aov` integrator's
    /// `shape_index`).
    #[pyo3(get)]
    shape: Py<PyAny>,
    /// The triangle within a mesh (0 for other shapes).
    #[pyo3(get)]
    prim_index: Py<PyAny>,
    valid: Py<PyAny>,
}

#[pymethods]
impl SurfaceInteraction {
    /// Whether each ray hit a surface, as Mitsuba's `si.is_valid()`.
    fn is_valid(&self, py: Python<'_>) -> Py<PyAny> {
        self.valid.clone_ref(py)
    }
}

/// The rays a query is asked about, and whether they came as one [`Ray3f`].
pub struct Rays {
    rays: Vec<Ray>,
    single: bool,
}

impl Rays {
    /// The rays of a query's arguments: a [`Ray3f`] alone, or (N, 3) arrays of `origins` and
    /// `directions` with `tmax` None (no bound), one number or N of them.
    pub fn of(
        origins: &Bound<'_, PyAny>,
        directions: Option<&Bound<'_, PyAny>>,
        tmax: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Rays> {
        if let Ok(ray) = origins.cast::<Ray3f>() {
            if directions.is_some() || tmax.is_some() {
                return Err(PyValueError::new_err(
                    "a Ray3f carries its direction and maxt: give it alone",
                ));
            }
            let ray = ray.borrow();
            return Ok(Rays {
                rays: vec![Ray::new(ray.o.into(), ray.d.into(), ray.maxt, ray.time)],
                single: true,
            });
        }
        let Some(directions) = directions else {
            return Err(PyValueError::new_err(
                "give a Ray3f, or (N, 3) arrays of origins and directions",
            ));
        };
        let origins = points("origins", origins)?;
        let directions = points("directions", directions)?;
        if origins.len() != directions.len() {
            return Err(PyValueError::new_err(format!(
                "{} origins but {} directions",
                origins.len(),
                directions.len()
            )));
        }
        let tmax = match tmax {
            None => vec![f32::INFINITY; origins.len()],
            Some(tmax) => match tmax.extract::<f32>() {
                Ok(bound) => vec![bound; origins.len()],
                Err(_) => {
                    let bounds: PyArrayLike1<'_, f32, AllowTypeChange> = tmax.extract()?;
                    let bounds = bounds.as_array().to_vec();
                    if bounds.len() != origins.len() {
                        return Err(PyValueError::new_err(format!(
                            "{} values of tmax for {} rays",
                            bounds.len(),
                            origins.len()
                        )));
                    }
                    bounds
                }
            },
        };
        let rays = (origins.into_iter().zip(directions).zip(tmax))
            .map(|((o, d), t_max)| Ray::new(o, d, t_max, 0.0))
            .collect();
        Ok(Rays {
            rays,
            single: false,
        })
    }
}

/// The rows of an (N, 3) array-like as points or vectors.
fn points(name: &str, array: &Bound<'_, PyAny>) -> PyResult<Vec<Vec3>> {
    let array: PyArrayLike2<'_, f32, AllowTypeChange> = array
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{name} must be an (N, 3) array of numbers")))?;
    let array = array.as_array();
    if array.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "{name} must be an (N, 3) array, not {:?}",
            array.shape()
        )));
    }
    Ok(array
        .rows()
        .into_iter()
        .map(|row| Vec3::new(row[0], row[1], row[2]))
        .collect())
}

/// The value for one ray (its entry) or for several (the array).
fn entry_or_array(array: Bound<'_, PyAny>, single: bool) -> PyResult<Py<PyAny>> {
    Ok(if single {
        array.get_item(0)?.unbind()
    } else {
        array.unbind()
    })
}

/// The closest hit of every ray in `rays` with `geometry`.
pub fn intersect(py: Python<'_>, geometry: &Geometry, rays: Rays) -> PyResult<SurfaceInteraction> {
    let hits: Vec<_> = py.detach(|| {
        (rays.rays.par_iter())
            .map(|ray| geometry.intersect(ray))
            .collect()
    });
    let n = hits.len();
    let mut t = Vec::with_capacity(n);
    let mut p = Vec::with_capacity(3 * n);
    let mut normal = Vec::with_capacity(3 * n);
    let mut shading = Vec::with_capacity(3 * n);
    let mut uv = Vec::with_capacity(2 * n);
    let mut shape = Vec::with_capacity(n);
    let mut prim_index = Vec::with_capacity(n);
    let mut valid = Vec::with_capacity(n);
    for hit in &hits {
        match hit {
            Some(si) => {
                t.push(si.t);
                p.extend(si.p.to_array());
                normal.extend(si.n.to_array());
                shading.extend(si.shading.n.to_array());
                uv.extend(si.uv.to_array());
                shape.push(i64::from(si.shape));
                prim_index.push(i64::from(si.primitive));
                valid.push(true);
            }
            None => {
                t.push(f32::INFINITY);
                p.extend([0.0; 3]);
                normal.extend([0.0; 3]);
                shading.extend([0.0; 3]);
                uv.extend([0.0; 2]);
                shape.push(-1);
                prim_index.push(-1);
                valid.push(false);
            }
        }
    }
    let single = rays.single;
    let rows = |values: Vec<f32>, columns: usize| -> PyResult<Py<PyAny>> {
        let array = Array2::from_shape_vec((n, columns), values)
            .expect("one row per ray")
            .into_pyarray(py);
        entry_or_array(array.into_any(), single)
    };
    Ok(SurfaceInteraction {
        t: entry_or_array(Array1::from(t).into_pyarray(py).into_any(), single)?,
        p: rows(p, 3)?,
        n: rows(normal, 3)?,
        sh_n: rows(shading, 3)?,
        uv: rows(uv, 2)?,
        shape: entry_or_array(Array1::from(shape).into_pyarray(py).into_any(), single)?,
        prim_index: entry_or_array(Array1::from(prim_index).into_pyarray(py).into_any(), single)?,
        valid: entry_or_array(Array1::from(valid).into_pyarray(py).into_any(), single)?,
    })
}

/// Whether anything blocks each ray of `rays` before its `tmax` (a bool, or a bool array).
pub fn occluded(py: Python<'_>, geometry: &Geometry, rays: Rays) -> PyResult<Py<PyAny>> {
    let blocked: Vec<bool> = py.detach(|| {
        (rays.rays.par_iter())
            .map(|ray| geometry.occluded(ray))
            .collect()
    });
    entry_or_array(
        Array1::from(blocked).into_pyarray(py).into_any(),
        rays.single,
    )
}
