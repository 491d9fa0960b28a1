//! The rays of the traversal benchmark: incoherent, like a path tracer's bounce rays.
//!
//! Camera rays through uniformly random film positions find the first surfaces; from each hit
//! a ray leaves in a direction drawn uniformly on the sphere, offset off the surface as the
//! integrators do. Rays from the same pixel region thus go everywhere, which defeats the
//! coherence that makes camera rays cheap. Seeded, so that two traversal back-ends (our BVH and
//! Embree) are timed on the very same rays.

use glam::Vec2;

use crate::math::Ray;
use crate::sampling::rng::Pcg32;
use crate::sampling::warp::sample_uniform_sphere;
use crate::scene::Scene;

/// `count` incoherent rays of `scene` (fewer only if camera rays never hit anything: then none).
pub fn incoherent_rays(scene: &Scene, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Pcg32::seeded(seed);
    let size = scene.film.size.as_vec2();
    let mut rays = Vec::with_capacity(count);
    // Give up if a fair number of camera rays find nothing at all (an empty view).
    let mut misses_in_a_row = 0;
    while rays.len() < count && misses_in_a_row < 10_000 {
        let film = Vec2::new(rng.next_f32(), rng.next_f32()) * size;
        let camera_ray = scene.camera.generate_ray(film, Vec2::splat(0.5), 0.0);
        let Some(hit) = scene.geometry.intersect(&camera_ray) else {
            misses_in_a_row += 1;
            continue;
        };
        misses_in_a_row = 0;
        let direction = sample_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
        rays.push(hit.spawn_ray(direction));
    }
    rays
}
