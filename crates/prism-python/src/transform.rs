//! `Transform`, a 4 × 4 matrix acting on column vectors, composed like Mitsuba's
//! `ScalarTransform4f`: each operation multiplies on the right, `T().translate(v).scale(s)` =
//! translate · scale (the scaling is applied first). The operations are those of the XML
//! reader's `<transform>` ([`prism_mitsuba::dict::transform`]). `T @ p` applies it to points as
//! Mitsuba's `Transform4f @ Point3f` does: p' = (M·(p, 1))_xyz / (M·(p, 1))_w.

use glam::{DMat4, DVec3, DVec4};
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use prism_mitsuba::dict::transform;

/// A 4 × 4 transform matrix.
#[pyclass(module = "prism_renderer", frozen)]
#[derive(Clone, Copy)]
pub struct Transform {
    pub matrix: DMat4,
}

impl Transform {
    /// The matrix's rows.
    pub fn rows(&self) -> [[f64; 4]; 4] {
        self.matrix.transpose().to_cols_array_2d()
    }

    fn then(&self, operation: DMat4) -> Transform {
        Transform {
            matrix: self.matrix * operation,
        }
    }

    /// The point `p` transformed, with the projective division by w.
    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let h = self.matrix * DVec4::new(p[0], p[1], p[2], 1.0);
        (h.truncate() / h.w).to_array()
    }
}

/// The right operand of `@`: a transform, one point, or a list of points (N × 3).
#[derive(FromPyObject)]
enum Operand<'py> {
    Transform(Bound<'py, Transform>),
    Point([f64; 3]),
    Points(Vec<[f64; 3]>),
}

/// Three numbers, or one repeated three times.
#[derive(FromPyObject)]
enum Vector {
    Three([f64; 3]),
    One(f64),
}

impl Vector {
    fn get(&self) -> DVec3 {
        match *self {
            Vector::Three(v) => DVec3::from_array(v),
            Vector::One(v) => DVec3::splat(v),
        }
    }
}

#[pymethods]
impl Transform {
    /// The identity, or the given 4 × 4 matrix (rows first).
    #[new]
    #[pyo3(signature = (matrix = None))]
    fn new(matrix: Option<PyReadonlyArray2<'_, f64>>) -> PyResult<Transform> {
        let Some(matrix) = matrix else {
            return Ok(Transform {
                matrix: DMat4::IDENTITY,
            });
        };
        let array = matrix.as_array();
        if array.shape() != [4, 4] {
            return Err(PyValueError::new_err(format!(
                "a transform is a 4×4 matrix, not {:?}",
                array.shape()
            )));
        }
        let mut rows = [[0.0; 4]; 4];
        for ((r, c), value) in array.indexed_iter() {
            rows[r][c] = *value;
        }
        let matrix = DMat4::from_cols_array_2d(&rows).transpose();
        if !matrix.is_finite() {
            return Err(PyValueError::new_err(
                "the matrix has entries that are not finite",
            ));
        }
        Ok(Transform { matrix })
    }

    /// This transform followed on the right by the translation by `offset`.
    fn translate(&self, offset: Vector) -> Transform {
        self.then(transform::translate(offset.get()))
    }

    /// This transform followed on the right by the scaling by `factors` (one number or three).
    fn scale(&self, factors: Vector) -> Transform {
        self.then(transform::scale(factors.get()))
    }

    /// This transform followed on the right by the rotation by `angle` degrees about `axis`
    /// (right-handed), taken as given as Mitsuba 3 does: an axis not of unit length also
    /// stretches and shears.
    fn rotate(&self, axis: [f64; 3], angle: f64) -> PyResult<Transform> {
        let rotation = transform::rotate(DVec3::from_array(axis), angle)
            .map_err(|problem| PyValueError::new_err(format!("rotate: {problem}")))?;
        Ok(self.then(rotation))
    }

    /// This transform followed on the right by the camera-to-world transform looking from
    /// `origin` at `target` with `up` (None: any direction perpendicular to the view).
    #[pyo3(signature = (origin, target, up = None))]
    fn look_at(
        &self,
        origin: [f64; 3],
        target: [f64; 3],
        up: Option<[f64; 3]>,
    ) -> PyResult<Transform> {
        let camera = transform::look_at(
            DVec3::from_array(origin),
            DVec3::from_array(target),
            up.map_or(DVec3::ZERO, DVec3::from_array),
        )
        .map_err(|problem| PyValueError::new_err(format!("look_at: {problem}")))?;
        Ok(self.then(camera))
    }

    /// The inverse transform.
    fn inverse(&self) -> PyResult<Transform> {
        let inverse = self.matrix.inverse();
        if inverse.is_finite() {
            Ok(Transform { matrix: inverse })
        } else {
            Err(PyValueError::new_err("the transform is not invertible"))
        }
    }

    /// The 4 × 4 matrix, rows first (a new numpy array of float64).
    #[getter]
    fn matrix<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let rows = self.rows();
        PyArray2::from_owned_array(
            py,
            numpy::ndarray::Array2::from_shape_fn((4, 4), |(r, c)| rows[r][c]),
        )
    }

    /// The product with another transform; or the point (three numbers) or points (N × 3)
    /// transformed, as a numpy float64 array of the same shape.
    fn __matmul__<'py>(&self, py: Python<'py>, other: Operand<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(match other {
            Operand::Transform(other) => Bound::new(py, self.then(other.get().matrix))?.into_any(),
            Operand::Point(p) => self.apply(p).to_vec().into_pyarray(py).into_any(),
            Operand::Points(points) => {
                let rows = points.len();
                let values: Vec<f64> = points.into_iter().flat_map(|p| self.apply(p)).collect();
                numpy::ndarray::Array2::from_shape_vec((rows, 3), values)
                    .expect("three values per point")
                    .into_pyarray(py)
                    .into_any()
            }
        })
    }

    fn __eq__(&self, other: &Transform) -> bool {
        self.matrix == other.matrix
    }

    fn __repr__(&self) -> String {
        let rows: Vec<String> = self
            .rows()
            .iter()
            .map(|row| format!("[{}, {}, {}, {}]", row[0], row[1], row[2], row[3]))
            .collect();
        format!("Transform([{}])", rows.join(", "))
    }
}
