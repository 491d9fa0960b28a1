//! An iteration of vertex connection and merging ([`crate::integrator::vcm`]), run as one
//! sample index of the particle tracer's passes ([`super::particles`]): the light subpaths of
//! every pixel of the full film first, their connections to the camera splatted and their
//! vertices kept in a hash grid ([`PhotonMap`]), then the camera subpaths of every pixel, whose
//! estimate adds to their own pixel.
//!
//! Sample index s is iteration s + 1, with radius r₁ (s + 1)^((α−1)/2). The light subpath of
//! pixel j in iteration s draws its random numbers from an independent stream for (j, s), its
//! camera subpath from the scene's sampler for (j, s) (whose camera sample also gives both the
//! time), and the iteration's wavelengths come from one more stream for s, as `sppm`'s passes'
//! do. The vertices are kept in the order of their pixels and the sums are exact, so the image
//! is bit-identical for any thread count; each index's total is a pixel sum as the particle
//! tracer's, so checkpoints, `--resume` and `prism merge` work as for `bdpt`. The film's
//! variance is the spread of the iterations' estimates, which leaves out the merges' bias:
//! with merging on it is no error bar, and a target error is refused.

use std::ops::Range;

use glam::UVec2;
use rayon::prelude::*;

use super::particles::Collector;
use super::pass::Pass;
use super::sppm::pass_wavelength;
use crate::camera::{CameraModel, CameraRay};
use crate::film::{SplatSums, SplatValue, Splatter};
use crate::integrator::photon_map::PhotonMap;
use crate::integrator::vcm::{Iteration, LightVertex};
use crate::integrator::{LightPathSample, RayCount, SampleContext, VcmIntegrator};
use crate::light::BoundingSphere;
use crate::sampling::rng::hash_u64s;
use crate::sampling::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use crate::spectrum::SampledWavelengths;

/// The stream of the light subpaths' random numbers.
const LIGHT_STREAM: u64 = 0x5643_4d5f_6c69_6768;

/// The first iteration's radius of `vcm` in `scene`: `initial_radius`, or three times the
/// scene's bounding radius over the film's larger side, times `radius_scale`.
pub(super) fn first_radius(scene: &Scene, vcm: &VcmIntegrator) -> f32 {
    let initial = vcm.initial_radius.unwrap_or_else(|| {
        let sphere = BoundingSphere::around_box(scene.world.geometry.bounds());
        let size = scene.film.size;
        3.0 * sphere.radius / size.x.max(size.y) as f32
    });
    initial * vcm.radius_scale
}

/// One task's light subpaths: their kept vertices in pixel order, how many each pixel's
/// subpath kept, their splats and the rays traced.
struct LightTask {
    vertices: Vec<LightVertex>,
    counts: Vec<u32>,
    splats: Vec<SplatValue>,
    rays: u64,
}

impl Pass<'_, '_> {
    /// Traces iteration `index` of `vcm` for the full film's pixels, in `tasks` of pixels
    /// (row-major indices), adding its splats and pixel estimates to `image`; returns the rays
    /// traced, or None when the pass was cancelled.
    pub(super) fn trace_vcm_iteration(
        &self,
        vcm: &VcmIntegrator,
        splatter: &Splatter,
        tasks: &[Range<u32>],
        index: u32,
        image: &mut SplatSums,
    ) -> Option<u64> {
        let scene = self.estimator.scene;
        let film = &scene.film;
        let lambda = SampledWavelengths::sample(
            pass_wavelength(self.options.seed, index),
            film.wavelength_sampling,
        );
        let iteration = Iteration {
            radius: first_radius(scene, vcm)
                * (f64::from(index) + 1.0).powf(0.5 * (f64::from(vcm.alpha) - 1.0)) as f32,
            light_paths: (film.size.x * film.size.y) as f32,
            merging: vcm.merging,
        };
        let traced: Vec<Option<LightTask>> = tasks
            .par_iter()
            .map(|pixels| self.trace_light_task(vcm, splatter, &iteration, &lambda, pixels, index))
            .collect();
        let mut rays = 0;
        let mut vertices = Vec::new();
        let mut starts = vec![0u32];
        for task in traced {
            let task = task?;
            image.add(&task.splats);
            rays += task.rays;
            vertices.extend(task.vertices);
            for count in task.counts {
                starts.push(starts[starts.len() - 1] + count);
            }
        }
        let map = vcm
            .merging
            .then(|| PhotonMap::new(&vertices, iteration.radius));
        let camera = CameraTask {
            vcm,
            splatter,
            iteration: &iteration,
            lambda: &lambda,
            vertices: &vertices,
            starts: &starts,
            map: map.as_ref(),
            index,
        };
        let traced: Vec<Option<(Vec<SplatValue>, u64)>> = tasks
            .par_iter()
            .map(|pixels| self.trace_camera_task(&camera, pixels))
            .collect();
        for task in traced {
            let (values, task_rays) = task?;
            image.add(&values);
            rays += task_rays;
        }
        Some(rays)
    }

    /// The light subpaths of iteration `index` keyed by the pixels `pixels`.
    fn trace_light_task(
        &self,
        vcm: &VcmIntegrator,
        splatter: &Splatter,
        iteration: &Iteration,
        lambda: &SampledWavelengths,
        pixels: &Range<u32>,
        index: u32,
    ) -> Option<LightTask> {
        if self.cancel.raised() {
            return None;
        }
        let scene = self.estimator.scene;
        let film = &scene.film;
        let mut camera_sampler = Sampler::new(
            scene.sampler.kind,
            self.options.samples_per_pixel,
            self.options.seed,
        );
        let mut sampler = Sampler::new(
            SamplerKind::Independent,
            1,
            hash_u64s(&[self.options.seed, LIGHT_STREAM]),
        );
        let mut count = RayCount::default();
        let mut collector = Collector::new(splatter, film.crop, *lambda);
        let mut vertices = Vec::new();
        let mut counts = Vec::with_capacity(pixels.len());
        for pixel in pixels.clone() {
            let pixel = UVec2::new(pixel % film.size.x, pixel / film.size.x);
            let (primary, time, time_weight) = self.start_sample(&mut camera_sampler, pixel, index);
            collector.time_weight = time_weight;
            sampler.start_pixel_sample(pixel, index);
            let sample = LightPathSample {
                camera: &scene.camera,
                lambda,
                time,
                u_lens: primary.lens,
            };
            let ctx = &mut SampleContext {
                prepared: &self.estimator.integrator,
                sampler: &mut sampler,
                count: &mut count,
            };
            let before = vertices.len();
            vcm.trace_light_path(ctx, &sample, iteration, &mut vertices, &mut collector);
            counts.push((vertices.len() - before) as u32);
        }
        Some(LightTask {
            vertices,
            counts,
            splats: collector.values,
            rays: count.rays,
        })
    }

    /// The camera subpaths of the pixels `pixels` (row-major indices of the full film): their
    /// estimates for their own pixels, and the rays traced.
    fn trace_camera_task(
        &self,
        camera: &CameraTask,
        pixels: &Range<u32>,
    ) -> Option<(Vec<SplatValue>, u64)> {
        if self.cancel.raised() {
            return None;
        }
        let scene = self.estimator.scene;
        let film = &scene.film;
        let mut sampler = Sampler::new(
            scene.sampler.kind,
            self.options.samples_per_pixel,
            self.options.seed,
        );
        let mut count = RayCount::default();
        let mut collector = Collector::new(camera.splatter, film.crop, *camera.lambda);
        for key in pixels.clone() {
            let pixel = UVec2::new(key % film.size.x, key / film.size.x);
            let (primary, time, time_weight) = self.start_sample(&mut sampler, pixel, camera.index);
            let (film_position, filter_weight) = self.estimator.film_position(pixel, primary.film);
            let CameraRay { ray, weight } =
                scene.camera.generate_ray(film_position, primary.lens, time);
            let sample = LightPathSample {
                camera: &scene.camera,
                lambda: camera.lambda,
                time,
                u_lens: primary.lens,
            };
            let ctx = &mut SampleContext {
                prepared: &self.estimator.integrator,
                sampler: &mut sampler,
                count: &mut count,
            };
            let light_path = &camera.vertices
                [camera.starts[key as usize] as usize..camera.starts[key as usize + 1] as usize];
            let radiance = camera.vcm.trace_camera_path(
                ctx,
                &sample,
                ray,
                camera.iteration,
                light_path,
                camera.map,
            );
            let scale = weight * time_weight * filter_weight;
            let xyz = camera.lambda.to_xyz(&radiance).map(|v| v * scale);
            collector.add_to_pixel(pixel, xyz);
        }
        Some((collector.values, count.rays))
    }
}

/// What the camera subpaths of an iteration read.
struct CameraTask<'a> {
    vcm: &'a VcmIntegrator,
    splatter: &'a Splatter,
    iteration: &'a Iteration,
    lambda: &'a SampledWavelengths,
    /// The light subpaths' kept vertices in pixel order, pixel j's from `starts[j]` to
    /// `starts[j + 1]`.
    vertices: &'a [LightVertex],
    starts: &'a [u32],
    map: Option<&'a PhotonMap<'a, LightVertex>>,
    index: u32,
}
