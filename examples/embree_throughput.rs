//! Incoherent ray throughput of our BVH and of Embree on the same rays (cargo feature `embree`).
//!
//!     cargo run --release --features embree --example embree_throughput [-- TRIANGLES [RAYS]]
//!
//! The scene is one finely tessellated bumpy sphere (a latitude–longitude grid of about
//! TRIANGLES triangles, default 1 M, radius 1 ± 0.05); the rays start at uniform points of its
//! bounding box and go in uniform directions (default 1 M rays). Each backend traces all rays to
//! their closest hit on one thread, three times; the best time counts. Both must find the same
//! number of hits, up to the odd ray through an edge or vertex.

use std::f32::consts::{PI, TAU};
use std::time::Instant;

use prism::geometry::{Accel, Geometry, Shape, TraceReport, TriangleMesh};
use prism::math::{Ray, Vec2, Vec3};
use prism::sampling::rng::Pcg32;
use prism::sampling::warp::sample_uniform_sphere;

/// A sphere displaced by r = 1 + 0.05·sin(13θ)·cos(17φ) on a `rings` × 2·`rings` grid.
fn bumpy_sphere(rings: u32) -> TriangleMesh {
    let segments = 2 * rings;
    let mut positions = Vec::new();
    for i in 0..=rings {
        let theta = PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = TAU * j as f32 / segments as f32;
            let r = 1.0 + 0.05 * (13.0 * theta).sin() * (17.0 * phi).cos();
            positions.push(
                r * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ),
            );
        }
    }
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let a = i * (segments + 1) + j;
            let b = a + segments + 1;
            triangles.push([a, b, a + 1]);
            triangles.push([a + 1, b, b + 1]);
        }
    }
    TriangleMesh::new(positions, None, None, triangles, false)
}

/// The best of three runs.
fn best_of_three(geometry: &Geometry, rays: &[Ray]) -> TraceReport {
    (0..3)
        .map(|_| geometry.trace(rays))
        .min_by_key(|report| report.elapsed)
        .expect("three runs")
}

fn main() -> prism::error::Result<()> {
    let mut args = std::env::args().skip(1);
    let triangles: u32 = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let ray_count: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    // rings × 2·rings quads of two triangles.
    let rings = ((triangles as f64 / 4.0).sqrt().round() as u32).max(2);

    let start = Instant::now();
    let mut geometry = Geometry::new(vec![Shape::Mesh(bumpy_sphere(rings))]);
    println!(
        "{} triangles; our BVH built in {:.2} s",
        geometry.primitive_count(),
        start.elapsed().as_secs_f64()
    );
    let (lo, hi) = geometry.bounds().expect("a non-empty scene");
    let mut rng = Pcg32::seeded(1);
    let rays: Vec<Ray> = (0..ray_count)
        .map(|_| {
            let mut u = || rng.next_f32();
            let o = lo + (hi - lo) * Vec3::new(u(), u(), u());
            let d = sample_uniform_sphere(Vec2::new(u(), u()));
            Ray::new(o, d, f32::INFINITY, 0.0)
        })
        .collect();

    let bvh = best_of_three(&geometry, &rays);
    let start = Instant::now();
    geometry.set_accel(Accel::Embree)?;
    println!("Embree built in {:.2} s", start.elapsed().as_secs_f64());
    let embree = best_of_three(&geometry, &rays);

    for (name, report) in [("our BVH", bvh), ("Embree", embree)] {
        println!(
            "{name:>8}: {} rays, {} hits, {:.3} s, {:.2} M rays/s (one thread)",
            report.rays,
            report.hits,
            report.elapsed.as_secs_f64(),
            report.rays_per_second() / 1e6
        );
    }
    println!(
        "our BVH / Embree: {:.2}×",
        bvh.rays_per_second() / embree.rays_per_second()
    );
    Ok(())
}
