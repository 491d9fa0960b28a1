//! The rays of the traversal benchmark: incoherent, like a path tracer's bounce rays, and
//! shadow rays, like its light samples.
//!
//! Camera rays through uniformly random film positions find the first surfaces; from each hit
//! a ray leaves in a direction drawn uniformly on the sphere, offset off the surface as the
//! integrators do. Rays from the same pixel region thus go everywhere, which defeats the
//! coherence that makes camera rays cheap. The shadow rays join the same kind of hits to
//! points drawn on the lights as the path tracer's light samples are (a light chosen by the
//! scene's light sampler, a point by the light's own sampling): segments that end where the
//! lights are, often inside lamps. Seeded, so that two traversal back-ends (our BVH and
//! Embree) are timed on the very same rays.

use glam::Vec2;

use prism_core::camera::CameraModel;
use prism_core::geometry::SurfaceInteraction;
use prism_core::light::{LightQuery, LightSource, Receiver};
use prism_core::math::Ray;
use prism_core::sampling::rng::Pcg32;
use prism_core::sampling::warp::sample_uniform_sphere;
use prism_core::scene::Scene;
use prism_core::spectrum::{SampledWavelengths, WavelengthSampling};

/// `count` incoherent rays of `scene` (fewer only if camera rays never hit anything: then none).
pub fn incoherent_rays(scene: &Scene, count: usize, seed: u64) -> Vec<Ray> {
    rays_from_visible_surfaces(scene, count, seed, |hit, rng| {
        let direction = sample_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
        Some(hit.spawn_ray(direction))
    })
}

/// `count` shadow rays of `scene`, from visible surfaces to points on its lights (none if the
/// scene has no light that can be sampled, or camera rays never hit anything).
pub fn shadow_rays(scene: &Scene, count: usize, seed: u64) -> Vec<Ray> {
    let wavelengths = SampledWavelengths::sample(0.5, WavelengthSampling::default());
    let integrator = scene.integrator.prepare(&scene.world);
    rays_from_visible_surfaces(scene, count, seed, |hit, rng| {
        let receiver = Receiver::surface(hit.p, hit.shading.n);
        let (light, _) = integrator
            .light_sampler()
            .sample(rng.next_f32(), &receiver)?;
        let (u_choice, u) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
        let sample = scene.world.lights[light].sample_incident(LightQuery {
            shapes: &scene.world.geometry.primitives,
            reference: hit.p,
            time: hit.time,
            u_choice,
            u,
            lambda: &wavelengths,
        })?;
        Some(hit.spawn_ray_to(sample.p, sample.n))
    })
}

/// Rays made by `ray_from(hit, rng)` at the first surfaces seen through uniformly random film
/// positions, until there are `count` (fewer only if a fair number of tries in a row give none:
/// an empty view, or no light).
fn rays_from_visible_surfaces(
    scene: &Scene,
    count: usize,
    seed: u64,
    mut ray_from: impl FnMut(&SurfaceInteraction, &mut Pcg32) -> Option<Ray>,
) -> Vec<Ray> {
    let mut rng = Pcg32::seeded(seed);
    let size = scene.film.size.as_vec2();
    let mut rays = Vec::with_capacity(count);
    let mut failures_in_a_row = 0;
    while rays.len() < count && failures_in_a_row < 10_000 {
        let film = Vec2::new(rng.next_f32(), rng.next_f32()) * size;
        let camera_ray = scene.camera.generate_ray(film, Vec2::splat(0.5), 0.0).ray;
        match scene
            .world
            .geometry
            .intersect(&camera_ray)
            .and_then(|hit| ray_from(&hit, &mut rng))
        {
            Some(ray) => {
                failures_in_a_row = 0;
                rays.push(ray);
            }
            None => failures_in_a_row += 1,
        }
    }
    rays
}
