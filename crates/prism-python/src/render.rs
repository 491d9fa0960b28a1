//! `render`: the scene rendered on worker threads while the calling thread, holding the GIL
//! only briefly, reports progress and watches for Ctrl-C. An interruption (or an exception
//! from the progress callback) raises the render's stop flag; the render finishes the tiles in
//! flight, its threads are joined, and the exception is raised.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use crate::error::{IntoPyResult, to_py};
use crate::image::Image;
use crate::scene::Scene;
use prism_core::error::Error;
use prism_core::film::{FilmImages, RenderMetadata};
use prism_core::render::{
    ProgressCounter, RenderOptions, StopRule, StopRuleNames, render as render_scene,
};

/// How often the calling thread checks for signals and reports progress.
const POLL: Duration = Duration::from_millis(100);

/// How to render, read from the keyword arguments of `prism_renderer.render` (a dict): `spp`
/// samples per pixel (None: the sampler's `sample_count`), the random streams of `seed` (None:
/// the sampler's `seed`), `threads` worker threads (None: one per core), and with a
/// `time_limit` in seconds or a `target_error` (the image's mean relative standard error) the
/// render stops at whichever comes first, `spp` then only capping the samples.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct RenderSettings {
    spp: Option<u32>,
    seed: Option<u64>,
    threads: Option<usize>,
    time_limit: Option<f64>,
    target_error: Option<f64>,
}

/// Renders `scene` as `settings` say. `progress`, if given, is called as
/// `progress(samples, total, error)` about ten times a second and once at the end, with the
/// camera samples taken, those the render will take (None when open-ended) and the image's mean
/// relative error (infinite before the first pass). The image is the same for every number of
/// threads.
#[pyfunction]
#[pyo3(signature = (scene, settings, progress = None))]
pub fn render(
    py: Python<'_>,
    scene: &Scene,
    settings: RenderSettings,
    progress: Option<Bound<'_, PyAny>>,
) -> PyResult<Image> {
    let RenderSettings {
        spp,
        seed,
        threads,
        time_limit,
        target_error,
    } = settings;
    if threads == Some(0) {
        return Err(to_py(py, &Error::usage("threads must be at least 1")));
    }
    let loaded = &scene.loaded;
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
    let stop = StopRule::requested(spp, samples_per_pixel, time_limit, target_error, &names)
        .into_py_result(py)?;
    let interrupt = Arc::new(AtomicBool::new(false));
    let counter = Arc::new(ProgressCounter::default());
    let options = RenderOptions {
        samples_per_pixel,
        first_sample: 0,
        initial: None,
        stop,
        interrupt: Some(interrupt.clone()),
        threads,
        seed: seed.unwrap_or(loaded.seed),
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

    let caller = std::thread::current();
    let done = AtomicBool::new(false);
    let (outcome, raised) = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let output = render_scene(&loaded.scene, &options);
            done.store(true, Ordering::Release);
            caller.unpark();
            output
        });
        let mut raised: Option<PyErr> = None;
        // `is_finished` too, in case the render panics before saying it is done.
        while !done.load(Ordering::Acquire) && !worker.is_finished() {
            py.detach(|| std::thread::park_timeout(POLL));
            if raised.is_none()
                && let Err(error) = py.check_signals().and_then(|()| report())
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
    let metadata = RenderMetadata {
        spp: output.samples.end - output.samples.start,
        seed: options.seed,
        seconds: Some(output.elapsed.as_secs_f64()),
    };
    let film = &output.film;
    let (images, aovs) = py.detach(|| {
        let aovs = (film.aov_names.iter().cloned())
            .enumerate()
            .map(|(c, name)| (name, film.aov(c)))
            .collect();
        (FilmImages::of(film), aovs)
    });
    Image::new(py, images, aovs, Some(metadata))
}
