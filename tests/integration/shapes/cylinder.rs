//! The `cylinder` shape: intersection, normals and (u, v) as Mitsuba's; uniform area sampling
//! (chi-square test of its density in (u, v), and the claimed pdf); and the irradiance an
//! emitting tube gives a point on its axis, against the closed form.

use std::f64::consts::PI;
use std::path::PathBuf;

use glam::{DMat4, DVec3, Vec2, Vec3};
use prism_core::geometry::Shape;
use prism_core::geometry::ShapeGeometry;
use prism_core::geometry::shape::Cylinder;
use prism_core::math::{Ray, Transform};
use prism_core::sampling::chi2::{Cells, Suite, chi2_rectangle};
use prism_core::sampling::rng::Pcg32;
use prism_mitsuba::load_scene;

use crate::common::scenes::{assert_mean_luminance, render_film};

/// The chi-square tests of this module, one name per statistic: the suite of Šidák's correction.
const SUITE: Suite = Suite::new(&["cylinder area sampling"]);

/// A cylinder of radius `r` and length `l` along +z from `origin`.
fn cylinder(origin: DVec3, r: f64, l: f64, flip_normals: bool) -> Cylinder {
    let m = DMat4::from_translation(origin) * DMat4::from_scale(DVec3::new(r, r, l));
    Cylinder::new(Transform::new(m).unwrap(), flip_normals)
}

fn ray(o: Vec3, d: Vec3) -> Ray {
    Ray {
        o,
        d,
        t_max: f32::INFINITY,
        time: 0.0,
    }
}

#[test]
fn rays_meet_the_open_tube_where_they_should() {
    let c = cylinder(DVec3::new(1.0, 2.0, 3.0), 0.5, 2.0, false);
    let shape = Shape::Cylinder(c.clone());
    // From outside, towards the axis at mid-height: the near wall at distance 4.5.
    let hit = c.intersect(Vec3::new(-4.0, 2.0, 4.0), Vec3::X, f32::INFINITY);
    assert!((hit.unwrap() - 4.5).abs() < 1e-5, "{hit:?}");
    // From the axis: the wall at distance r, from inside.
    let t = c
        .intersect(Vec3::new(1.0, 2.0, 4.0), Vec3::Y, f32::INFINITY)
        .unwrap();
    assert!((t - 0.5).abs() < 1e-6, "{t}");
    // No caps: a ray along the axis, or one passing beyond the ends, misses.
    assert_eq!(
        c.intersect(Vec3::new(1.0, 2.0, 0.0), Vec3::Z, f32::INFINITY),
        None
    );
    assert_eq!(
        c.intersect(Vec3::new(-4.0, 2.0, 5.5), Vec3::X, f32::INFINITY),
        None
    );
    // Entering through the open end and leaving through the wall.
    let d = Vec3::new(0.3, 0.0, 1.0).normalize();
    let t = c
        .intersect(Vec3::new(1.0, 2.0, 2.0), d, f32::INFINITY)
        .unwrap();
    let p = Vec3::new(1.0, 2.0, 2.0) + d * t;
    assert!(
        (p.x - 1.5).abs() < 1e-5 && (p.z - (2.0 + 0.5 / 0.3)).abs() < 1e-4,
        "{p}"
    );
    // t_max is respected.
    assert_eq!(c.intersect(Vec3::new(-4.0, 2.0, 4.0), Vec3::X, 4.4), None);

    // The point at φ = 90°, a quarter of the way up: (u, v) = (1/4, 1/4), outward normal +y,
    // ∂p/∂u = 2π r (−1, 0, 0), ∂p/∂v = (0, 0, l).
    let r = ray(Vec3::new(1.0, 6.0, 3.5), -Vec3::Y);
    let t = shape.intersect_analytic(&r, f32::INFINITY).unwrap();
    let si = c.interaction_at(r.o, r.d, t, 7);
    assert!(si.p.abs_diff_eq(Vec3::new(1.0, 2.5, 3.5), 1e-5), "{}", si.p);
    assert!(si.uv.abs_diff_eq(Vec2::new(0.25, 0.25), 1e-5), "{}", si.uv);
    assert!(si.n.abs_diff_eq(Vec3::Y, 1e-6), "{}", si.n);
    assert!(si.dp_du.abs_diff_eq(Vec3::new(-PI as f32, 0.0, 0.0), 1e-5));
    assert!(si.dp_dv.abs_diff_eq(Vec3::new(0.0, 0.0, 2.0), 1e-6));
    assert_eq!(si.shape, 7);
    let flipped = cylinder(DVec3::new(1.0, 2.0, 3.0), 0.5, 2.0, true);
    assert!(
        flipped
            .interaction_at(r.o, r.d, t, 7)
            .n
            .abs_diff_eq(-Vec3::Y, 1e-6)
    );
    assert!((c.area() - (2.0 * PI * 0.5 * 2.0) as f32).abs() < 1e-5);
}

/// Area sampling: uniform in (u, v) = (φ/2π, z) of the object frame, with pdf 1/(2π r l) per
/// unit area (the area element being 2π r l du dv).
#[test]
fn area_samples_are_uniform_with_the_claimed_density() {
    let c = cylinder(DVec3::new(-0.5, 0.25, 1.0), 0.7, 1.9, false);
    let expected_pdf = 1.0 / (2.0 * PI * 0.7 * 1.9);
    let outcome = chi2_rectangle(
        1_000_000,
        Cells {
            x: (0.0, 1.0),
            y: (0.0, 1.0),
            nx: 40,
            ny: 20,
        },
        17,
        |rng: &mut Pcg32| {
            let s = c
                .sample_area(0.5, Vec2::new(rng.next_f32(), rng.next_f32()))
                .unwrap();
            assert!(
                (f64::from(s.pdf) / expected_pdf - 1.0).abs() < 1e-5,
                "pdf {} instead of {expected_pdf}",
                s.pdf
            );
            let local = c.to_world.inverse_point(s.p).as_dvec3();
            let radial = (local.x * local.x + local.y * local.y).sqrt();
            assert!(
                (radial - 1.0).abs() < 1e-5,
                "a sample off the tube: {local}"
            );
            let outward = Vec3::new(local.x as f32, local.y as f32, 0.0).normalize();
            assert!(s.n.abs_diff_eq(outward, 1e-5), "normal {} at {local}", s.n);
            let u = local.y.atan2(local.x).rem_euclid(2.0 * PI) / (2.0 * PI);
            Some((u.min(1.0 - 1e-12), local.z.clamp(0.0, 1.0 - 1e-12)))
        },
        |_, _| 1.0,
    )
    .unwrap();
    SUITE.assert_passes("cylinder area sampling", &outcome);
}

/// A tube of radius R from z = 0 to h emitting radiance L inwards (flip_normals) lights a
/// small diffuse disk of reflectance ρ at the centre of its base, facing up. The disk sees the
/// wall at polar angles from θ₀ = atan(R/h) to π/2, so E = ∫ L cos θ dω = π L cos²θ₀ =
/// π L h²/(h² + R²), and the disk's radiance is ρ E/π = ρ L h²/(h² + R²). The camera looks
/// down the axis and sees only the disk; direct lighting only (max_depth 2), light sampled by
/// area with MIS against the BSDF.
#[test]
fn an_emitting_tube_lights_its_axis_as_the_closed_form_says() {
    let (radius, height, rho) = (1.0, 1.5, 0.5);
    let scene = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="0.5"/>
        <transform name="to_world"><lookat origin="0, 0, 1.2" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
    <shape type="cylinder">
        <float name="radius" value="{radius}"/>
        <point name="p1" x="0" y="0" z="{height}"/>
        <boolean name="flip_normals" value="true"/>
        <emitter type="area"/>
    </shape>
    <shape type="disk">
        <transform name="to_world"><scale value="0.02"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="{rho}"/></bsdf>
    </shape>
</scene>
"#
    );
    let dir: PathBuf = std::env::temp_dir().join(format!("prism-cylinder-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.xml"), scene).unwrap();
    let loaded = load_scene(&dir.join("scene.xml"), &[]);
    let _ = std::fs::remove_dir_all(&dir);
    let loaded = loaded.unwrap_or_else(|e| panic!("{e}"));
    let film = render_film(&loaded.scene, 4096, 3, Some(1));
    let expected = rho * height * height / (height * height + radius * radius);
    assert_mean_luminance("disk on the axis of an emitting tube", &film, expected);
}
