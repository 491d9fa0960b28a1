//! Python values of a scene dictionary as [`prism_mitsuba::dict`]'s values; a value that no
//! scene holds is a `PrismError` at its key path.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::error::to_py;
use crate::transform::Transform;
use prism_core::error::{Error, SourceLocation};
use prism_mitsuba::dict::{Dict, DictValue};

/// How deeply dictionaries and lists may nest: far more than any scene needs, and few enough
/// that a dictionary containing itself is an error rather than a stack overflow.
const MAX_DEPTH: usize = 64;

/// The dictionary at key path `path`.
pub fn dict_of(dict: &Bound<'_, PyDict>, path: &str) -> PyResult<Dict> {
    nested_dict(dict, path, 0)
}

fn nested_dict(dict: &Bound<'_, PyDict>, path: &str, depth: usize) -> PyResult<Dict> {
    if depth > MAX_DEPTH {
        return Err(invalid(
            dict.py(),
            path,
            format!("the dictionary is nested more than {MAX_DEPTH} levels deep"),
            "a dictionary must not contain itself",
        ));
    }
    let mut entries = Vec::with_capacity(dict.len());
    for (key, value) in dict.iter() {
        let Ok(key) = key.cast::<PyString>() else {
            return Err(invalid(
                dict.py(),
                path,
                format!("the key {} is not a string", key.repr()?),
                "name every entry with a string",
            ));
        };
        let key: String = key.extract()?;
        let value = value_of(&value, &format!("{path}.{key}"), depth + 1)?;
        entries.push((key, value));
    }
    Ok(Dict { entries })
}

/// The value at key path `path`: a bool, int, float or string; a path-like object (as its
/// string); a dictionary; a [`Transform`]; a list, tuple or numpy array (4 × 4 numbers are a
/// matrix); or a numpy scalar.
fn value_of(value: &Bound<'_, PyAny>, path: &str, depth: usize) -> PyResult<DictValue> {
    let py = value.py();
    if let Ok(b) = value.cast::<PyBool>() {
        return Ok(DictValue::Boolean(b.is_true()));
    }
    if value.is_instance_of::<PyInt>() {
        return match value.extract::<i64>() {
            Ok(v) => Ok(DictValue::Integer(v)),
            Err(_) => Err(invalid(
                py,
                path,
                format!("the integer {} is too large", value.repr()?),
                "give an integer that fits in 64 bits",
            )),
        };
    }
    if let Ok(f) = value.cast::<PyFloat>() {
        return Ok(DictValue::Float(f.value()));
    }
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(DictValue::String(s.extract()?));
    }
    if let Ok(d) = value.cast::<PyDict>() {
        return Ok(DictValue::Dict(nested_dict(d, path, depth)?));
    }
    if let Ok(t) = value.cast::<Transform>() {
        return Ok(DictValue::Matrix(t.get().rows()));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        if depth > MAX_DEPTH {
            return Err(invalid(
                py,
                path,
                format!("the list is nested more than {MAX_DEPTH} levels deep"),
                "a list must not contain itself",
            ));
        }
        let items = value
            .try_iter()?
            .enumerate()
            .map(|(i, item)| value_of(&item?, &format!("{path}[{i}]"), depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(matrix_of(&items).unwrap_or(DictValue::List(items)));
    }
    if value.hasattr("__fspath__")? {
        let os = py.import("os")?;
        let text = os.call_method1("fspath", (value,))?;
        return value_of(&text, path, depth);
    }
    if value.hasattr("tolist")? {
        // A numpy array or scalar.
        return value_of(&value.call_method0("tolist")?, path, depth + 1);
    }
    Err(invalid(
        py,
        path,
        format!(
            "a value of type {} is not part of a scene dictionary",
            value.get_type().name()?
        ),
        "give a number, string, bool, list of numbers, 4×4 matrix, Transform or dictionary",
    ))
}

/// Four lists of four numbers as a matrix.
fn matrix_of(items: &[DictValue]) -> Option<DictValue> {
    let mut rows = [[0.0; 4]; 4];
    if items.len() != 4 {
        return None;
    }
    for (row, item) in rows.iter_mut().zip(items) {
        let DictValue::List(entries) = item else {
            return None;
        };
        if entries.len() != 4 {
            return None;
        }
        for (entry, value) in row.iter_mut().zip(entries) {
            *entry = match *value {
                DictValue::Integer(v) => v as f64,
                DictValue::Float(v) => v,
                _ => return None,
            };
        }
    }
    Some(DictValue::Matrix(rows))
}

fn invalid(py: Python<'_>, path: &str, message: String, help: &str) -> PyErr {
    to_py(
        py,
        &Error::input(&SourceLocation::key_path(path), message).with_help(help),
    )
}
