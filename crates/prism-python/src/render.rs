//! `render`: the scene rendered on worker threads while the calling thread, holding the GIL
//! only briefly, reports progress, hands the developing image to a preview callback and watches
//! for Ctrl-C. An interruption (or an exception from a callback) raises the render's stop flag;
//! the render finishes the tiles in flight, its threads are joined, and the exception is raised.
//! A crop window, checkpoints, resuming and sample ranges work as
//! `prism render --crop/--checkpoint/--resume/--sample-range` do, with the same state files; a
//! render of a sample range gives its [`RenderState`] for [`crate::render_state::merge`].

use std::cell::Cell;
use std::ops::Range;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use crate::error::{IntoPyResult, to_py};
use crate::image::Image;
use crate::render_state::RenderState;
use crate::scene::Scene;
use glam::UVec2;
use prism_core::error::Error;
use prism_core::film::{CropWindow, Film, FilmImages, RenderMetadata};
use prism_core::render::resume::Continuation;
use prism_core::render::sppm;
use prism_core::render::{
    Checkpoints, Preview, ProgressCounter, RenderOptions, Snapshot, StopRule, StopRuleNames,
    render_with_preview,
};
use prism_mitsuba::LoadedScene;

/// How often the calling thread checks for signals and reports progress.
const POLL: Duration = Duration::from_millis(100);

/// How to render, read from the keyword arguments of `prism_renderer.render` (a dict): `spp`
/// samples per pixel (None: the sampler's `sample_count`), the random streams of `seed` (None:
/// the sampler's `seed`), `threads` worker threads (None: one per core), and with a
/// `time_limit` in seconds or a `target_error` (the image's mean relative standard error) the
/// render stops at whichever comes first, `spp` then only capping the samples; `sensor` is the
/// sensor to look through. `crop` (x0, y0, x1, y1) renders the pixels x0 ≤ x < x1,
/// y0 ≤ y < y1 only; `checkpoint` saves the render state there every `checkpoint_every` seconds
/// and at the end; `resume` continues the state saved there (and saves to it, without a
/// `checkpoint`). `sample_range` (start, end) takes the sample indices start ≤ i < end of every
/// pixel only, and the render gives their state rather than an image.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct RenderSettings {
    spp: Option<u32>,
    seed: Option<u64>,
    threads: Option<usize>,
    time_limit: Option<f64>,
    target_error: Option<f64>,
    sensor: SensorChoice,
    crop: Option<[u32; 4]>,
    checkpoint: Option<PathBuf>,
    checkpoint_every: f64,
    resume: Option<PathBuf>,
    sample_range: Option<(u32, u32)>,
}

/// A sensor of the scene, by its index from 0 in document order or by its id.
#[derive(FromPyObject)]
pub enum SensorChoice {
    Index(usize),
    Id(String),
}

/// The callbacks of a render: `progress(samples, total, error)` and `preview(image)`.
struct Callbacks<'py> {
    progress: Option<Bound<'py, PyAny>>,
    preview: Option<Bound<'py, PyAny>>,
}

/// Renders `scene` as `settings` say. `progress`, if given, is called as
/// `progress(samples, total, error)` about ten times a second and once at the end, with the
/// camera samples taken, those the render will take (None when open-ended) and the image's mean
/// relative error (infinite before the first pass). `preview`, if given, is called as
/// `preview(image)` with the developing [`Image`] after passes (the newest, when several
/// finished since the last call) and last with the image returned, unless the last pass's
/// image, equal to it, was shown already. The image is the same for every number of threads.
/// With a crop window the scene is held exclusively while it renders. A render of a
/// `sample_range` returns its [`RenderState`] in place of the image.
#[pyfunction]
#[pyo3(signature = (scene, settings, progress = None, preview = None))]
pub fn render(
    py: Python<'_>,
    scene: &Bound<'_, Scene>,
    settings: RenderSettings,
    progress: Option<Bound<'_, PyAny>>,
    preview: Option<Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    select_sensor(py, scene, &settings.sensor)?;
    let callbacks = Callbacks { progress, preview };
    let Some([x0, y0, x1, y1]) = settings.crop else {
        return render_loaded(py, &scene.borrow().loaded, settings, callbacks);
    };
    let mut scene = scene.try_borrow_mut()?;
    let film = &mut scene.loaded.scene.film;
    if !(x0 < x1 && y0 < y1 && x1 <= film.size.x && y1 <= film.size.y) {
        return Err(to_py(
            py,
            &Error::usage(format!(
                "the crop window ({x0}, {y0}, {x1}, {y1}) is empty or reaches outside the \
                 {}×{} film",
                film.size.x, film.size.y
            ))
            .with_help("give crop=(x0, y0, x1, y1) with x0 < x1 <= width, y0 < y1 <= height"),
        ));
    }
    let whole = film.crop;
    film.crop = CropWindow {
        offset: UVec2::new(x0, y0),
        size: UVec2::new(x1 - x0, y1 - y0),
    };
    let image = render_loaded(py, &scene.loaded, settings, callbacks);
    scene.loaded.scene.film.crop = whole;
    image
}

/// Renders a loaded scene (its sensor chosen and its crop window set) as [`render`] does.
fn render_loaded(
    py: Python<'_>,
    loaded: &LoadedScene,
    settings: RenderSettings,
    callbacks: Callbacks<'_>,
) -> PyResult<Py<PyAny>> {
    let RenderSettings {
        spp,
        seed,
        threads,
        time_limit,
        target_error,
        sensor: _,
        crop: _,
        checkpoint,
        checkpoint_every,
        resume,
        sample_range,
    } = settings;
    let Callbacks { progress, preview } = callbacks;
    if threads == Some(0) {
        return Err(to_py(py, &Error::usage("threads must be at least 1")));
    }
    if !(checkpoint_every > 0.0 && checkpoint_every.is_finite()) {
        return Err(to_py(
            py,
            &Error::usage("checkpoint_every must be a positive number of seconds"),
        ));
    }
    let samples_per_pixel = loaded
        .scene
        .sampler
        .kind
        .sample_count(spp.unwrap_or(loaded.scene.sampler.samples_per_pixel));
    let names = StopRuleNames {
        spp: "spp",
        time_limit: "time_limit",
        target_error: "target_error",
    };
    let mut stop = StopRule::requested(spp, samples_per_pixel, time_limit, target_error, &names)
        .into_py_result(py)?;
    if let Some((start, end)) = sample_range {
        if start >= end {
            return Err(to_py(
                py,
                &Error::usage(format!(
                    "the sample range ({start}, {end}) is empty: end must exceed start"
                )),
            ));
        }
        stop.sample_end = Some(end);
    }
    let range_start = sample_range.map_or(0, |(start, _)| start);
    let seed = seed.unwrap_or(loaded.seed);
    let strata = loaded.scene.strata(samples_per_pixel);
    let mut continuation = Continuation::new(&loaded.scene, seed, strata);
    let (first_sample, initial) = match &resume {
        Some(path) => {
            let (end, sums) = py
                .detach(|| continuation.resume(path, range_start))
                .into_py_result(py)?;
            (end, Some(sums))
        }
        None => (range_start, None),
    };
    if let Some(end) = sppm::chain_end(&loaded.scene, range_start) {
        stop.sample_end = Some(end);
    }
    if let Some(end) = stop.sample_end
        && first_sample >= end
    {
        return Err(to_py(
            py,
            &Error::usage(format!(
                "nothing to render: the samples before {end} are done already"
            ))
            .with_help("ask for more with spp"),
        ));
    }
    let state_path = checkpoint.or(resume);
    let interrupt = Arc::new(AtomicBool::new(false));
    let counter = Arc::new(ProgressCounter::default());
    let options = RenderOptions {
        samples_per_pixel,
        first_sample,
        initial,
        stop,
        interrupt: Some(interrupt.clone()),
        threads,
        seed,
        progress: Some(counter.clone()),
    };
    let report = || -> PyResult<()> {
        match &progress {
            Some(callback) => callback
                .call1((counter.samples(), counter.total(), counter.relative_error()))
                .map(drop),
            None => Ok(()),
        }
    };
    // The newest pass's image not yet shown, with its samples.
    let developing: Mutex<Option<(Film, Range<u32>)>> = Mutex::new(None);
    // The samples of the last image shown.
    let shown: Cell<Option<Range<u32>>> = Cell::new(None);
    let start = Instant::now();
    let show_developing = || -> PyResult<()> {
        let newest = developing
            .lock()
            .expect("no thread panics holding it")
            .take();
        match (&preview, newest) {
            (Some(callback), Some((film, samples))) => {
                shown.set(Some(samples));
                let image = image_of(py, &film, seed, start.elapsed().as_secs_f64())?;
                callback.call1((image,)).map(drop)
            }
            _ => Ok(()),
        }
    };

    let previewing = preview.is_some();
    let caller = std::thread::current();
    let done = AtomicBool::new(false);
    let (outcome, raised) = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let mut write = |snapshot: &Snapshot| match &state_path {
                Some(path) => continuation.save(snapshot, path),
                None => Ok(()),
            };
            let checkpoints = state_path.as_ref().map(|_| Checkpoints {
                every: Duration::from_secs_f64(checkpoint_every),
                write: &mut write,
            });
            let mut keep = |snapshot: &Snapshot| {
                let film = snapshot.film(&loaded.scene);
                *developing.lock().expect("no thread panics holding it") =
                    Some((film, snapshot.samples.clone()));
                caller.unpark();
                Ok(())
            };
            let output = render_with_preview(
                &loaded.scene,
                &options,
                checkpoints,
                previewing.then_some(&mut keep as Preview),
            );
            done.store(true, Ordering::Release);
            caller.unpark();
            output
        });
        let mut raised: Option<PyErr> = None;
        // `is_finished` too, in case the render panics before saying it is done.
        while !done.load(Ordering::Acquire) && !worker.is_finished() {
            py.detach(|| std::thread::park_timeout(POLL));
            if raised.is_none()
                && let Err(error) = (py.check_signals())
                    .and_then(|()| report())
                    .and_then(|()| show_developing())
            {
                interrupt.store(true, Ordering::SeqCst);
                raised = Some(error);
            }
        }
        (py.detach(|| worker.join()), raised)
    });
    if let Some(error) = raised {
        return Err(error);
    }
    let output = outcome
        .map_err(|_| PyRuntimeError::new_err("the render's thread panicked"))?
        .into_py_result(py)?;
    report()?;
    if sample_range.is_some() {
        let snapshot = Snapshot {
            samples: output.samples,
            pixels: &output.film.pixels,
            aovs: &output.film.aovs,
            integrator_state: output.integrator_state.as_ref(),
        };
        let state = continuation.state(&snapshot);
        return Ok(Py::new(py, RenderState { state })?.into_any());
    }
    let image = Py::new(
        py,
        image_of(py, &output.film, seed, output.elapsed.as_secs_f64())?,
    )?;
    if let Some(callback) = &preview
        && shown.take() != Some(output.samples)
    {
        callback.call1((image.clone_ref(py),))?;
    }
    Ok(image.into_any())
}

/// The image of `film`, rendered with the random streams of `seed` in `seconds`; its samples
/// per pixel are those its pixels hold (a resumed render's included).
fn image_of(py: Python<'_>, film: &Film, seed: u64, seconds: f64) -> PyResult<Image> {
    let metadata = RenderMetadata {
        spp: film.pixels.first().map_or(0, |p| p.samples) as u32,
        seed,
        seconds: Some(seconds),
    };
    let (images, aovs) = py.detach(|| {
        let aovs = (film.aov_names.iter().cloned())
            .enumerate()
            .map(|(c, name)| (name, film.aov(c)))
            .collect();
        (FilmImages::of(film), aovs)
    });
    Image::new(py, images, aovs, Some(metadata))
}

/// Makes `scene` seen through the sensor `choice` names; changing it needs the scene not to be
/// rendering.
fn select_sensor(py: Python<'_>, scene: &Bound<'_, Scene>, choice: &SensorChoice) -> PyResult<()> {
    let index = match choice {
        SensorChoice::Index(index) => *index,
        SensorChoice::Id(id) => scene.borrow().loaded.find_sensor(id).into_py_result(py)?,
    };
    if scene.borrow().loaded.selected_sensor() == index {
        return Ok(());
    }
    let mut scene = scene.try_borrow_mut().map_err(|_| {
        to_py(
            py,
            &Error::usage("the scene is rendering: render through another of its sensors after that render ends"),
        )
    })?;
    scene.loaded.select_sensor(index).into_py_result(py)
}
