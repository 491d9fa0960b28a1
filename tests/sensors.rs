//! The sensor plugins as the scene reader builds them from Mitsuba XML: the field of view
//! from `fov`, `fov_axis` and `focal_length` (Mitsuba 3's `parse_fov`), and `focus_distance`,
//! which Mitsuba 3 reads on every projective camera.

use std::path::Path;

use glam::Vec2;
use prism_core::camera::Camera;
use prism_core::scene::Scene;
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::reader::read_scene_str;

/// Builds a scene holding one sensor, whose inner XML is `sensor` and film `width` × `height`.
fn load_sensor(
    kind: &str,
    sensor: &str,
    width: u32,
    height: u32,
) -> prism_core::error::Result<Scene> {
    let text = format!(
        r#"<scene version="3.0.0">
    <sensor type="{kind}">
        {sensor}
        <film type="hdrfilm"><integer name="width" value="{width}"/><integer name="height" value="{height}"/></film>
    </sensor>
</scene>"#
    );
    let root = read_scene_str(&text, &Path::new(".").join("scene.xml"), &[])?;
    Ok(build_scene(&root)?.scene)
}

fn tan_half_fov_x(scene: &Scene) -> f64 {
    match &scene.camera {
        Camera::Perspective(camera) => f64::from(camera.tan_half_fov_x),
        #[allow(unreachable_patterns)]
        _ => panic!("not a perspective camera"),
    }
}

/// tan(x/2) for x in degrees.
fn tan_half(degrees: f64) -> f64 {
    (0.5 * degrees).to_radians().tan()
}

/// Mitsuba 3's `parse_fov`: the horizontal half-angle's tangent from each axis, on a landscape
/// (64 × 48) and a portrait (48 × 64) film.
#[test]
fn field_of_view_axes_are_read_as_mitsuba_reads_them() {
    for (width, height) in [(64u32, 48u32), (48, 64)] {
        let aspect = f64::from(width) / f64::from(height);
        let t = tan_half(50.0);
        let diagonal = t / (1.0 + 1.0 / (aspect * aspect)).sqrt();
        let (smaller, larger) = if aspect > 1.0 {
            (t * aspect, t)
        } else {
            (t, t * aspect)
        };
        for (axis, expected) in [
            ("x", t),
            ("y", t * aspect),
            ("diagonal", diagonal),
            ("smaller", smaller),
            ("larger", larger),
            ("Diagonal", diagonal),
        ] {
            let sensor = format!(
                r#"<float name="fov" value="50"/><string name="fov_axis" value="{axis}"/>"#
            );
            let scene = load_sensor("perspective", &sensor, width, height).unwrap();
            let got = tan_half_fov_x(&scene);
            assert!(
                (got / expected - 1.0).abs() < 1e-6,
                "{axis} on {width} × {height}: {got}, expected {expected}"
            );
        }
    }
}

/// `focal_length` is the diagonal field of view of a lens on 36 × 24 mm film, with or without
/// the "mm" suffix; 50 mm is the default.
#[test]
fn focal_lengths_give_diagonal_fields_of_view() {
    let (width, height) = (64u32, 48u32);
    let aspect = f64::from(width) / f64::from(height);
    for (text, mm) in [(None, 50.0), (Some("35mm"), 35.0), (Some("85"), 85.0)] {
        let sensor = text.map_or(String::new(), |t| {
            format!(r#"<string name="focal_length" value="{t}"/>"#)
        });
        let scene = load_sensor("perspective", &sensor, width, height).unwrap();
        let half_diagonal = (36.0f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * mm);
        let expected = half_diagonal / (1.0 + 1.0 / (aspect * aspect)).sqrt();
        let got = tan_half_fov_x(&scene);
        assert!(
            (got / expected - 1.0).abs() < 1e-6,
            "{text:?}: {got} vs {expected}"
        );
    }
    // Mitsuba 3 reads `fov_axis` only with `fov`: beside `focal_length` it is unused.
    let err = load_sensor(
        "perspective",
        r#"<string name="focal_length" value="35mm"/><string name="fov_axis" value="y"/>"#,
        width,
        height,
    )
    .err()
    .expect("fov_axis beside focal_length is an error");
    assert!(err.to_string().contains("fov_axis"), "{err}");
}

/// Mitsuba 3 reads `focus_distance` on every projective camera; on a pinhole it changes no
/// ray.
#[test]
fn focus_distance_on_a_pinhole_changes_nothing() {
    let plain = load_sensor("perspective", r#"<float name="fov" value="40"/>"#, 32, 32).unwrap();
    let focused = load_sensor(
        "perspective",
        r#"<float name="fov" value="40"/><float name="focus_distance" value="3"/>"#,
        32,
        32,
    )
    .unwrap();
    for (film, lens) in [
        (Vec2::new(0.0, 0.0), Vec2::new(0.1, 0.9)),
        (Vec2::new(16.5, 7.25), Vec2::new(0.7, 0.3)),
        (Vec2::new(32.0, 32.0), Vec2::new(0.5, 0.5)),
    ] {
        let a = plain.camera.generate_ray(film, lens, 0.0);
        let b = focused.camera.generate_ray(film, lens, 0.0);
        assert_eq!((a.o, a.d, a.t_max), (b.o, b.d, b.t_max));
    }
    let err = load_sensor(
        "perspective",
        r#"<string name="focus_distance" value="near"/>"#,
        32,
        32,
    )
    .err()
    .expect("a string focus_distance is an error");
    assert!(err.to_string().contains("focus_distance"), "{err}");
}

/// A Mitsuba 0.6 film's `banner`, `attachLog`, `highQualityEdges` and an HDR film's `gamma`
/// are read and ignored, each with one warning naming its place; the scene loads.
#[test]
fn mitsuba_06_film_parameters_are_ignored_with_one_warning_each() {
    let text = r#"<scene version="0.6.0">
    <sensor type="perspective">
        <film type="hdrfilm">
            <integer name="width" value="4"/><integer name="height" value="4"/>
            <boolean name="banner" value="false"/>
            <boolean name="attachLog" value="false"/>
            <boolean name="highQualityEdges" value="true"/>
            <float name="gamma" value="2.2"/>
        </film>
    </sensor>
</scene>"#;
    let path = Path::new("old").join("scene.xml");
    let root = read_scene_str(text, &path, &[]).unwrap();
    let loaded = build_scene(&root).unwrap();
    let got: Vec<String> = loaded.warnings.iter().map(|w| w.to_string()).collect();
    let file = path.display();
    let expected_starts = [
        format!("{file}:5:13: warning: film \"hdrfilm\" ignores \"banner\""),
        format!("{file}:6:13: warning: film \"hdrfilm\" ignores \"attach_log\""),
        format!("{file}:7:13: warning: film \"hdrfilm\" ignores \"high_quality_edges\""),
        format!("{file}:8:13: warning: film \"hdrfilm\" ignores \"gamma\""),
    ];
    assert_eq!(got.len(), expected_starts.len(), "{got:#?}");
    for (warning, start) in got.iter().zip(&expected_starts) {
        assert!(
            warning.starts_with(start.as_str()),
            "{warning}\nexpected {start}"
        );
    }
    // A scene without them has no warnings.
    let plain = load_sensor("perspective", "", 4, 4);
    assert!(plain.is_ok());
}

/// `prism render` prints each warning once, on stderr, and renders.
#[test]
fn the_command_line_prints_each_warning_once() {
    let dir = std::env::temp_dir().join(format!("prism-sensors-warnings-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("scene.xml"),
        r#"<scene version="0.6.0">
    <sensor type="perspective">
        <film type="hdrfilm">
            <integer name="width" value="4"/><integer name="height" value="4"/>
            <boolean name="banner" value="false"/>
        </film>
    </sensor>
</scene>"#,
    )
    .unwrap();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("render")
        .arg(dir.join("scene.xml"))
        .arg("-o")
        .arg(dir.join("out.exr"))
        .args(["--spp", "1"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert_eq!(stderr.matches("warning:").count(), 1, "{stderr}");
    assert!(
        stderr.contains("scene.xml:5:13: warning: film \"hdrfilm\" ignores \"banner\""),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
