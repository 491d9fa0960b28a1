//! The `sdfgrid` shape: intersections against closed forms (a plane, which trilinear
//! interpolation reproduces exactly, and a sphere, which it approximates to O(h²)), normals
//! (the gradient, analytic and smooth), hits from inside, the hierarchy's per-voxel primitives
//! against a brute-force loop, and the `.vol` file refused with a clear error where it is not a
//! grid Mitsuba reads.

use glam::{UVec3, Vec3};
use prism_core::geometry::Shape;
use prism_core::geometry::aggregate::Aggregate;
use prism_core::geometry::shape::{SdfGrid, SdfNormals, ShapeGeometry};
use prism_core::math::{Ray, Transform};
use prism_core::sampling::rng::Pcg32;

fn ray(o: Vec3, d: Vec3) -> Ray {
    Ray {
        o,
        d,
        t_max: f32::INFINITY,
        time: 0.0,
    }
}

/// The grid of `f` sampled at n points per axis over the unit cube.
fn sampled(n: u32, f: impl Fn(Vec3) -> f32) -> Vec<f32> {
    let mut values = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                values.push(f(Vec3::new(x as f32, y as f32, z as f32) / (n - 1) as f32));
            }
        }
    }
    values
}

fn grid(n: u32, f: impl Fn(Vec3) -> f32, normals: SdfNormals) -> SdfGrid {
    SdfGrid::new(UVec3::splat(n), sampled(n, f), Transform::IDENTITY, normals)
        .expect("a grid the surface crosses")
}

/// The surface interaction of `ray`'s first hit on `grid` (through the hierarchy).
fn hit(grid: &SdfGrid, r: &Ray) -> Option<prism_core::geometry::SurfaceInteraction> {
    Aggregate::new(vec![Shape::SdfGrid(grid.clone())]).intersect(r)
}

#[test]
fn a_plane_is_reproduced_exactly_from_both_sides() {
    for normals in [SdfNormals::Analytic, SdfNormals::Smooth] {
        let plane = grid(5, |p| p.z - 0.37, normals);
        // Only the voxels of the layer z in [0.25, 0.5] hold the surface.
        assert_eq!(plane.voxel_count(), 16);
        for (x, y) in [(0.1, 0.2), (0.5, 0.5), (0.93, 0.61), (0.25, 0.75)] {
            let from_above = hit(&plane, &ray(Vec3::new(x, y, 2.0), -Vec3::Z)).unwrap();
            assert!(
                (from_above.t - (2.0 - 0.37)).abs() < 1e-5,
                "{}",
                from_above.t
            );
            assert!(from_above.n.abs_diff_eq(Vec3::Z, 1e-5), "{}", from_above.n);
            assert!(from_above.shading.n.abs_diff_eq(Vec3::Z, 1e-5));
            // From below (inside the function's negative side) the surface is hit too, its
            // normal still the gradient.
            let from_below = hit(&plane, &ray(Vec3::new(x, y, 0.1), Vec3::Z)).unwrap();
            assert!((from_below.t - 0.27).abs() < 1e-5, "{}", from_below.t);
            assert!(from_below.n.abs_diff_eq(Vec3::Z, 1e-5));
        }
        // A slanted ray: z(t) = 0.9 − 0.5 t meets the plane at t = 1.06.
        let d = Vec3::new(0.2, 0.1, -0.5);
        let si = hit(&plane, &ray(Vec3::new(0.1, 0.2, 0.9), d)).unwrap();
        assert!((si.t - 1.06).abs() < 1e-5, "{}", si.t);
        // Beside the grid, nothing.
        assert!(hit(&plane, &ray(Vec3::new(1.5, 0.5, 2.0), -Vec3::Z)).is_none());
    }
}

#[test]
fn a_sphere_is_approximated_to_second_order() {
    let (c, r) = (Vec3::new(0.5, 0.48, 0.52), 0.3f32);
    let sphere = grid(33, |p| (p - c).length() - r, SdfNormals::Analytic);
    let smooth = grid(33, |p| (p - c).length() - r, SdfNormals::Smooth);
    let mut rng = Pcg32::new(5, 1);
    let mut worst_radial = 0.0f32;
    let mut worst_n = 0.0f32;
    let mut worst_smooth = 0.0f32;
    for _ in 0..300 {
        let o = c + Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 2.0);
        let target = c + Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 0.0) * 0.5;
        let d = (target - o).normalize();
        // Closed form: the sphere's entry along the ray.
        let oc = (o - c).as_dvec3();
        let b = oc.dot(d.as_dvec3());
        let disc = b * b - (oc.length_squared() - f64::from(r * r));
        let Some(si) = hit(&sphere, &ray(o, d)) else {
            assert!(disc < 1e-3, "a ray through the sphere misses");
            continue;
        };
        assert!(disc > 0.0);
        let expected = -b - disc.sqrt();
        // The hit's distance from the sphere (the error in t grows at grazing incidence).
        worst_radial = worst_radial.max(((o + d * si.t - c).length() - r).abs());
        let exact = (o + d * expected as f32 - c).normalize();
        worst_n = worst_n.max((si.n - exact).length());
        let s = hit(&smooth, &ray(o, d)).unwrap();
        assert_eq!(s.t, si.t);
        worst_smooth = worst_smooth.max((s.shading.n - exact).length());
    }
    // h = 1/32: the trilinear function differs from the distance by about h²/(8r) = 4 × 10⁻⁴.
    assert!(worst_radial < 1e-3, "{worst_radial}");
    // The normals are the patches' gradients, first-order accurate: off by about h/r = 0.1;
    // the smooth blend less so.
    assert!(worst_n < 0.1, "{worst_n}");
    assert!(worst_smooth < worst_n, "{worst_smooth} {worst_n}");
}

#[test]
fn the_hierarchy_finds_the_first_voxel() {
    let c = Vec3::splat(0.5);
    let field = |p: Vec3| {
        // Two overlapping spheres: several crossings per ray.
        let a = (p - c - Vec3::new(0.15, 0.0, 0.0)).length() - 0.2;
        let b = (p - c + Vec3::new(0.2, 0.1, 0.0)).length() - 0.15;
        a.min(b)
    };
    let to_world = Transform::new(glam::DMat4::from_scale_rotation_translation(
        glam::DVec3::new(2.0, 1.0, 1.5),
        glam::DQuat::from_rotation_z(0.4),
        glam::DVec3::new(-1.0, 0.5, 0.0),
    ))
    .unwrap();
    let grid = SdfGrid::new(
        UVec3::new(17, 13, 11),
        sampled_axes(UVec3::new(17, 13, 11), field),
        to_world,
        SdfNormals::Smooth,
    )
    .unwrap();
    let aggregate = Aggregate::new(vec![Shape::SdfGrid(grid.clone())]);
    assert_eq!(aggregate.primitive_count(), grid.voxel_count());
    let (lo, hi) = grid.object_bounds();
    let mut rng = Pcg32::new(9, 4);
    let mut hits = 0;
    for _ in 0..2000 {
        let o = lo
            + (hi - lo) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32())
            + Vec3::new(0.0, 0.0, 3.0);
        let target = lo + (hi - lo) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let r = ray(o, target - o);
        let expected = grid.intersect(&r, f32::INFINITY).map(|(_, t)| t);
        assert_eq!(aggregate.closest_hit(&r).map(|h| h.triangle.t), expected);
        assert_eq!(aggregate.occluded(&r), expected.is_some());
        hits += usize::from(expected.is_some());
    }
    assert!(hits > 200, "{hits} hits: the test sees too few");
    assert_eq!(grid.area(), 0.0);
}

/// The grid of `f` sampled at `n` points per axis over the unit cube.
fn sampled_axes(n: UVec3, f: impl Fn(Vec3) -> f32) -> Vec<f32> {
    let mut values = Vec::new();
    for z in 0..n.z {
        for y in 0..n.y {
            for x in 0..n.x {
                let p = Vec3::new(x as f32, y as f32, z as f32) / (n - 1).as_vec3();
                values.push(f(p));
            }
        }
    }
    values
}

#[test]
fn grids_without_a_surface_are_refused() {
    let id = Transform::IDENTITY;
    let n = SdfNormals::Smooth;
    assert!(SdfGrid::new(UVec3::splat(3), vec![1.0; 27], id, n).is_none());
    assert!(SdfGrid::new(UVec3::splat(3), vec![-1.0; 27], id, n).is_none());
    assert!(SdfGrid::new(UVec3::new(1, 3, 3), vec![0.0; 9], id, n).is_none());
    assert!(SdfGrid::new(UVec3::splat(2), vec![0.0; 7], id, n).is_none());
    let mut values = sampled(3, |p| p.z - 0.5);
    values[4] = f32::NAN;
    assert!(SdfGrid::new(UVec3::splat(3), values, id, n).is_none());
    // A zero value alone makes a voxel hold the surface.
    let mut values = vec![1.0; 8];
    values[0] = 0.0;
    assert_eq!(
        SdfGrid::new(UVec3::splat(2), values, id, n).map(|g| g.voxel_count()),
        Some(1)
    );
}

/// A `.vol` file of `channels` channels at n × n × n points of `value`.
fn vol(n: i32, channels: i32, value: impl Fn(usize) -> f32) -> Vec<u8> {
    let mut bytes = b"VOL\x03".to_vec();
    for v in [1, n, n, n, channels] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    for i in 0..(n * n * n * channels) as usize {
        bytes.extend_from_slice(&value(i).to_le_bytes());
    }
    bytes
}

#[test]
fn bad_grid_files_are_refused_with_their_place() {
    let cases: [(Vec<u8>, &str); 5] = [
        (vol(3, 3, |i| i as f32 - 20.0), "has 3"),
        (vol(1, 1, |_| 0.0), "at least 2 per axis"),
        (vol(3, 1, |_| 1.0), "never change sign"),
        (
            vol(3, 1, |i| if i == 5 { f32::NAN } else { i as f32 - 9.0 }),
            "value 5 is not a finite number",
        ),
        (vol(3, 1, |i| i as f32)[..100].to_vec(), "truncated"),
    ];
    let dir = std::env::temp_dir().join(format!("prism-sdfgrid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (i, (bytes, says)) in cases.iter().enumerate() {
        let name = format!("g{i}.vol");
        std::fs::write(dir.join(&name), bytes).unwrap();
        let xml = format!(
            "<scene version=\"3.0.0\"><sensor type=\"perspective\"/>\n\
             <shape type=\"sdfgrid\"><string name=\"filename\" value=\"{name}\"/></shape></scene>"
        );
        let error =
            crate::common::scenes::scene_from_xml(&xml, dir.join("s.xml").to_str().unwrap())
                .err()
                .unwrap_or_else(|| panic!("{says}: the grid is accepted"));
        let text = error.to_string();
        assert!(text.contains(says), "{says}: {text}");
        assert!(text.contains("s.xml:2:"), "{says}: {text}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
