//! Scenes with several `<sensor>`s, as Mitsuba reads them: every sensor is built (an error in
//! any is reported), the first is rendered unless another is chosen by its index from 0 or its
//! id (`prism render --sensor`, Python's `render(sensor=...)`), and a render through a chosen
//! sensor is the render of the scene with that sensor alone.

use std::path::Path;
use std::process::Command;

use prism_mitsuba::LoadedScene;

use crate::common::scenes::render_film;

/// A sensor looking at the emitting rectangle from `origin`, with a `width` × 4 film and the
/// sampler's `seed`.
fn sensor(id: &str, origin: &str, width: u32, seed: u32) -> String {
    format!(
        r#"<sensor type="perspective" {id}>
        <transform name="to_world"><lookat origin="{origin}" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/><integer name="seed" value="{seed}"/></sampler>
        <film type="hdrfilm"><integer name="width" value="{width}"/><integer name="height" value="4"/><rfilter type="box"/></film>
    </sensor>"#
    )
}

fn scene_with(sensors: &[String]) -> String {
    format!(
        r#"<scene version="3.0.0">
    {}
    <shape type="rectangle"><transform name="to_world"><translate x="0.3"/></transform><emitter type="area"/></shape>
    <shape type="sphere"><float name="radius" value="0.4"/></shape>
    <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
</scene>"#,
        sensors.join("\n    ")
    )
}

fn sensors() -> [String; 3] {
    [
        sensor("", "0, 0, 4", 6, 1),
        sensor(r#"id="side""#, "3, 1, 3", 5, 2),
        sensor(r#"id="top""#, "0.5, 4, 0.5", 3, 3),
    ]
}

fn load(xml: &str) -> LoadedScene {
    let root = prism_mitsuba::reader::read_scene_str(xml, Path::new("sensors.xml"), &[])
        .unwrap_or_else(|e| panic!("{e}"));
    prism_mitsuba::factory::build_scene(&root).unwrap_or_else(|e| panic!("{e}"))
}

/// Every pixel's sums, which are equal only for the same samples.
fn pixels(loaded: &LoadedScene) -> Vec<[f64; 3]> {
    let film = render_film(&loaded.scene, 4, loaded.seed, Some(2));
    (film.pixels.iter())
        .map(|p| [p.sum(0), p.sum(1), p.sum(2)])
        .collect()
}

#[test]
fn the_first_sensor_is_rendered_unless_another_is_chosen() {
    let [first, side, top] = sensors();
    let mut loaded = load(&scene_with(&[first.clone(), side.clone(), top.clone()]));
    let ids: Vec<Option<&str>> = (loaded.sensors().iter()).map(|s| s.id.as_deref()).collect();
    assert_eq!(ids, [None, Some("side"), Some("top")]);
    assert_eq!(loaded.selected_sensor(), 0);
    assert_eq!(loaded.scene.film.size.x, 6);
    let alone = load(&scene_with(std::slice::from_ref(&first)));
    assert_eq!(pixels(&loaded), pixels(&alone));
    assert_eq!(loaded.scene.fingerprint, {
        // The first sensor keeps the description's fingerprint.
        let root = prism_mitsuba::reader::read_scene_str(
            &scene_with(&[first.clone(), side.clone(), top.clone()]),
            Path::new("sensors.xml"),
            &[],
        )
        .unwrap();
        prism_mitsuba::fingerprint::scene_fingerprint(&root)
    });
    let first_fingerprint = loaded.scene.fingerprint;

    for (choice, index, alone) in [("side", 1, &side), ("2", 2, &top), ("top", 2, &top)] {
        loaded
            .select_sensor(loaded.find_sensor(choice).unwrap())
            .unwrap();
        assert_eq!(loaded.selected_sensor(), index);
        assert_ne!(loaded.scene.fingerprint, first_fingerprint);
        let alone = load(&scene_with(std::slice::from_ref(alone)));
        assert_eq!(loaded.scene.film.size, alone.scene.film.size);
        assert_eq!(loaded.seed, alone.seed);
        assert_eq!(pixels(&loaded), pixels(&alone), "sensor {choice}");
    }
    loaded.select_sensor(0).unwrap();
    assert_eq!(loaded.scene.fingerprint, first_fingerprint);
    assert_eq!(pixels(&loaded), pixels(&load(&scene_with(&[first]))));
}

#[test]
fn a_wavelength_override_carries_over_to_the_chosen_sensor() {
    use prism_core::spectrum::WavelengthSampling;
    let [first, side, _] = sensors();
    let mut loaded = load(&scene_with(&[first, side]));
    let density = WavelengthSampling::Uniform;
    assert_ne!(loaded.scene.film.wavelength_sampling, density);
    prism_mitsuba::fingerprint::override_wavelengths(&mut loaded.scene, density);
    loaded.select_sensor(1).unwrap();
    assert_eq!(loaded.scene.film.wavelength_sampling, density);
}

#[test]
fn a_sensor_that_does_not_exist_is_an_error_that_lists_them() {
    let [first, side, top] = sensors();
    let mut loaded = load(&scene_with(&[first, side, top]));
    let error = loaded.find_sensor("front").unwrap_err().to_string();
    assert!(
        error.contains("the scene has no sensor \"front\"")
            && error.contains("from 0 to 2")
            && error.contains("\"side\", \"top\""),
        "{error}"
    );
    let error = loaded.find_sensor("3").unwrap_err().to_string();
    assert!(error.contains("the scene has no sensor 3"), "{error}");
    assert!(loaded.select_sensor(7).is_err());
    assert_eq!(loaded.selected_sensor(), 0);
}

/// Mitsuba builds every sensor: an error in one that is not rendered is still reported.
#[test]
fn every_sensor_is_checked() {
    let [first, _, _] = sensors();
    let broken = r#"<sensor type="perspective"><float name="fov" value="-3"/></sensor>"#;
    let xml = scene_with(&[first, broken.to_string()]);
    let root = prism_mitsuba::reader::read_scene_str(&xml, Path::new("sensors.xml"), &[]).unwrap();
    assert!(prism_mitsuba::factory::build_scene(&root).is_err());
}

/// `prism render --sensor` by id and by index writes the chosen sensor's film; a sensor that
/// does not exist is a usage error.
#[test]
fn the_command_line_renders_the_chosen_sensor() {
    let [first, side, top] = sensors();
    let folder = std::env::temp_dir().join(format!("prism-sensors-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    let scene = folder.join("sensors.xml");
    std::fs::write(&scene, scene_with(&[first, side, top])).unwrap();
    for (choice, width) in [(None, 6), (Some("side"), 5), (Some("2"), 3)] {
        let out = folder.join(format!("{}.exr", choice.unwrap_or("default")));
        let mut command = Command::new(env!("CARGO_BIN_EXE_prism"));
        command
            .args(["render", "--quiet", "-o"])
            .arg(&out)
            .arg(&scene);
        if let Some(choice) = choice {
            command.args(["--sensor", choice]);
        }
        let output = command.output().expect("the prism binary runs");
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let image = prism_core::image::read_exr(&out).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (image.width, image.height),
            (width, 4),
            "--sensor {choice:?}"
        );
    }
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(["render", "--quiet", "--sensor", "front"])
        .arg(&scene)
        .output()
        .expect("the prism binary runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("the scene has no sensor \"front\""),
        "{stderr}"
    );
    std::fs::remove_dir_all(&folder).unwrap();
}
