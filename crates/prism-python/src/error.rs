//! Prism's errors as the Python exception `PrismError`, whose `file`, `line` and `column` say
//! where the input is wrong (for a dictionary: `file` is the entry's key path, `line` and
//! `column` are None).

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

use prism_core::error::{Error, ErrorKind};

create_exception!(
    prism_renderer,
    PrismError,
    PyException,
    "An error in a scene, a file it uses or an argument, with its location: `file`, `line` and \
     `column` (for a dictionary, `file` is the entry's key path such as \
     `scene.sphere.bsdf.reflectance` and `line` and `column` are None), `message`, `help` and \
     `kind` (\"input\" or \"io\")."
);

/// The Python exception for `error`; its text is the one the command line prints.
pub fn to_py(py: Python<'_>, error: &Error) -> PyErr {
    let exception = PrismError::new_err(error.to_string());
    let value = exception.value(py);
    let (file, line, column) = match &error.location {
        None => (None, None, None),
        Some(location) if location.is_key_path() => {
            (Some(location.file.display().to_string()), None, None)
        }
        Some(location) => (
            Some(location.file.display().to_string()),
            Some(location.line),
            Some(location.column),
        ),
    };
    let kind = match error.kind {
        ErrorKind::Input => "input",
        ErrorKind::Io => "io",
    };
    let attributes = [
        value.setattr("file", file),
        value.setattr("line", line),
        value.setattr("column", column),
        value.setattr("message", &error.message),
        value.setattr("help", error.help.as_deref()),
        value.setattr("kind", kind),
    ];
    match attributes.into_iter().find_map(Result::err) {
        Some(failure) => failure,
        None => exception,
    }
}

/// Converts a Prism result into a Python one.
pub trait IntoPyResult<T> {
    fn into_py_result(self, py: Python<'_>) -> PyResult<T>;
}

impl<T> IntoPyResult<T> for prism_core::error::Result<T> {
    fn into_py_result(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|error| to_py(py, &error))
    }
}
