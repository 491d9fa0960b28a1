//! `prism bench` and the measurements behind it: the JSON it prints is complete and
//! self-consistent, geometry memory stays within the budget of 100 bytes per triangle
//! (BVH included), and the traversal benchmark's rays are incoherent.

use std::process::Command;

use glam::Vec3;
use prism::bench::rays::{incoherent_rays, shadow_rays};
use prism_core::geometry::{AggregateElement, Geometry, Shape, TriangleMesh};
use prism_core::scene::Scene;
use prism_mitsuba::load_scene;

/// The number `key` of a JSON object.
fn field(json: &serde_json::Value, key: &str) -> f64 {
    json[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number {key} in {json}"))
}

/// The suite needs nothing outside the repository: all six scenes are listed, with files that
/// exist.
#[test]
fn bench_lists_its_six_scenes_from_the_repository() {
    let cache = std::env::temp_dir().join(format!("prism-bench-list-{}", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(["bench", "--list", "--cache"])
        .arg(&cache)
        .current_dir(std::env::temp_dir())
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    let stdout = String::from_utf8(output.stdout).unwrap();
    let names: Vec<&str> = stdout
        .lines()
        .map(|l| l.split('\t').next().unwrap())
        .collect();
    assert_eq!(names, prism::bench::SCENE_NAMES, "{stdout}");
    for line in stdout.lines() {
        let file = line.split('\t').nth(1).unwrap();
        assert!(std::path::Path::new(file).is_file(), "{line}");
    }
    let _ = std::fs::remove_dir_all(&cache);
}

/// `--only` with a scene's whole name selects that scene alone; any other text, the names
/// containing it.
#[test]
fn only_a_whole_name_selects_that_scene_alone() {
    let cache = std::env::temp_dir().join(format!("prism-bench-only-{}", std::process::id()));
    let listed = |pattern: &str| -> Vec<String> {
        let output = Command::new(env!("CARGO_BIN_EXE_prism"))
            .args(["bench", "--list", "--only", pattern, "--cache"])
            .arg(&cache)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        assert!(output.status.success(), "{output:?}");
        String::from_utf8(output.stdout)
            .unwrap()
            .lines()
            .map(|l| l.split('\t').next().unwrap().to_string())
            .collect()
    };
    assert_eq!(listed("smoke-box"), ["smoke-box"]);
    assert_eq!(listed("smoke"), ["smoke-box", "smoke-box-volpathmis"]);
    assert_eq!(listed("veach"), ["veach-mis", "veach-bidir"]);
    let _ = std::fs::remove_dir_all(&cache);
}

#[test]
fn bench_prints_one_consistent_json_object_per_scene() {
    let cache = std::env::temp_dir().join(format!("prism-bench-test-{}", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(["bench", "--only", "cornell", "--seconds", "0.3"])
        .args(["--reference-spp", "16", "--rays", "4096", "--json"])
        .arg("--cache")
        .arg(&cache)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&cache);
    assert!(output.status.success(), "{output:?}");
    let stdout = String::from_utf8(output.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1, "{stdout}");
    let json: serde_json::Value = serde_json::from_str(lines[0]).expect("a JSON object");
    assert_eq!(json["scene"], "cornell-box", "{json}");
    // The bundled box: eight meshes of 36 non-degenerate triangles in all.
    assert_eq!(field(&json, "primitives"), 36.0);
    for key in [
        "bvh_build_seconds",
        "geometry_bytes",
        "rays_per_second",
        "shadow_rays_per_second",
        "samples_per_second",
        "spp",
        "render_seconds",
    ] {
        assert!(field(&json, key) > 0.0, "{key} in {json}");
    }
    // A 256 x 256 render of a few samples per pixel against a 16-spp reference: the relative
    // MSE is that of a noisy image, well inside (0, 1).
    let rel_mse = field(&json, "rel_mse");
    assert!(rel_mse > 1e-4 && rel_mse < 1.0, "{json}");
    let efficiency = 1.0 / (rel_mse * field(&json, "render_seconds"));
    assert!(
        (field(&json, "efficiency") / efficiency - 1.0).abs() < 1e-3,
        "{json}"
    );
    let samples = 256.0 * 256.0 * field(&json, "spp");
    let rate = samples / field(&json, "render_seconds");
    assert!(
        (field(&json, "samples_per_second") / rate - 1.0).abs() < 1e-3,
        "{json}"
    );
}

#[test]
fn geometry_memory_is_at_most_100_bytes_per_triangle() {
    // A 250 x 200 grid of quads, 100,000 triangles, with shading normals and uvs.
    let (nx, ny) = (250u32, 200u32);
    let mut positions = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            let (x, y) = (i as f32 / nx as f32, j as f32 / ny as f32);
            positions.push(Vec3::new(x, y, 0.1 * (7.0 * x).sin() * (5.0 * y).cos()));
        }
    }
    let normals = vec![Vec3::Z; positions.len()];
    let uvs = positions.iter().map(|p| p.truncate()).collect();
    let at = |i: u32, j: u32| j * (nx + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let count = triangles.len();
    let mesh = TriangleMesh::new(positions, Some(normals), Some(uvs), triangles, false);
    let geometry = Geometry::new(vec![Shape::Mesh(mesh).into()]);
    assert_eq!(geometry.primitive_count(), count);
    let per_triangle = geometry.memory_bytes() as f64 / count as f64;
    // At least the triangles' own data (three 12-byte vertices in the leaves, indices) ...
    assert!(per_triangle > 48.0, "{per_triangle} bytes per triangle");
    // ... and at most the budget of the performance issue.
    assert!(per_triangle <= 100.0, "{per_triangle} bytes per triangle");
}

/// The bundled Cornell box at 64 × 64 pixels.
fn small_cornell_box() -> Scene {
    let scene_path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/cornell-box/scene.xml");
    let defines = [
        ("resx".to_string(), "64".to_string()),
        ("resy".to_string(), "64".to_string()),
    ];
    load_scene(std::path::Path::new(scene_path), &defines)
        .unwrap()
        .scene
}

#[test]
fn benchmark_rays_leave_surfaces_in_all_directions() {
    let scene = small_cornell_box();
    let n = 20_000;
    let rays = incoherent_rays(&scene, n, 3);
    assert_eq!(rays.len(), n);
    assert_eq!(rays, incoherent_rays(&scene, n, 3), "seeded");
    let (lo, hi) = scene.world.geometry.bounds().unwrap();
    let slack = 1e-3 * (hi - lo).length();
    let mut mean = Vec3::ZERO;
    for ray in &rays {
        assert!(ray.o.cmpge(lo - slack).all() && ray.o.cmple(hi + slack).all());
        mean += ray.d.normalize() / n as f32;
    }
    // Uniform on the sphere: each component of the mean direction is 0 with a standard error
    // of 1/sqrt(3n).
    let standard_error = 1.0 / (3.0 * n as f32).sqrt();
    assert!(mean.abs().max_element() < 4.0 * standard_error, "{mean}");
}

#[test]
fn shadow_rays_join_visible_surfaces_to_the_lights() {
    let scene = small_cornell_box();
    let n = 5_000;
    let rays = shadow_rays(&scene, n, 4);
    assert_eq!(rays.len(), n);
    assert_eq!(rays, shadow_rays(&scene, n, 4), "seeded");
    // The box's one light is on the ceiling: every segment ends on it (the ray's parameter
    // stops just short of 1, at the point sampled on the light).
    let (lights, _): (Vec<_>, Vec<_>) = scene
        .world
        .geometry
        .primitives
        .iter()
        .zip(&scene.world.shape_info)
        .partition(|(_, info)| info.light.is_some());
    assert_eq!(lights.len(), 1);
    let (lo, hi) = lights[0].0.bounds();
    let slack = 1e-3 * (hi - lo).length();
    let mut occluded = 0;
    for ray in &rays {
        let end = ray.o + ray.d;
        assert!(
            end.cmpge(lo - slack).all() && end.cmple(hi + slack).all(),
            "{end} is not on the light"
        );
        assert!(ray.t_max < 1.0 && ray.t_max > 0.99);
        occluded += usize::from(scene.world.geometry.occluded(ray));
    }
    // The two boxes hide the light from part of the floor and walls, but not from most of
    // what the camera sees.
    assert!(
        occluded > 0 && occluded < n / 2,
        "{occluded} of {n} occluded"
    );
}
