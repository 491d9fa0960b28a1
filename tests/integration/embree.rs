//! Embree (cargo feature `embree`) renders the same image as our BVH.

use std::path::Path;

use prism::accel::Accel;
use prism_core::film::stats::variance_of_mean;
use prism_core::render::{RenderOptions, render};
use prism_mitsuba::load_scene;

/// The image's mean luminance and the variance of that mean, for the Cornell box rendered at
/// 64×64, 16 spp with `seed`, traced by `accel`.
fn cornell_box_mean(accel: Accel, seed: u64) -> (f64, f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    let defines = [("resx", "64"), ("resy", "64"), ("spp", "16")]
        .map(|(name, value)| (name.to_string(), value.to_string()));
    let mut scene = load_scene(&path, &defines).unwrap().scene;
    accel.apply(&mut scene.world.geometry).unwrap();
    assert_eq!(Accel::of(&scene.world.geometry), accel);
    let film = render(&scene, &RenderOptions::fixed(16, seed, Some(2)))
        .unwrap()
        .film;
    let n = film.pixels.len() as f64;
    let mean = film.pixels.iter().map(|p| p.mean()[1]).sum::<f64>() / n;
    let variance = film
        .pixels
        .iter()
        .map(|p| variance_of_mean(p, 1))
        .sum::<f64>()
        / (n * n);
    (mean, variance)
}

/// Two independent renders (different seeds), one per backend, agree within 4 standard errors;
/// with the same seed the means agree far more closely, the paths being nearly the same.
#[test]
fn cornell_box_has_the_same_mean_with_embree() {
    let (bvh, bvh_variance) = cornell_box_mean(Accel::Bvh, 1);
    let (embree, embree_variance) = cornell_box_mean(Accel::Embree, 2);
    let sigma = (bvh_variance + embree_variance).sqrt();
    assert!(bvh > 0.0 && sigma > 0.0 && sigma < 0.05 * bvh);
    assert!(
        (bvh - embree).abs() < 4.0 * sigma,
        "mean Y {bvh} (BVH) against {embree} (Embree), σ of the difference {sigma}"
    );
    let (same_seed, _) = cornell_box_mean(Accel::Embree, 1);
    assert!(
        (bvh - same_seed).abs() < 0.1 * sigma,
        "mean Y {bvh} (BVH) against {same_seed} (Embree, same seed), σ {sigma}"
    );
}
