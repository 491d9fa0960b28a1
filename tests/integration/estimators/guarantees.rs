//! The render guarantees every estimator keeps, as checks their tests call: the same film for
//! any thread count, and a render resumed or merged from parts equal to one render.

use prism_core::film::Film;
use prism_core::render::resume::InitialState;
use prism_core::render::{RenderOptions, StopRule, render};
use prism_core::scene::Scene;

use crate::common::scenes::render_film;

/// One and two threads give the same film of `spp` samples per pixel to the last bit, and
/// another seed another film.
pub(super) fn assert_bit_identical_for_any_thread_count(scene: &Scene, spp: u32) {
    let one = render_film(scene, spp, 42, Some(1));
    let two = render_film(scene, spp, 42, Some(2));
    assert!(one.pixels.iter().any(|p| p.sum(1) > 0.0), "black");
    assert_eq!(one.pixels, two.pixels);
    assert_ne!(one.pixels, render_film(scene, spp, 43, Some(2)).pixels);
}

/// A render continued part by part from its state (as `--resume` does), and the renders of the
/// parts merged (as `prism merge` does), equal one render of all the samples; the parts are the
/// sample ranges between 0 and each of the increasing `ends` in turn.
pub(super) fn assert_resumed_and_merged_equal_one_render(scene: &Scene, ends: &[u32]) {
    let spp = *ends.last().expect("at least one part");
    let whole = render_film(scene, spp, 7, Some(2));
    let mut initial = None;
    let mut merged: Option<Film> = None;
    let mut start = 0;
    for &end in ends {
        let mut options = RenderOptions::fixed(spp, 7, Some(2));
        options.first_sample = start;
        options.stop = StopRule::samples(end);
        let part = render(scene, &options).unwrap().film;
        options.initial = initial.take();
        let resumed = render(scene, &options).unwrap().film;
        initial = Some(InitialState::sums(resumed.pixels, resumed.aovs));
        match &mut merged {
            None => merged = Some(part),
            Some(m) => {
                for (a, b) in m.pixels.iter_mut().zip(&part.pixels) {
                    a.merge(b);
                }
            }
        }
        start = end;
    }
    assert_eq!(merged.unwrap().pixels, whole.pixels, "merged");
    assert_eq!(initial.unwrap().pixels, whole.pixels, "resumed");
}
