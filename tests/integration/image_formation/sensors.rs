//! The sensor plugins as the scene reader builds them from Mitsuba XML: the field of view
//! from `fov`, `fov_axis` and `focal_length` (Mitsuba 3's `parse_fov`), `focus_distance`,
//! which Mitsuba 3 reads on every projective camera, the orthographic camera against closed
//! forms, the radiance meter, Mitsuba 0.6's ignored film parameters and its `ldrfilm`.

use std::path::Path;

use glam::Vec2;
use prism_core::camera::{Camera, CameraModel};
use prism_core::scene::Scene;
use prism_mitsuba::factory::build_scene;
use prism_mitsuba::reader::read_scene_str;

use crate::common::scenes::{
    assert_mean_luminance, image_mean_and_standard_error, pixel_mean_and_variance, render_film,
    scene_from_xml,
};

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
        let a = plain.camera.generate_ray(film, lens, 0.0).ray;
        let b = focused.camera.generate_ray(film, lens, 0.0).ray;
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

/// Renders `film` (the inner XML of an `ldrfilm` of 8 × 6 pixels) with `prism render` into a
/// fresh folder; returns the folder.
fn render_ldrfilm(name: &str, film: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-sensors-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("scene.xml"),
        format!(
            r#"<scene version="0.6.0">
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="toWorld"><lookAt origin="0, 0, -3" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="ldrfilm">
            <integer name="width" value="8"/><integer name="height" value="6"/>
            {film}
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.3, 0.6, 1.5"/></emitter>
    <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="0.9, 0.5, 0.1"/></bsdf></shape>
</scene>"#
        ),
    )
    .unwrap();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("render")
        .arg(dir.join("scene.xml"))
        .arg("-o")
        .arg(dir.join("out.exr"))
        .args(["--spp", "4"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    dir
}

/// The linear sRGB pixels of the EXR Prism wrote.
fn exr_rgb(dir: &Path) -> Vec<[f64; 3]> {
    let image = prism_core::image::read_exr(&dir.join("out.exr")).unwrap();
    let (r, g, b) = (
        image.channel("R").unwrap(),
        image.channel("G").unwrap(),
        image.channel("B").unwrap(),
    );
    (0..r.len())
        .map(|i| [f64::from(r[i]), f64::from(g[i]), f64::from(b[i])])
        .collect()
}

/// The 8-bit values of an image file, `channels` per pixel.
fn image_bytes(path: &Path) -> (usize, Vec<i32>) {
    let bitmap = prism_core::image::read_bitmap(path).unwrap();
    assert_eq!((bitmap.width, bitmap.height), (8, 6));
    let bytes = bitmap
        .data
        .iter()
        .map(|v| (v * 255.0).round() as i32)
        .collect();
    (bitmap.channels, bytes)
}

/// Asserts 8-bit values equal the exact ones rounded: within half a step, and 10⁻² more for
/// the difference between Prism's f32 arithmetic and the test's f64.
fn assert_bytes(got: &[i32], expected: &[f64]) {
    assert_eq!(got.len(), expected.len());
    for (i, (&g, &e)) in got.iter().zip(expected).enumerate() {
        assert!(
            (f64::from(g) - e).abs() <= 0.5 + 1e-2,
            "value {i}: {g}, expected {e}"
        );
    }
}

/// `ldrfilm` with `gamma` tonemapping: the PNG holds 255 · clamp(2^exposure · v)^(1/γ) of the
/// EXR's linear values.
#[test]
fn ldrfilm_writes_exposure_and_gamma() {
    let dir = render_ldrfilm(
        "ldr-gamma",
        r#"<float name="exposure" value="-1"/><float name="gamma" value="2.2"/>"#,
    );
    let rgb = exr_rgb(&dir);
    let expected: Vec<f64> = rgb
        .iter()
        .flatten()
        .map(|&v| 255.0 * (0.5 * v).clamp(0.0, 1.0).powf(1.0 / 2.2))
        .collect();
    let (channels, bytes) = image_bytes(&dir.join("out.png"));
    assert_eq!(channels, 3);
    assert_bytes(&bytes, &expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `ldrfilm` with Reinhard's operator, as luminance: each pixel's luminance L becomes
/// Lp (1 + Lp / L_white²) / (1 + Lp) with Lp = L · key / exp(mean ln(10⁻³ + L)) and
/// b = 1 − burn entering as L_white² b⁴, then the sRGB curve.
#[test]
fn ldrfilm_writes_reinhard_luminance() {
    let dir = render_ldrfilm(
        "ldr-reinhard",
        r#"<string name="tonemapMethod" value="reinhard"/><float name="key" value="0.3"/>
            <float name="burn" value="0.2"/><string name="pixelFormat" value="luminance"/>"#,
    );
    let luminance: Vec<f64> = exr_rgb(&dir)
        .iter()
        .map(|p| 0.212_671 * p[0] + 0.715_160 * p[1] + 0.072_169 * p[2])
        .collect();
    let log_average =
        (luminance.iter().map(|l| (1e-3 + l).ln()).sum::<f64>() / luminance.len() as f64).exp();
    let scale = 0.3 / log_average;
    let white = luminance.iter().copied().fold(0.0, f64::max) * scale;
    let inv_white2 = 1.0 / (white * white * 0.8f64.powi(4));
    let srgb = |v: f64| {
        if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        }
    };
    let expected: Vec<f64> = luminance
        .iter()
        .map(|&l| {
            let lp = l * scale;
            255.0 * srgb((lp * (1.0 + lp * inv_white2) / (1.0 + lp)).clamp(0.0, 1.0))
        })
        .collect();
    let (channels, bytes) = image_bytes(&dir.join("out.png"));
    assert_eq!(channels, 1);
    assert_bytes(&bytes, &expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `fileFormat="jpeg"` writes `out.jpg` (and no PNG); an RGBA PNG's alpha is the coverage,
/// complete under the constant environment.
#[test]
fn ldrfilm_writes_jpeg_and_rgba() {
    let dir = render_ldrfilm("ldr-jpeg", r#"<string name="fileFormat" value="jpeg"/>"#);
    let jpeg = std::fs::read(dir.join("out.jpg")).unwrap();
    assert_eq!(&jpeg[..2], &[0xFF, 0xD8]);
    assert!(!dir.join("out.png").exists());
    let (channels, _) = image_bytes(&dir.join("out.jpg"));
    assert_eq!(channels, 3);
    std::fs::remove_dir_all(&dir).unwrap();

    let dir = render_ldrfilm("ldr-rgba", r#"<string name="pixelFormat" value="rgba"/>"#);
    let (channels, bytes) = image_bytes(&dir.join("out.png"));
    assert_eq!(channels, 4);
    assert!(bytes.chunks(4).all(|p| p[3] == 255));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An orthographic scene of 64 × 48 pixels with a box filter: the camera 3 above the origin
/// looking down, its film scaled by `scale` (covering [−s, s] × [−0.75 s, 0.75 s]), over `body`.
fn orthographic_scene(scale: f64, body: &str) -> Scene {
    let text = format!(
        r#"<scene version="3.0.0">
    <sensor type="orthographic">
        <transform name="to_world">
            <scale x="{scale}" y="{scale}"/>
            <lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="48"/>
            <rfilter type="box"/></film>
    </sensor>
    {body}
</scene>"#
    );
    let root = read_scene_str(&text, &Path::new(".").join("scene.xml"), &[]).unwrap();
    build_scene(&root).unwrap().scene
}

/// Over an emitting plane that fills the film, every pixel of an orthographic camera measures
/// the plane's radiance: `<rgb value="2"/>` emission is D65 of luminance 2, so Y = 2.
#[test]
fn an_orthographic_camera_over_an_emitting_plane_sees_its_radiance() {
    let scene = orthographic_scene(
        2.0,
        r#"<shape type="rectangle"><transform name="to_world"><scale value="5"/></transform>
        <emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>"#,
    );
    let film = render_film(&scene, 64, 1, None);
    assert_mean_luminance("orthographic over a plane", &film, 2.0);
}

/// The image of an emitting disk of radius 0.6 (Y = 1) on black covers its area's share of
/// the film's 2s × 1.5s: the image's mean luminance is π 0.6² / (2s · 1.5s).
#[test]
fn the_orthographic_image_of_a_disk_has_the_disks_area() {
    let s = 1.5;
    let scene = orthographic_scene(
        s,
        r#"<shape type="disk"><transform name="to_world"><scale value="0.6"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#,
    );
    let film = render_film(&scene, 256, 2, None);
    let expected = std::f64::consts::PI * 0.36 / (2.0 * s * 1.5 * s);
    assert_mean_luminance("orthographic image of a disk", &film, expected);
}

/// A scene seen by a `radiancemeter` placed by `placement`, with `body` after the sensor.
fn radiance_meter_scene(placement: &str, body: &str) -> prism_core::error::Result<Scene> {
    let text = format!(
        r#"<scene version="3.0.0">
    <sensor type="radiancemeter">
        {placement}
        <sampler type="independent"><integer name="sample_count" value="16384"/></sampler>
        <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/><rfilter type="box"/></film>
    </sensor>
    {body}
</scene>"#
    );
    scene_from_xml(&text, "meter.xml")
}

/// A radiance meter sees the radiance along its one ray: an emitter of radiance 3 (a constant
/// spectrum, so Y = 3) straight ahead, whichever way the sensor is placed; beside the emitter
/// it sees nothing.
#[test]
fn a_radiance_meter_measures_the_radiance_along_its_ray() {
    let emitter = r#"<shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate y="1" angle="180"/><translate z="2"/></transform>
        <emitter type="area"><spectrum name="radiance" value="3"/></emitter>
    </shape>"#;
    for placement in [
        r#"<point name="origin" x="0.1" y="-0.2" z="-1"/><vector name="direction" x="0" y="0" z="2"/>"#,
        r#"<transform name="to_world"><lookat origin="0.1, -0.2, -1" target="0.1, -0.2, 0" up="0, 1, 0"/></transform>"#,
    ] {
        let scene = radiance_meter_scene(placement, emitter).unwrap();
        let film = render_film(&scene, 16384, 3, None);
        assert_mean_luminance(placement, &film, 3.0);
    }
    let aside = radiance_meter_scene(
        r#"<point name="origin" x="2" y="0" z="-1"/><vector name="direction" x="0" y="0" z="1"/>"#,
        emitter,
    )
    .unwrap();
    let film = render_film(&aside, 64, 3, None);
    assert_eq!(film.pixels[0].mean()[1], 0.0);
}

#[test]
fn a_radiance_meter_needs_a_one_pixel_film_and_both_origin_and_direction() {
    let error = load_sensor("radiancemeter", "", 2, 1)
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("must be 1 × 1 pixels"), "{error}");
    let error = radiance_meter_scene(r#"<point name="origin" x="0" y="0" z="0"/>"#, "")
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("needs both"), "{error}");
    let error = radiance_meter_scene(
        r#"<point name="origin" x="0" y="0" z="0"/><vector name="direction" x="0" y="0" z="0"/>"#,
        "",
    )
    .err()
    .unwrap()
    .to_string();
    assert!(error.contains("has no length"), "{error}");
}

/// The mean Y of the pixels `xs` (columns) of a film, and its standard error.
fn columns_mean_luminance(film: &prism_core::film::Film, xs: std::ops::Range<u32>) -> (f64, f64) {
    let width = film.size.x;
    let pixels: Vec<usize> = (0..film.pixels.len())
        .filter(|i| xs.contains(&(*i as u32 % width)))
        .collect();
    let count = pixels.len() as f64;
    let (sum, variance) = (pixels.iter())
        .map(|&i| pixel_mean_and_variance(film, i, 1))
        .fold((0.0, 0.0), |(s, v), (m, var)| (s + m, v + var));
    (sum / count, variance.sqrt() / count)
}

/// A one-pixel film with a box filter and `spp` independent samples.
fn one_pixel(spp: u32) -> String {
    format!(
        r#"<sampler type="independent"><integer name="sample_count" value="{spp}"/></sampler>
        <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/><rfilter type="box"/></film>"#
    )
}

/// An irradiance meter on a unit disk facing a coaxial emitting disk of radius 2 (radiance 1, a
/// constant spectrum, so Y = 1) at height 1 measures the disk's mean irradiance π F₁₂, F₁₂ the
/// form factor of parallel coaxial disks: ½ (X − √(X² − 4 (r₂/r₁)²)), X = 1 + (1 + r₂²/h²) h²/r₁²,
/// here ½ (6 − √20) and E = π (3 − √5) = 2.39996. Mitsuba 3.9.1 (`mitsuba-ref`, the same scene
/// with an `xyz` film, scalar_spectral, 2²⁰ spp, seed 7, 2 threads) gives Y = 2.40422; Prism at
/// 2²⁰ spp gives 2.40213.
#[test]
fn an_irradiance_meter_measures_the_form_factor_of_coaxial_disks() {
    let text = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <shape type="disk">
        <sensor type="irradiancemeter">{}</sensor>
    </shape>
    <shape type="disk">
        <transform name="to_world"><scale value="2"/><rotate x="1" angle="180"/><translate z="1"/></transform>
        <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
    </shape>
</scene>"#,
        one_pixel(1 << 16)
    );
    let scene = scene_from_xml(&text, "irradiance.xml").unwrap();
    let film = render_film(&scene, 1 << 16, 5, None);
    let expected = std::f64::consts::PI * (3.0 - 5.0f64.sqrt());
    assert_mean_luminance("irradiance meter under a disk", &film, expected);
}

/// The point light of intensity 1 at height 1 over the distant sensor's plane.
const POINT_LIGHT: &str = r#"<emitter type="point">
        <point name="position" x="0" y="0" z="1"/>
        <spectrum name="intensity" value="1"/>
    </emitter>"#;

/// A scene with a diffuse plane (ρ = 0.5) of 20 × 20 at z = 0 under `emitter`, seen by a
/// `distant` sensor looking straight down, with `target` given by `target`.
fn distant_scene(target: &str, emitter: &str, spp: u32) -> prism_core::error::Result<Scene> {
    let text = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="distant">
        <vector name="direction" x="0" y="0" z="-1"/>
        {target}
        {}
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale value="10"/></transform>
        <bsdf type="diffuse"><spectrum name="reflectance" value="0.5"/></bsdf>
    </shape>
    {emitter}
</scene>"#,
        one_pixel(spp)
    );
    scene_from_xml(&text, "distant.xml")
}

/// Aimed at the square [−1, 1]² under the light, a distant sensor measures the radiance ρ I
/// cos θ / (π d²) averaged over the square: ρ I Ω / (4π), Ω = 4 arctan(1/√3) = 2π/3 the solid
/// angle the square subtends at the light, so 1/12. Mitsuba 3.9.1 (`mitsuba-ref`, the same scene
/// with an `xyz` film, scalar_spectral, 2²⁰ spp, seed 7, 2 threads) gives Y = 0.083402; Prism at
/// 2²⁰ spp gives 0.083324.
#[test]
fn a_distant_sensor_averages_the_radiance_over_its_target_shape() {
    let target = r#"<shape type="rectangle" name="target"/>"#;
    let scene = distant_scene(target, POINT_LIGHT, 1 << 16).unwrap();
    let film = render_film(&scene, 1 << 16, 6, None);
    assert_mean_luminance("distant sensor aimed at a square", &film, 1.0 / 12.0);
}

/// Aimed at a point, every ray of a distant sensor is the same: the radiance leaving the plane
/// there, ρ I cos θ / (π d²), here at distance d = √2 and cos θ = 1/√2. Without a target, rays
/// cover the cross-section of the scene's bounding sphere, of radius R = 10√2 (1 + 10⁻⁴) around
/// the 20 × 20 plane: under a directional light of irradiance 1 the plane's radiance is ρ / π,
/// and the rays that miss it see nothing, so the mean is ρ / π · 400 / (π R²).
#[test]
fn a_distant_sensor_aims_at_a_point_or_at_the_whole_scene() {
    let target = r#"<point name="target" x="0.6" y="0.8" z="0"/>"#;
    let scene = distant_scene(target, POINT_LIGHT, 4096).unwrap();
    let film = render_film(&scene, 4096, 7, None);
    let (mean, se) = image_mean_and_standard_error(&film, 1);
    let expected = 0.5 / std::f64::consts::PI * 2.0f64.powf(-1.5);
    assert!(
        (mean - expected).abs() < (4.0 * se).max(1e-4 * expected),
        "aimed at a point: {mean} ± {se}, not {expected}"
    );

    let sun = r#"<emitter type="directional">
        <vector name="direction" x="0" y="0" z="-1"/>
        <spectrum name="irradiance" value="1"/>
    </emitter>"#;
    let scene = distant_scene("", sun, 1 << 17).unwrap();
    let film = render_film(&scene, 1 << 17, 8, None);
    let radius = 200.0f64.sqrt() * (1.0 + 1e-4);
    let cross_section = std::f64::consts::PI * radius * radius;
    let expected = 0.5 / std::f64::consts::PI * 400.0 / cross_section;
    assert_mean_luminance("distant sensor over the scene", &film, expected);
}

/// Two orthographic cameras in a batch on a 128 × 48 film each see a 64 × 48 film (the aspect
/// ratio of their own): the left one an emitting disk of radius 0.6, the right one, turned away,
/// a disk of radius 0.3; each half's mean luminance is its disk's share π r² / (2s · 1.5s) of
/// the film's extent, as for a single camera: 0.167552 and 0.041888. Mitsuba 3.9.1
/// (`mitsuba-ref`, the same scene with an `xyz` film, scalar_spectral, 256 spp, seed 3, 2
/// threads) gives 0.167543 and 0.041777, and its image matches Prism's pixel by pixel
/// (relMSE 2.4·10⁻⁴ in Y).
#[test]
fn a_batch_puts_its_sensors_side_by_side() {
    let s = 1.5;
    let camera = |z: f64| {
        format!(
            r#"<sensor type="orthographic">
            <transform name="to_world">
                <scale x="{s}" y="{s}"/>
                <lookat origin="0, 0, {z}" target="0, 0, {}" up="0, 1, 0"/>
            </transform>
        </sensor>"#,
            z - z.signum()
        )
    };
    let text = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="batch">
        {}
        {}
        <film type="hdrfilm"><integer name="width" value="128"/><integer name="height" value="48"/>
            <rfilter type="box"/></film>
    </sensor>
    <shape type="disk"><transform name="to_world"><scale value="0.6"/><translate z="1"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
    <shape type="disk"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="180"/><translate z="-1"/></transform>
        <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>
</scene>"#,
        camera(3.0),
        camera(-3.0)
    );
    let scene = scene_from_xml(&text, "batch.xml").unwrap();
    let film = render_film(&scene, 256, 9, None);
    for (columns, radius) in [(0..64, 0.6), (64..128, 0.3)] {
        let (mean, se) = columns_mean_luminance(&film, columns.clone());
        let expected = std::f64::consts::PI * radius * radius / (2.0 * s * 1.5 * s);
        assert!(se < 0.0025 * expected, "{columns:?}: {se}");
        assert!(
            (mean - expected).abs() < 4.0 * se,
            "columns {columns:?}: mean Y {mean} ± {se}, not {expected}"
        );
    }
}

/// A sensor carried by a shape stands among the scene's sensors where its shape stands.
#[test]
fn a_shape_sensor_stands_where_its_shape_does() {
    let text = format!(
        r#"<scene version="3.0.0">
    <shape type="sphere"><sensor type="irradiancemeter" id="meter">{}</sensor></shape>
    <sensor type="perspective" id="camera"/>
</scene>"#,
        one_pixel(4)
    );
    let root = read_scene_str(&text, &Path::new(".").join("scene.xml"), &[]).unwrap();
    let loaded = build_scene(&root).unwrap();
    let ids: Vec<_> = (loaded.sensors().iter())
        .map(|s| s.id.as_deref().unwrap())
        .collect();
    assert_eq!(ids, ["meter", "camera"]);
    assert!(matches!(loaded.scene.camera, Camera::IrradianceMeter(_)));
}

/// The new sensors' parameters are checked, each error at its element.
#[test]
fn meter_and_batch_errors_name_the_element() {
    let error = |xml: &str| {
        let text = format!(r#"<scene version="3.0.0">{xml}</scene>"#);
        scene_from_xml(&text, "bad.xml").err().unwrap().to_string()
    };
    let cases = [
        (
            format!(r#"<sensor type="irradiancemeter">{}</sensor>"#, one_pixel(4)),
            "must be nested in the <shape>",
        ),
        (
            format!(
                r#"<shape type="sphere"><sensor type="irradiancemeter"><transform name="to_world"/>{}</sensor></shape>"#,
                one_pixel(4)
            ),
            "has no \"to_world\"",
        ),
        (
            r#"<shape type="sphere"><sensor type="perspective"/></shape>"#.to_string(),
            "can carry an irradiancemeter",
        ),
        (
            format!(
                r#"<sensor type="distant"><vector name="direction" x="0" y="0" z="1"/><transform name="to_world"/>{}</sensor>"#,
                one_pixel(4)
            ),
            "not both",
        ),
        (
            r#"<sensor type="distant"/>"#.to_string(),
            "must be 1 × 1 pixels",
        ),
        (
            format!(
                r#"<sensor type="distant"><bsdf type="diffuse" name="target"/>{}</sensor>"#,
                one_pixel(4)
            ),
            "a point or a shape",
        ),
        (
            r#"<sensor type="batch"><sensor type="perspective"/><sensor type="perspective"/><sensor type="perspective"/><film type="hdrfilm"><integer name="width" value="64"/></film></sensor>"#.to_string(),
            "a multiple of 3",
        ),
    ];
    for (xml, expected) in cases {
        let message = error(&xml);
        assert!(message.contains(expected), "{xml}: {message}");
        assert!(
            message.contains("bad.xml:1:"),
            "{xml}: no location in {message}"
        );
    }
}

/// A `specfilm` over a constant environment of radiance L(λ) = 1 + 2 (λ − 400)/300 on
/// 400–700 nm (zero elsewhere): each channel is ∫ s L dλ, unnormalised, as Mitsuba 3 writes it.
/// A box response of 1 on 500–600 nm gives 200, a ramp s = 2 (λ − 400)/300 gives
/// ∫₀¹ 2t (1 + 2t) 300 dt = 700, a constant 0.5 gives 300. Mitsuba 3.9.1 (`mitsuba-ref`, the
/// first two seen by a radiance meter on an emitter of that radiance, scalar_spectral, 65536
/// spp, seed 3, 2 threads) gives 199.95 and 699.38 (it refuses a constant response). The
/// EXR holds the channels by their names beside Y and its statistics.
#[test]
fn a_spectral_film_integrates_the_radiance_against_each_response() {
    let text = r#"<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="perspective">
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="specfilm">
            <integer name="width" value="32"/><integer name="height" value="32"/>
            <rfilter type="box"/>
            <spectrum name="zeta" value="500:1, 600:1"/>
            <spectrum name="alpha" value="400:0, 700:2"/>
            <spectrum name="flat" value="0.5"/>
        </film>
    </sensor>
    <emitter type="constant"><spectrum name="radiance" value="400:1, 700:3"/></emitter>
</scene>"#;
    let scene = scene_from_xml(text, "specfilm.xml").unwrap();
    assert_eq!(scene.aov_names(), ["zeta", "alpha", "flat"]);
    assert_eq!(
        scene.exr_output.pixel_format,
        prism_core::film::PixelFormat::Luminance
    );
    let film = render_film(&scene, 64, 10, None);
    for (channel, expected) in [(0, 200.0), (1, 700.0), (2, 300.0)] {
        let values = film.aov(channel);
        let n = values.len() as f64;
        let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let variance = values
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        let se = (variance / n).sqrt();
        assert!(se < 0.0025 * expected, "channel {channel}: {se}");
        assert!(
            (mean - expected).abs() < 4.0 * se,
            "channel {channel}: {mean} ± {se}, not {expected}"
        );
    }
}

/// A spectral film's responses must be finite, lie in Prism's wavelength range and not take the
/// image's channel names; it needs one.
#[test]
fn spectral_film_errors_name_the_spectrum() {
    let error = |bands: &str| {
        let text = format!(
            r#"<scene version="3.0.0">
    <sensor type="perspective"><film type="specfilm">{bands}</film></sensor>
</scene>"#
        );
        scene_from_xml(&text, "bad.xml").err().unwrap().to_string()
    };
    for (bands, expected) in [
        ("", "at least one response"),
        (
            r#"<spectrum name="Y" value="1"/>"#,
            "would replace the image's own",
        ),
        (
            r#"<spectrum name="nir" value="800:1, 900:1"/>"#,
            "not zero at 900 nm",
        ),
    ] {
        let message = error(bands);
        assert!(message.contains(expected), "{bands}: {message}");
        assert!(
            message.contains("bad.xml:"),
            "{bands}: no location in {message}"
        );
    }
}

/// A radiance meter facing an emitter of radiance `radiance`, its sensor given `srf`.
fn response_scene(srf: &str, radiance: &str) -> Scene {
    let text = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <sensor type="radiancemeter">
        <point name="origin" x="0" y="0" z="-1"/><vector name="direction" x="0" y="0" z="1"/>
        {srf}
        {}
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><rotate y="1" angle="180"/><translate z="1"/></transform>
        <emitter type="area"><spectrum name="radiance" value="{radiance}"/></emitter>
    </shape>
</scene>"#,
        one_pixel(1 << 16)
    );
    scene_from_xml(&text, "srf.xml").unwrap()
}

/// A sensor's `srf` multiplies the radiance at each wavelength: a box response on 500–600 nm
/// over a constant radiance 1 gives the image of a box radiance under a response of 1, the
/// same wavelengths giving the same values. Mitsuba 3.9.1 (`mitsuba-ref`, xyz film,
/// scalar_spectral, 2¹⁸ spp, seed 3, 2 threads) gives Y = 0.757729 for the first and 0.757575
/// for the second; a constant response of 0.5 halves the image.
#[test]
fn a_sensor_response_filters_the_radiance() {
    let filtered = response_scene(r#"<spectrum name="srf" value="500:1, 600:1"/>"#, "1");
    let boxed = response_scene("", "500:1, 600:1");
    let a = render_film(&filtered, 1 << 16, 11, None);
    let b = render_film(&boxed, 1 << 16, 11, None);
    let (mean_a, se) = image_mean_and_standard_error(&a, 1);
    let (mean_b, _) = image_mean_and_standard_error(&b, 1);
    assert!(
        (mean_a - mean_b).abs() <= 1e-6 * mean_b,
        "{mean_a} against {mean_b}"
    );
    assert!(
        (mean_a - 0.757729).abs() < 4.0 * se + 1e-3 * 0.757729,
        "{mean_a} ± {se}"
    );

    let half = response_scene(r#"<spectrum name="srf" value="0.5"/>"#, "1");
    let film = render_film(&half, 1 << 16, 12, None);
    let (mean, se) = image_mean_and_standard_error(&film, 1);
    assert!((mean - 0.5).abs() < 4.0 * se + 1e-6, "{mean} ± {se}");

    let text = r#"<scene version="3.0.0"><sensor type="perspective">
        <spectrum name="srf" value="1"/>
        <film type="specfilm"><spectrum name="band" value="1"/></film>
    </sensor></scene>"#;
    let error = scene_from_xml(text, "bad.xml").err().unwrap().to_string();
    assert!(error.contains("cannot have a specfilm"), "{error}");
}

/// An irradiance meter on a mesh, the rectangle [−2, 2] × [−1, 1], under an emitting sphere
/// (radiance 1, radius r = 0.3, centre 0.7 above (1.5, 0.5), wholly above the plane): a
/// sphere's irradiance at p is π r² h / d³ (h the centre's height, d its distance), so the
/// mean over the area A = 8 is π r² Ω / A, Ω = ∫ h / d³ dA the solid angle the rectangle
/// subtends at the centre, the sum of arctan(ab / (h √(a² + b² + h²))) over the four rectangles
/// the foot of the centre cuts it into: 0.0918930. The points come from the mesh's
/// `sample_position`, which picks a triangle and reuses the number. Mitsuba 3.9.1 (`mitsuba-ref`,
/// xyz film, scalar_spectral, 2²⁰ spp, seed 7, 2 threads) gives Y = 0.091965; Prism at 2²⁰ spp
/// 0.091906.
#[test]
fn an_irradiance_meter_on_a_mesh_averages_over_its_area() {
    let text = format!(
        r#"<scene version="3.0.0">
    <integrator type="path"/>
    <shape type="rectangle">
        <transform name="to_world"><scale x="2" y="1"/></transform>
        <sensor type="irradiancemeter">{}</sensor>
    </shape>
    <shape type="sphere">
        <point name="center" x="1.5" y="0.5" z="0.7"/>
        <float name="radius" value="0.3"/>
        <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
    </shape>
</scene>"#,
        one_pixel(1 << 19)
    );
    let scene = scene_from_xml(&text, "mesh-meter.xml").unwrap();
    let film = render_film(&scene, 1 << 19, 13, None);
    let h = 0.7f64;
    let corner = |a: f64, b: f64| (a * b / (h * (a * a + b * b + h * h).sqrt())).atan();
    let omega = corner(3.5, 1.5) + corner(3.5, 0.5) + corner(0.5, 1.5) + corner(0.5, 0.5);
    let expected = std::f64::consts::PI * 0.09 * omega / 8.0;
    let (mean, se) = image_mean_and_standard_error(&film, 1);
    assert!(se < 0.01 * expected, "{se}");
    assert!(
        (mean - expected).abs() < 4.0 * se,
        "mean Y {mean} ± {se}, not {expected}"
    );
}
