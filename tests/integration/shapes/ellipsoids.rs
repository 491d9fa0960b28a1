//! The `ellipsoids` shape: ray intersection against closed forms (a sphere, an axis-aligned
//! ellipsoid, a rotated one through an independent affine map), Mitsuba's normal (the
//! implicit surface's gradient), back-face culling, bounds that hold the surface, the
//! hierarchy's per-ellipsoid primitives against a brute-force loop, and the PLY file as
//! Mitsuba reads it (logarithmic scales, quaternions normalised, `to_world`, extent).

use glam::{Mat3, Quat, Vec3};
use prism_core::geometry::Shape;
use prism_core::geometry::aggregate::Aggregate;
use prism_core::geometry::shape::{Ellipsoid, Ellipsoids, ShapeGeometry};
use prism_core::math::Ray;
use prism_core::sampling::rng::Pcg32;

fn ray(o: Vec3, d: Vec3) -> Ray {
    Ray {
        o,
        d,
        t_max: f32::INFINITY,
        time: 0.0,
    }
}

fn uniform_direction(rng: &mut Pcg32) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[test]
fn equal_radii_make_a_sphere() {
    let e = Ellipsoid {
        center: Vec3::new(1.0, 2.0, 3.0),
        radii: Vec3::splat(0.5),
        rotation: Mat3::from_rotation_x(0.7),
    };
    let mut rng = Pcg32::new(3, 5);
    for _ in 0..1000 {
        let o = e.center + uniform_direction(&mut rng) * 4.0;
        // Towards a random point within the sphere's silhouette disk.
        let to_center = (e.center - o).normalize();
        let aim = e.center + uniform_direction(&mut rng).reject_from(to_center) * 0.45;
        let d = (aim - o).normalize();
        let t = e
            .intersect(o, d, f32::INFINITY)
            .expect("the ray aims inside");
        // Closed form: t = b − √(b² − (|oc|² − r²)), b = d·(c − o).
        let oc = (e.center - o).as_dvec3();
        let b = d.as_dvec3().dot(oc);
        let expected = b - (b * b - (oc.length_squared() - 0.25)).sqrt();
        assert!((f64::from(t) - expected).abs() < 1e-5, "{t} {expected}");
        let (p, n) = e.surface_at(o + d * t);
        assert!(n.abs_diff_eq((p - e.center) / 0.5, 1e-5), "{n}");
    }
}

#[test]
fn an_axis_aligned_ellipsoid_meets_rays_at_its_closed_form() {
    let radii = Vec3::new(2.0, 0.5, 1.0);
    let e = Ellipsoid {
        center: Vec3::ZERO,
        radii,
        rotation: Mat3::IDENTITY,
    };
    // Along each axis from outside: t = distance − radius, the normal along the axis.
    for (axis, r) in [(Vec3::X, 2.0), (Vec3::Y, 0.5), (Vec3::Z, 1.0)] {
        let o = axis * 5.0;
        let t = e.intersect(o, -axis, f32::INFINITY).unwrap();
        assert!((t - (5.0 - r)).abs() < 1e-6, "{t}");
        let (p, n) = e.surface_at(o - axis * t);
        assert!(p.abs_diff_eq(axis * r, 1e-6), "{p}");
        assert!(n.abs_diff_eq(axis, 1e-6), "{n}");
    }
    // Through (x, y) = (1, 0.25) along −z: z = √(1 − 1/4 − 1/4) = √½, and the normal is the
    // gradient (x/a², y/b², z/c²) normalised.
    let o = Vec3::new(1.0, 0.25, 3.0);
    let t = e.intersect(o, -Vec3::Z, f32::INFINITY).unwrap();
    let z = 0.5f32.sqrt();
    assert!((t - (3.0 - z)).abs() < 1e-6, "{t}");
    let (_, n) = e.surface_at(o - Vec3::Z * t);
    let gradient = Vec3::new(1.0 / 4.0, 0.25 / 0.25, z).normalize();
    assert!(n.abs_diff_eq(gradient, 1e-5), "{n} {gradient}");
    // A ray that passes beside it misses; one that ends before it too.
    assert!(
        e.intersect(Vec3::new(2.1, 0.0, 3.0), -Vec3::Z, f32::INFINITY)
            .is_none()
    );
    assert!(e.intersect(o, -Vec3::Z, 2.0).is_none());
}

#[test]
fn a_rotated_ellipsoid_is_the_unit_sphere_under_its_affine_map() {
    let mut rng = Pcg32::new(11, 2);
    for _ in 0..200 {
        let rotation = Mat3::from_quat(
            Quat::from_xyzw(
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
            )
            .normalize(),
        );
        let radii = Vec3::new(
            0.2 + rng.next_f32(),
            0.2 + rng.next_f32(),
            0.2 + rng.next_f32(),
        );
        let e = Ellipsoid {
            center: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()),
            radii,
            rotation,
        };
        // A ray from outside aimed at a point of the surface: it hits at most there, and the
        // hit point lies on the surface, |M⁻¹ (p − c)| = 1 with M = R S.
        let m = rotation * Mat3::from_diagonal(radii);
        let target = e.center + m * uniform_direction(&mut rng);
        let o = e.center + uniform_direction(&mut rng) * 6.0;
        let d = target - o;
        let Some(t) = e.intersect(o, d, f32::INFINITY) else {
            panic!("a ray aimed at a surface point misses");
        };
        assert!(t <= 1.0 + 1e-5, "{t}");
        let p = o + d * t;
        let on_sphere = m.inverse() * (p - e.center);
        assert!((on_sphere.length() - 1.0).abs() < 1e-4, "{on_sphere}");
        // Mitsuba's normal, R (local / s²) normalised with local = Rᵀ (p − c), is the
        // inverse transpose of M applied to the sphere's normal.
        let (_, n) = e.surface_at(p);
        let expected = (m.inverse().transpose() * on_sphere).normalize();
        assert!(n.abs_diff_eq(expected, 1e-4), "{n} {expected}");
        // The bounds hold the hit point.
        let (lo, hi) = e.bounds();
        assert!(p.cmpge(lo - 1e-5).all() && p.cmple(hi + 1e-5).all());
    }
}

#[test]
fn the_bounds_touch_the_ellipsoid() {
    // For R = I the box is c ± radii exactly; for a rotation about z by 90° the x and y
    // extents swap.
    let e = Ellipsoid {
        center: Vec3::new(1.0, 0.0, 0.0),
        radii: Vec3::new(2.0, 0.5, 1.0),
        rotation: Mat3::IDENTITY,
    };
    let (lo, hi) = e.bounds();
    assert!(lo.abs_diff_eq(Vec3::new(-1.0, -0.5, -1.0), 1e-6));
    assert!(hi.abs_diff_eq(Vec3::new(3.0, 0.5, 1.0), 1e-6));
    let turned = Ellipsoid {
        rotation: Mat3::from_rotation_z(std::f32::consts::FRAC_PI_2),
        ..e
    };
    let (lo, hi) = turned.bounds();
    assert!(lo.abs_diff_eq(Vec3::new(0.5, -2.0, -1.0), 1e-6), "{lo}");
    assert!(hi.abs_diff_eq(Vec3::new(1.5, 2.0, 1.0), 1e-6), "{hi}");
}

#[test]
fn back_faces_are_culled_as_in_mitsuba() {
    let e = Ellipsoid {
        center: Vec3::ZERO,
        radii: Vec3::new(1.0, 2.0, 1.0),
        rotation: Mat3::IDENTITY,
    };
    // From the centre (Mitsuba's test01_backface_culling_contract) and from any inner point.
    assert!(e.intersect(Vec3::ZERO, -Vec3::Z, f32::INFINITY).is_none());
    assert!(
        e.intersect(Vec3::new(0.2, 1.5, 0.0), Vec3::Y, f32::INFINITY)
            .is_none()
    );
    // From outside, beyond it: the ellipsoid lies behind the ray.
    assert!(
        e.intersect(Vec3::new(0.0, 0.0, 2.0), Vec3::Z, f32::INFINITY)
            .is_none()
    );
    assert!(e.intersect(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z, f32::INFINITY) == Some(1.0));
}

#[test]
fn invalid_ellipsoids_are_refused() {
    let good = Ellipsoid {
        center: Vec3::ZERO,
        radii: Vec3::ONE,
        rotation: Mat3::IDENTITY,
    };
    assert!(Ellipsoids::new(vec![]).is_none());
    for bad in [
        Ellipsoid {
            center: Vec3::new(f32::NAN, 0.0, 0.0),
            ..good
        },
        Ellipsoid {
            radii: Vec3::new(1.0, 0.0, 1.0),
            ..good
        },
        Ellipsoid {
            radii: Vec3::new(1.0, f32::INFINITY, 1.0),
            ..good
        },
        Ellipsoid {
            rotation: Mat3::from_diagonal(Vec3::new(1.0, 2.0, 1.0)),
            ..good
        },
    ] {
        assert!(Ellipsoids::new(vec![good, bad]).is_none(), "{bad:?}");
    }
}

#[test]
fn the_hierarchy_finds_the_nearest_ellipsoid() {
    let mut rng = Pcg32::new(7, 9);
    let mut cloud = Vec::new();
    for _ in 0..200 {
        let q = Quat::from_xyzw(
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
            rng.next_f32() - 0.5,
        )
        .normalize();
        cloud.push(Ellipsoid {
            center: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0,
            radii: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 0.3 + 0.02,
            rotation: Mat3::from_quat(q),
        });
    }
    let ellipsoids = Ellipsoids::new(cloud).unwrap();
    let aggregate = Aggregate::new(vec![Shape::Ellipsoids(ellipsoids.clone())]);
    assert_eq!(aggregate.primitive_count(), 200);
    let mut hits = 0;
    for _ in 0..2000 {
        let o = Vec3::splat(2.0) + uniform_direction(&mut rng) * 5.0;
        let d = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - o).normalize();
        let r = ray(o, d);
        let expected = ellipsoids.intersect(&r, f32::INFINITY);
        let found = aggregate.closest_hit(&r);
        assert_eq!(found.map(|h| h.triangle.t), expected.map(|(_, t)| t));
        assert_eq!(aggregate.occluded(&r), expected.is_some());
        if let Some((i, t)) = expected {
            hits += 1;
            let si = aggregate.intersect(&r).unwrap();
            assert_eq!(si.primitive, i as u32);
            let (p, n) = ellipsoids.ellipsoids()[i].surface_at(o + d * t);
            assert!(si.p.abs_diff_eq(p, 1e-5) && si.n.abs_diff_eq(n, 1e-5));
            assert!(si.n.dot(d) < 0.0, "a front face");
            // The shape as a whole, as an external structure sees it, names the same
            // ellipsoid.
            assert_eq!(ellipsoids.intersect_analytic(&r, f32::INFINITY), Some(t));
        }
    }
    assert!(hits > 200, "{hits} hits: the test sees too few");
    assert_eq!(ellipsoids.area(), 0.0);
}

/// The geometry of a scene of the shapes `xml`, whose file `e.ply` holds `ply`.
fn scene_geometry(xml: &str, ply: &[u8], tag: &str) -> prism_core::geometry::Geometry {
    let dir = std::env::temp_dir().join(format!("prism-ellipsoids-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("e.ply"), ply).unwrap();
    let xml = format!(
        "<scene version=\"3.0.0\"><sensor type=\"perspective\"/>{}</scene>",
        xml
    );
    let scene =
        crate::common::scenes::scene_from_xml(&xml, dir.join("scene.xml").to_str().unwrap())
            .unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).unwrap();
    scene.world.geometry
}

/// A binary little-endian PLY of Mitsuba's minimal layout (`x y z nx ny nz scale_0..2
/// rot_0..3`), one record per row.
fn binary_ply(rows: &[[f32; 13]]) -> Vec<u8> {
    let names = [
        "x", "y", "z", "nx", "ny", "nz", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1",
        "rot_2", "rot_3",
    ];
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\n",
        rows.len()
    );
    for name in names {
        bytes += &format!("property float {name}\n");
    }
    bytes += "end_header\n";
    let mut bytes = bytes.into_bytes();
    for row in rows {
        for v in row {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    bytes
}

#[test]
fn the_file_is_placed_as_mitsuba_places_it() {
    // Scales are logarithms: exp(ln 0.1) = 0.1 (and 0.2), times the extent 2, the scale
    // factor 1.5 and the transform's uniform scale 2: radii (0.6, 1.2, 0.6) before the rotation. The
    // quaternion (w, x, y, z) = (2, 0, 0, 2) is a turn by 90° about z once normalised, which
    // `to_world`'s own 90° turn about z makes 180°: the long axis stays along y. The centre
    // (1, 0, 0) goes to (0, 2, 0) + (0, 0, 1).
    let (l, m) = (0.1f32.ln(), 0.2f32.ln());
    let ply = binary_ply(&[[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, l, m, l, 2.0, 0.0, 0.0, 2.0]]);
    let xml = r#"<shape type="ellipsoids">
            <string name="filename" value="e.ply"/>
            <float name="extent" value="2"/>
            <float name="scale_factor" value="1.5"/>
            <transform name="to_world">
                <rotate z="1" angle="90"/><scale value="2"/><translate z="1"/>
            </transform>
        </shape>"#;
    let geometry = scene_geometry(xml, &ply, "place");
    let center = Vec3::new(0.0, 2.0, 1.0);
    for (axis, radius) in [(Vec3::X, 0.6), (Vec3::Y, 1.2), (Vec3::Z, 0.6)] {
        let si = geometry
            .intersect(&ray(center + axis * 10.0, -axis))
            .expect("a ray along an axis hits");
        assert!((si.t - (10.0 - radius)).abs() < 1e-5, "{axis}: {}", si.t);
        assert!(si.n.abs_diff_eq(axis, 1e-5), "{}", si.n);
    }
}

#[test]
fn adaptive_clamping_scales_by_the_opacity() {
    // A Gaussian splatting file: opacity logit ln(o / (1 − o)) for o = 0.5 gives the extent
    // 3 √(2 ln 50) / 3 = √(2 ln 50); scale 1 (ln 1 = 0). The second ellipsoid's opacity,
    // sigmoid(−6) < 0.01, leaves it no extent: it is left out.
    let names = [
        "x", "y", "z", "nx", "ny", "nz", "f_dc_0", "opacity", "scale_0", "scale_1", "scale_2",
        "rot_0", "rot_1", "rot_2", "rot_3",
    ];
    let mut text = "ply\nformat ascii 1.0\nelement vertex 2\n".to_string();
    for name in names {
        text += &format!("property float {name}\n");
    }
    text += "end_header\n0 0 0 0 0 1 0.3 0 0 0 0 1 0 0 0\n5 0 0 0 0 1 0.3 -6 0 0 0 1 0 0 0\n";
    let xml = r#"<shape type="ellipsoids">
            <string name="filename" value="e.ply"/>
            <boolean name="extent_adaptive_clamping" value="true"/>
        </shape>"#;
    let geometry = scene_geometry(xml, text.as_bytes(), "clamp");
    let radius = (2.0 * 50f32.ln()).sqrt();
    let si = geometry.intersect(&ray(Vec3::Z * 10.0, -Vec3::Z)).unwrap();
    assert!((si.t - (10.0 - radius)).abs() < 1e-5, "{} {radius}", si.t);
    assert!(
        geometry
            .intersect(&ray(Vec3::new(5.0, 0.0, 10.0), -Vec3::Z))
            .is_none()
    );
    assert_eq!(geometry.primitive_count(), 1);
}
