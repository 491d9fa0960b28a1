//! Render states for a render farm: `render(..., sample_range=(start, end))` returns the exact
//! pixel sums of those samples as a [`RenderState`], and [`merge`] adds the states of disjoint
//! ranges into the state of one render of all their samples, as `prism render --sample-range`
//! and `prism merge` do with the same core functions and the same files. A state travels
//! between processes as the bytes of its file (it pickles), so any task engine can carry it.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::error::{IntoPyResult, to_py};
use crate::image::Image;
use prism_core::error::Error;
use prism_core::film::{Film, FilmImages, RenderMetadata};
use prism_core::render::state::RenderState as State;

/// The exact pixel sums of a render over some sample ranges, with what they belong to (the
/// scene's fingerprint, the seed, the sampler and its samples per pixel, the film and crop).
#[pyclass(module = "prism_renderer", frozen)]
pub struct RenderState {
    pub state: State,
}

/// The name messages give a state decoded from memory.
const FROM_BYTES: &str = "<bytes>";

#[pymethods]
impl RenderState {
    /// Reads a state file written by `prism render --checkpoint` or [`RenderState::write`].
    #[staticmethod]
    fn read(py: Python<'_>, path: PathBuf) -> PyResult<RenderState> {
        let state = py.detach(|| State::read(&path)).into_py_result(py)?;
        Ok(RenderState { state })
    }

    /// The state whose file holds `data` (the bytes [`RenderState::to_bytes`] gives).
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<RenderState> {
        let state = py
            .detach(|| State::decode(data, Path::new(FROM_BYTES)))
            .into_py_result(py)?;
        Ok(RenderState { state })
    }

    /// The bytes of the state's file.
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &py.detach(|| self.state.encode()))
    }

    /// Writes the state's file atomically (`prism merge` and `prism render --resume` read it).
    fn write(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.state.write(&path)).into_py_result(py)
    }

    /// The sample index ranges every pixel holds, as `(start, end)` pairs, sorted.
    #[getter]
    fn ranges(&self) -> Vec<(u32, u32)> {
        (self.state.ranges.iter())
            .map(|range| (range.start, range.end))
            .collect()
    }

    /// Samples per pixel the state holds.
    #[getter]
    fn spp(&self) -> u32 {
        self.state.sample_count()
    }

    /// The seed of the render's random numbers.
    #[getter]
    fn seed(&self) -> u64 {
        self.state.identity.seed
    }

    /// The image of the state's sums, as `prism merge` writes it.
    fn image(&self, py: Python<'_>) -> PyResult<Image> {
        image_of(py, &self.state)
    }

    /// Pickles as the bytes of its file.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let from_bytes = py.get_type::<RenderState>().getattr("from_bytes")?;
        Ok((from_bytes, (slf.get().to_bytes(py),)))
    }

    fn __repr__(&self) -> String {
        let id = &self.state.identity;
        let ranges: Vec<String> = (self.state.ranges.iter())
            .map(|range| format!("{}..{}", range.start, range.end))
            .collect();
        format!(
            "RenderState({}×{} pixels, samples {}, seed {})",
            id.crop.size.x,
            id.crop.size.y,
            ranges.join(", "),
            id.seed
        )
    }
}

/// The image of `state`'s sums: its film holds them, and its metadata their samples per pixel
/// and seed (no duration: the samples may come from many machines).
fn image_of(py: Python<'_>, state: &State) -> PyResult<Image> {
    let identity = &state.identity;
    let mut film = Film::with_aovs(identity.film_size, identity.crop, state.aov_names.clone());
    if film.pixels.len() != state.pixels.len() || film.aovs.len() != state.aovs.len() {
        return Err(to_py(
            py,
            &Error::usage("the state's sums do not match its crop window"),
        ));
    }
    film.pixels.clone_from(&state.pixels);
    film.aovs.clone_from(&state.aovs);
    let metadata = RenderMetadata {
        spp: state.sample_count(),
        seed: identity.seed,
        seconds: None,
    };
    let (images, aovs) = py.detach(|| {
        let aovs = (film.aov_names.iter().cloned())
            .enumerate()
            .map(|(c, name)| (name, film.aov(c)))
            .collect();
        (FilmImages::of(&film), aovs)
    });
    Image::new(py, images, aovs, Some(metadata))
}

/// A state to merge: a [`RenderState`] or the path of a state file.
#[derive(FromPyObject)]
pub enum StateOrPath {
    State(Py<RenderState>),
    Path(PathBuf),
}

/// The state of one render of all the samples of `states` (each a [`RenderState`] or a state
/// file's path), whose sample ranges must be disjoint and whose renders the same, as
/// `prism merge` merges them; bit for bit the sums of a render of all their samples.
#[pyfunction]
pub fn merge(py: Python<'_>, states: Vec<StateOrPath>) -> PyResult<RenderState> {
    let mut read = Vec::with_capacity(states.len());
    let mut names = Vec::with_capacity(states.len());
    for (i, state) in states.iter().enumerate() {
        match state {
            StateOrPath::State(state) => {
                read.push(state.get().state.clone());
                names.push(PathBuf::from(format!("states[{i}]")));
            }
            StateOrPath::Path(path) => {
                read.push(py.detach(|| State::read(path)).into_py_result(py)?);
                names.push(path.clone());
            }
        }
    }
    let paths: Vec<&Path> = names.iter().map(PathBuf::as_path).collect();
    let state = py
        .detach(|| State::merge(&read, &paths))
        .into_py_result(py)?;
    Ok(RenderState { state })
}
