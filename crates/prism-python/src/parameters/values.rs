//! What a parameter holds, and its values to and from Python: a value of the description as
//! the parameter's Python value, and a Python value checked against the parameter's type and
//! shape as the description's.

use glam::{DMat4, DVec3};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyString};

use crate::error::to_py;
use crate::transform::Transform;
use prism_core::camera::perspective::FovAxis;
use prism_core::error::Error;
use prism_core::spectrum::ior::named_ior;
use prism_mitsuba::description::{PluginNode, PropertyValue, SpectrumValue};

/// What a parameter holds, and so which Python values it takes.
#[derive(Clone, Debug)]
pub(super) enum Kind {
    Float,
    Integer,
    Boolean,
    /// An `<rgb>` colour: three numbers (one number means three equal ones).
    Rgb,
    /// A `<spectrum>` of one value at every wavelength.
    UniformSpectrum,
    /// The values of a `<spectrum>` sampled at `wavelengths` (nm), which stay.
    SpectrumValues {
        wavelengths: Vec<f64>,
    },
    Point,
    Vector,
    Transform,
    /// The horizontal field of view of a camera whose `fov` is measured along `axis` on a film
    /// of `aspect` = width / height; set, it becomes `fov` along `fov_axis` "x".
    HorizontalFov {
        axis: FovAxis,
        aspect: f64,
    },
    /// Mitsuba's `eta` of a dielectric interface, `int_ior` / `ext_ior` (each a number or a
    /// name; absent, the named default `interior` or `exterior`); set, it becomes `int_ior`
    /// over an `ext_ior` of 1.
    RelativeIor {
        interior: &'static str,
        exterior: &'static str,
    },
}

impl Kind {
    /// The parameter's type, for the table and for messages.
    pub(super) fn describe(&self) -> &'static str {
        match self {
            Kind::Float
            | Kind::UniformSpectrum
            | Kind::HorizontalFov { .. }
            | Kind::RelativeIor { .. } => "float",
            Kind::Integer => "int",
            Kind::Boolean => "bool",
            Kind::Rgb => "rgb",
            Kind::SpectrumValues { .. } => "spectrum values",
            Kind::Point => "point",
            Kind::Vector => "vector",
            Kind::Transform => "Transform",
        }
    }
}

/// `int_ior` / `ext_ior` of the plugin `node`, each a number or a name, or absent the named
/// default (`interior`, `exterior`); None when either is a spectrum.
pub(super) fn relative_ior(node: &PluginNode, interior: &str, exterior: &str) -> Option<f64> {
    let index = |name: &str, default: &str| {
        let value = (node.properties.iter()).find(|p| p.name == name);
        match value.map(|p| &p.value) {
            Some(PropertyValue::Float(v)) => Some(*v),
            Some(PropertyValue::String(named)) => named_ior(named).map(f64::from),
            None => named_ior(default).map(f64::from),
            Some(_) => None,
        }
    };
    Some(index("int_ior", interior)? / index("ext_ior", exterior)?)
}

/// A value of the description as the Python value of the parameter.
pub(super) fn to_python<'py>(
    py: Python<'py>,
    value: &PropertyValue,
) -> PyResult<Bound<'py, PyAny>> {
    let array = |values: Vec<f64>| values.into_pyarray(py).into_any();
    Ok(match value {
        PropertyValue::Float(v) => v.into_pyobject(py)?.into_any(),
        PropertyValue::Integer(v) => v.into_pyobject(py)?.into_any(),
        PropertyValue::Boolean(v) => PyBool::new(py, *v).to_owned().into_any(),
        PropertyValue::Rgb(rgb) => array(rgb.to_vec()),
        PropertyValue::Spectrum(SpectrumValue::Uniform(v)) => v.into_pyobject(py)?.into_any(),
        PropertyValue::Spectrum(SpectrumValue::Samples(samples)) => {
            array(samples.iter().map(|&(_, v)| v).collect())
        }
        PropertyValue::Point(p) | PropertyValue::Vector(p) => array(p.to_array().to_vec()),
        PropertyValue::Transform(matrix) => {
            Transform { matrix: *matrix }.into_pyobject(py)?.into_any()
        }
        PropertyValue::String(_)
        | PropertyValue::Animation(_)
        | PropertyValue::Numbers(_)
        | PropertyValue::Tensor { .. } => {
            unreachable!("strings, animations, lists of numbers and tensors are not parameters")
        }
    })
}

/// The Python `value` given for the parameter `key`, of kind `kind`, as the description's
/// value; a value of another type or shape is an error that says what the parameter takes.
pub(super) fn from_python(
    key: &str,
    kind: &Kind,
    value: &Bound<'_, PyAny>,
) -> PyResult<PropertyValue> {
    let py = value.py();
    let refuse = |takes: &str| {
        let shown = value
            .repr()
            .map(|r| r.to_string())
            .unwrap_or_else(|_| "the value".into());
        let shown: String = if shown.chars().count() > 60 {
            shown.chars().take(57).chain("...".chars()).collect()
        } else {
            shown
        };
        to_py(
            py,
            &Error::usage(format!("\"{key}\" cannot be set to {shown}"))
                .with_help(format!("\"{key}\" takes {takes}")),
        )
    };
    let number = |takes: &str| -> PyResult<f64> {
        let is_number = !value.is_instance_of::<PyBool>()
            && (value.is_instance_of::<PyFloat>()
                || value.is_instance_of::<PyInt>()
                || is_numpy_number(value));
        match is_number.then(|| value.extract::<f64>()) {
            Some(Ok(v)) if v.is_finite() => Ok(v),
            _ => Err(refuse(takes)),
        }
    };
    let numbers = |count: usize, takes: &str| -> PyResult<Vec<f64>> {
        if value.is_instance_of::<PyString>() {
            return Err(refuse(takes));
        }
        match value.extract::<Vec<f64>>() {
            Ok(v) if v.len() == count && v.iter().all(|x| x.is_finite()) => Ok(v),
            _ => Err(refuse(takes)),
        }
    };
    Ok(match kind {
        Kind::Float => PropertyValue::Float(number("a finite number")?),
        Kind::HorizontalFov { .. } => {
            let fov = number("an angle in degrees between 0 and 180")?;
            if !(fov > 0.0 && fov < 180.0) {
                return Err(refuse("an angle in degrees between 0 and 180"));
            }
            PropertyValue::Float(fov)
        }
        Kind::RelativeIor { .. } => {
            let eta = number("a positive number")?;
            if eta <= 0.0 {
                return Err(refuse("a positive number"));
            }
            PropertyValue::Float(eta)
        }
        Kind::UniformSpectrum => {
            PropertyValue::Spectrum(SpectrumValue::Uniform(number("a finite number")?))
        }
        Kind::Integer => match value.extract::<i64>() {
            Ok(v) if !value.is_instance_of::<PyBool>() => PropertyValue::Integer(v),
            _ => return Err(refuse("an integer of 64 bits")),
        },
        Kind::Boolean => match value.cast::<PyBool>() {
            Ok(b) => PropertyValue::Boolean(b.is_true()),
            Err(_) => return Err(refuse("True or False")),
        },
        Kind::Rgb => {
            const TAKES: &str = "three finite numbers (red, green, blue) or one for all three";
            match number(TAKES) {
                Ok(v) => PropertyValue::Rgb([v; 3]),
                Err(_) => {
                    let v = numbers(3, TAKES)?;
                    PropertyValue::Rgb([v[0], v[1], v[2]])
                }
            }
        }
        Kind::SpectrumValues { wavelengths } => {
            let count = wavelengths.len();
            let takes = format!("{count} finite numbers, one per wavelength of the spectrum");
            let values = numbers(count, &takes)?;
            let samples = wavelengths.iter().copied().zip(values).collect();
            PropertyValue::Spectrum(SpectrumValue::Samples(samples))
        }
        Kind::Point => {
            PropertyValue::Point(DVec3::from_slice(&numbers(3, "three finite numbers")?))
        }
        Kind::Vector => {
            PropertyValue::Vector(DVec3::from_slice(&numbers(3, "three finite numbers")?))
        }
        Kind::Transform => {
            const TAKES: &str = "a Transform or a 4 × 4 matrix of finite numbers";
            if let Ok(transform) = value.cast::<Transform>() {
                PropertyValue::Transform(transform.get().matrix)
            } else {
                let rows = value.extract::<Vec<[f64; 4]>>().ok().and_then(|rows| {
                    let rows: [[f64; 4]; 4] = rows.try_into().ok()?;
                    rows.as_flattened()
                        .iter()
                        .all(|x| x.is_finite())
                        .then_some(rows)
                });
                match rows {
                    Some(rows) => {
                        PropertyValue::Transform(DMat4::from_cols_array_2d(&rows).transpose())
                    }
                    None => return Err(refuse(TAKES)),
                }
            }
        }
    })
}

/// Whether `value` is a numpy number or a numpy array of no dimensions (a number of another
/// type than Python's `float` or `int`).
fn is_numpy_number(value: &Bound<'_, PyAny>) -> bool {
    value.hasattr("dtype").unwrap_or(false)
        && value.hasattr("__float__").unwrap_or(false)
        && value
            .getattr("ndim")
            .and_then(|n| n.extract::<usize>())
            .map(|n| n == 0)
            .unwrap_or(false)
}
