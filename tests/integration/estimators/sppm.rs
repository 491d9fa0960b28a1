//! Stochastic progressive photon mapping (`sppm`): against closed forms (a furnace, and a box
//! whose corners its radius blurs, with the error falling as the passes grow), against the
//! path tracer on the Cornell box, bit-identical for any thread count, resumed chains equal to
//! one render (through the library and the command line), merged chains equal to the
//! pass-weighted mean of their images, bad states and its bad parameters refused. Its images are
//! biased at any finite pass count, so the tolerances are stated per test instead of taken from a
//! variance the film does not have.

use std::path::Path;
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use glam::{DMat4, DVec3, Mat3, UVec2, Vec3};
use prism_core::film::{Film, PixelFormat, PixelSums};
use prism_core::geometry::{Shape, Sphere};
use prism_core::image::read_exr;
use prism_core::integrator::{Integrator, PathIntegrator, SppmIntegrator};
use prism_core::math::Transform;
use prism_core::render::resume::{Continuation, InitialState};
use prism_core::render::state::{IntegratorState, RenderState};
use prism_core::render::{
    Checkpoints, Preview, RenderOptions, RenderOutput, Snapshot, StopReason, StopRule, render,
    render_with_checkpoints, render_with_preview,
};
use prism_core::scene::Scene;
use prism_mitsuba::factory::shapes::{cube, transform_mesh};

use crate::common::scenes::{Object, build, camera, render_film, scene_from_xml};

fn sppm(photon_count: u32, initial_radius: Option<f32>) -> Integrator {
    Integrator::from(SppmIntegrator {
        photon_count,
        initial_radius,
        ..SppmIntegrator::default()
    })
}

/// A closed room of shape `shape` whose every surface has reflectance rho and emits le: the
/// radiance everywhere is le / (1 − rho).
fn furnace(shape: Shape, rho: f32, le: f32, integrator: Integrator) -> Scene {
    let size = UVec2::new(16, 16);
    let camera = camera(
        DVec3::new(0.1, 0.2, -0.3),
        DVec3::new(0.5, 0.3, 1.0),
        DVec3::Y,
        70.0,
        size,
    );
    let object = Object {
        shape: shape.into(),
        reflectance: rho,
        emission: Some(le),
    };
    build(vec![object], vec![], camera, size, integrator)
}

fn inner_sphere() -> Shape {
    Shape::Sphere(Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
        rotation: Mat3::IDENTITY,
        flip_normals: true,
    })
}

/// The inside of a 2 × 3 × 4 box.
fn inner_box() -> Shape {
    let to_world = Transform::new(DMat4::from_scale(DVec3::new(1.0, 1.5, 2.0))).unwrap();
    Shape::Mesh(transform_mesh(cube(), &to_world, true, true))
}

/// The mean of Y over the image.
fn mean_luminance(film: &Film) -> f64 {
    film.pixels.iter().map(|p| p.mean()[1]).sum::<f64>() / film.pixels.len() as f64
}

/// Inside a sphere every disc around a visible point sees the same photon density, so the
/// estimate has no radius bias: after 64 passes of 20,000 photons the image's mean is within
/// 1 % of le / (1 − rho) = 2 (the spread of the mean over seeds is about 0.2 %).
#[test]
fn sppm_sphere_furnace_gives_le_over_one_minus_rho() {
    let scene = furnace(inner_sphere(), 0.5, 1.0, sppm(20_000, None));
    let film = render_film(&scene, 64, 1, None);
    let mean = mean_luminance(&film);
    assert!((mean - 2.0).abs() < 0.02, "mean Y {mean}, expected 2");
}

/// The mean absolute error of Y over the pixels against `expected`.
fn mean_absolute_error(film: &Film, expected: f64) -> f64 {
    film.pixels
        .iter()
        .map(|p| (p.mean()[1] - expected).abs())
        .sum::<f64>()
        / film.pixels.len() as f64
}

/// In a box the search discs of points near its edges reach past them, which biases the
/// estimate there; the radius shrinks as the passes grow, and so does the error: with a large
/// initial radius (0.4 in a 2 × 3 × 4 box), the mean absolute error of the pixels against
/// le / (1 − rho) = 2 after 64 passes is under 0.7 times that after 8 (0.13 against 0.23 with
/// these seeds).
#[test]
fn sppm_error_in_a_box_falls_as_the_passes_grow() {
    let scene = furnace(inner_box(), 0.5, 1.0, sppm(10_000, Some(0.4)));
    let early = mean_absolute_error(&render_film(&scene, 8, 2, None), 2.0);
    let late = mean_absolute_error(&render_film(&scene, 64, 2, None), 2.0);
    assert!(
        late < 0.7 * early,
        "mean absolute error {early} after 8 passes, {late} after 64"
    );
}

fn cornell_box(size: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml");
    let defines = [
        ("resx".to_string(), size.to_string()),
        ("resy".to_string(), size.to_string()),
    ];
    prism_mitsuba::load_scene(&path, &defines).unwrap().scene
}

/// On the Cornell box (direct light, indirect light and the luminaire seen directly) the image
/// means of X, Y and Z agree with the path tracer's within 3 %: the path tracer's standard
/// error is about 0.5 %, and the rest allows for sppm's blur at the box's edges after 64
/// passes.
#[test]
fn sppm_and_path_agree_on_the_cornell_box() {
    let mut scene = cornell_box(24);
    let path = render_film(&scene, 512, 3, None);
    scene.integrator = sppm(50_000, None);
    let photons = render_film(&scene, 64, 4, None);
    for c in 0..3 {
        let mean = |film: &Film| {
            film.pixels.iter().map(|p| p.mean()[c]).sum::<f64>() / film.pixels.len() as f64
        };
        let (a, b) = (mean(&photons), mean(&path));
        assert!(
            (a / b - 1.0).abs() < 0.03,
            "channel {c}: sppm {a}, path {b}"
        );
    }
}

/// The same image, bit for bit, on one thread and on two, and the variance the film reports is
/// no error bar: every pixel holds its estimate as one sample, whose variance is infinite.
#[test]
fn sppm_is_deterministic_and_claims_no_error_bar() {
    let scene = furnace(inner_box(), 0.5, 1.0, sppm(5_000, None));
    let one = render_film(&scene, 4, 7, Some(1));
    let two = render_film(&scene, 4, 7, Some(2));
    for (a, b) in one.pixels.iter().zip(&two.pixels) {
        assert_eq!(a.mean(), b.mean());
        assert_eq!(a.samples, 1);
        assert!(a.variance_of_mean(1).is_infinite());
    }
}

/// Parameters outside their ranges are refused when the scene is read, naming the parameter.
#[test]
fn sppm_refuses_bad_parameters() {
    let cases = [
        (r#"<float name="alpha" value="1"/>"#, "alpha"),
        (r#"<float name="alpha" value="0"/>"#, "alpha"),
        (
            r#"<integer name="photon_count" value="0"/>"#,
            "photon_count",
        ),
        (r#"<integer name="max_passes" value="0"/>"#, "max_passes"),
        (r#"<integer name="max_depth" value="1"/>"#, "max_depth"),
        (r#"<integer name="rr_depth" value="0"/>"#, "rr_depth"),
        (r#"<integer name="granularity" value="-2"/>"#, "granularity"),
        (
            r#"<float name="initial_radius" value="-1"/>"#,
            "initial_radius",
        ),
    ];
    for (parameter, name) in cases {
        let xml = format!(
            r#"<scene version="3.0.0"><integrator type="sppm">{parameter}</integrator>
                <shape type="sphere"><bsdf type="diffuse"/></shape></scene>"#
        );
        let error = match scene_from_xml(&xml, "sppm-test.xml") {
            Ok(_) => panic!("{parameter} was accepted"),
            Err(error) => error.to_string(),
        };
        assert!(error.contains(name), "{parameter}: {error}");
    }
}

/// A target error is refused with a message naming sppm: nothing estimates the error of its
/// biased image.
#[test]
fn sppm_refuses_a_target_error() {
    let scene = furnace(inner_sphere(), 0.5, 1.0, sppm(1_000, None));
    let target = RenderOptions {
        stop: StopRule {
            target_error: Some(0.01),
            ..StopRule::samples(4)
        },
        ..RenderOptions::fixed(4, 0, None)
    };
    let error = render(&scene, &target).err().expect("accepted").to_string();
    assert!(error.contains("sppm"), "{error}");
}

/// The Mitsuba 0.6 scenes of scenes/sppm render as written (one small pass each), and their
/// caustics are lit.
#[test]
fn sppm_scenes_render_as_written() {
    for name in ["torus", "lamp"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/sppm/{name}.xml"));
        let defines = [
            ("resx", "16"),
            ("resy", "12"),
            ("passes", "2"),
            ("photons", "5000"),
        ]
        .map(|(k, v)| (k.to_string(), v.to_string()));
        let scene = prism_mitsuba::load_scene(&path, &defines).unwrap().scene;
        assert!(matches!(scene.integrator, Integrator::Sppm(_)), "{name}");
        let film = render(&scene, &RenderOptions::fixed(1, 0, None))
            .unwrap()
            .film;
        assert!(mean_luminance(&film) > 0.0, "{name}: black");
    }
}

/// A small sppm render to continue and merge: the 2 × 3 × 4 box furnace at 16 × 16 pixels,
/// with the coverage alpha (an extra channel).
fn small_scene() -> Scene {
    let mut scene = furnace(inner_box(), 0.5, 1.0, sppm(2_000, None));
    scene.exr_output.pixel_format = PixelFormat::Rgba;
    scene
}

/// Samples per pixel of the sampler's stratification in the renders of sample ranges.
const STRATA: u32 = 16;

/// The render of sample indices `first..end` (one chain, or the rest of one from `initial`).
fn render_range(
    scene: &Scene,
    first: u32,
    end: u32,
    initial: Option<InitialState>,
    threads: usize,
) -> prism_core::error::Result<RenderOutput> {
    let options = RenderOptions {
        first_sample: first,
        initial,
        stop: StopRule::samples(end),
        ..RenderOptions::fixed(STRATA, 11, Some(threads))
    };
    render(scene, &options)
}

/// P₁ passes, then resumed to P, equal P passes in one go, bit for bit: the film and the
/// integrator state, at several split points, on one thread and on two; and so does a render
/// resumed from each checkpoint written between its passes.
#[test]
fn sppm_resumed_renders_equal_one_render() {
    let scene = small_scene();
    let whole = render_range(&scene, 0, 6, None, 2).unwrap();
    assert!(whole.film.pixels.iter().any(|p| p.sum(1) > 0.0), "black");
    for threads in [1, 2] {
        for split in [1, 3, 5] {
            let part = render_range(&scene, 0, split, None, threads).unwrap();
            let resumed = render_range(&scene, split, 6, Some(part.initial_state()), threads);
            let resumed = resumed.unwrap();
            assert_eq!(resumed.samples, split..6);
            assert_eq!(resumed.film.pixels, whole.film.pixels, "split at {split}");
            assert_eq!(resumed.film.aovs, whole.film.aovs, "split at {split}");
            assert_eq!(resumed.integrator_state, whole.integrator_state);
        }
    }
    // A checkpoint after every pass and one at the end.
    let mut snapshots = Vec::new();
    let mut write = |snapshot: &Snapshot| {
        snapshots.push((snapshot.samples.clone(), snapshot.initial_state()));
        Ok(())
    };
    let checkpoints = Checkpoints {
        every: Duration::ZERO,
        write: &mut write,
    };
    let options = RenderOptions {
        stop: StopRule::samples(6),
        ..RenderOptions::fixed(STRATA, 11, Some(2))
    };
    let checkpointed = render_with_checkpoints(&scene, &options, Some(checkpoints)).unwrap();
    assert_eq!(checkpointed.film.pixels, whole.film.pixels);
    assert_eq!(snapshots.len(), 7);
    for (samples, initial) in snapshots {
        let end = samples.end;
        let resumed = render_range(&scene, end, 6, Some(initial), 1).unwrap();
        assert_eq!(resumed.film.pixels, whole.film.pixels, "from {end}");
        assert_eq!(resumed.integrator_state, whole.integrator_state);
    }
}

/// A render interrupted after its second pass (the flag raised from its preview, as a signal
/// handler would between passes) stops there and hands out its state, from which a resumed
/// render ends as one that never stopped.
#[test]
fn sppm_interrupted_render_leaves_a_state_to_resume_from() {
    let scene = small_scene();
    let whole = render_range(&scene, 0, 6, None, 2).unwrap();
    let interrupt = Arc::new(AtomicBool::new(false));
    let mut raise = |snapshot: &Snapshot| -> prism_core::error::Result<()> {
        if snapshot.samples.end == 2 {
            interrupt.store(true, Ordering::Relaxed);
        }
        Ok(())
    };
    let options = RenderOptions {
        interrupt: Some(interrupt.clone()),
        stop: StopRule::samples(6),
        ..RenderOptions::fixed(STRATA, 11, Some(2))
    };
    let stopped = render_with_preview(&scene, &options, None, Some(&mut raise as Preview)).unwrap();
    assert_eq!(stopped.stop, StopReason::Interrupted);
    assert_eq!(stopped.samples, 0..2);
    let resumed = render_range(&scene, 2, 6, Some(stopped.initial_state()), 1).unwrap();
    assert_eq!(resumed.film.pixels, whole.film.pixels);
    assert_eq!(resumed.integrator_state, whole.integrator_state);
}

/// The state of the render of `output`, as the command line saves it.
fn state_of(scene: &Scene, output: &RenderOutput) -> RenderState {
    Continuation::new(scene, 11, scene.strata(STRATA)).state(&Snapshot {
        samples: output.samples.clone(),
        pixels: &output.film.pixels,
        aovs: &output.film.aovs,
        integrator_state: output.integrator_state.as_ref(),
    })
}

/// Chains of the sample ranges 0..4 and 4..10 are independent estimates (their images differ),
/// and their merge, in either order, is the pass-weighted mean (4 L₁ + 6 L₂) / 10 of their
/// images, bit for bit, held as each pixel's one sample: still no error bar. A merge of
/// adjacent ranges holds one range, 0..10, and is still refused on resume, from its file.
#[test]
fn sppm_merged_chains_are_the_pass_weighted_mean_of_their_images() {
    let scene = small_scene();
    let first = render_range(&scene, 0, 4, None, 2).unwrap();
    let second = render_range(&scene, 4, 10, None, 1).unwrap();
    assert_eq!(
        second.film.pixels,
        render_range(&scene, 4, 10, None, 2).unwrap().film.pixels
    );
    assert_ne!(first.film.pixels, second.film.pixels);
    let states = [state_of(&scene, &first), state_of(&scene, &second)];
    let paths = [Path::new("first.state"), Path::new("second.state")];
    let merged = RenderState::merge(&states, &paths).unwrap();
    let swapped = [states[1].clone(), states[0].clone()];
    assert_eq!(
        RenderState::merge(&swapped, &[paths[1], paths[0]]).unwrap(),
        merged
    );
    assert_eq!(merged.ranges.as_slice(), std::slice::from_ref(&(0..10)));
    for (i, pixel) in merged.pixels.iter().enumerate() {
        let (a, b) = (first.film.pixels[i].mean(), second.film.pixels[i].mean());
        let mut expected = PixelSums::default();
        expected.add_total([0, 1, 2].map(|c| (4.0 * a[c] + 6.0 * b[c]) / 10.0));
        assert_eq!(*pixel, expected, "pixel {i}");
        assert!(pixel.variance_of_mean(1).is_infinite());
    }
    assert!(!merged.aovs.is_empty());
    assert_eq!(merged.aovs, first.film.aovs);

    let dir = std::env::temp_dir().join(format!("prism-sppm-merge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("merged.state");
    merged.write(&path).unwrap();
    let mut continuation = Continuation::new(&scene, 11, scene.strata(STRATA));
    let (end, initial) = continuation.resume(&path, 0).unwrap();
    assert_eq!(end, 10);
    let error = render_range(&scene, 10, 12, Some(initial), 1)
        .err()
        .expect("a merge was resumed")
        .to_string();
    assert!(error.contains("merge of 2 sppm chains"), "{error}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A damaged or truncated sppm state, one of passes that do not end where the resumed render
/// starts, and one of another integrator are refused with a message that says so; and a path
/// tracer refuses sppm's state.
#[test]
fn sppm_refuses_bad_and_foreign_states() {
    let scene = small_scene();
    let part = render_range(&scene, 0, 2, None, 1).unwrap();
    let good = part.integrator_state.clone().unwrap();
    let with_bytes = |bytes: Vec<u8>| InitialState {
        integrator: Some(IntegratorState {
            bytes,
            ..good.clone()
        }),
        ..part.initial_state()
    };
    let mut unknown_kind = good.bytes.clone();
    unknown_kind[0] = 9;
    let mut not_a_number = good.bytes.clone();
    not_a_number[17..25].copy_from_slice(&f64::NAN.to_le_bytes());
    let mut longer = good.bytes.clone();
    longer.push(0);
    let damaged = [
        (with_bytes(Vec::new()), "sppm statistics"),
        (with_bytes(good.bytes[..20].to_vec()), "sppm statistics"),
        (
            with_bytes(good.bytes[..good.bytes.len() - 8].to_vec()),
            "sppm statistics",
        ),
        (with_bytes(longer), "sppm statistics"),
        (with_bytes(unknown_kind), "unknown kind"),
        (with_bytes(not_a_number), "radius"),
    ];
    for (initial, says) in damaged {
        let error = render_range(&scene, 2, 4, Some(initial), 1)
            .err()
            .expect("a damaged state was resumed")
            .to_string();
        assert!(error.contains(says), "{error}");
    }
    let error = render_range(&scene, 3, 4, Some(part.initial_state()), 1)
        .err()
        .expect("resumed at the wrong sample")
        .to_string();
    assert!(error.contains("do not end where"), "{error}");

    let mut path_scene = small_scene();
    path_scene.integrator = Integrator::from(PathIntegrator::default());
    let path = render_range(&path_scene, 0, 2, None, 1).unwrap();
    let error = render_range(&scene, 2, 4, Some(path.initial_state()), 1)
        .err()
        .expect("sppm resumed a path state")
        .to_string();
    assert!(error.contains("no sppm statistics"), "{error}");
    let error = render_range(&path_scene, 2, 4, Some(part.initial_state()), 1)
        .err()
        .expect("path resumed an sppm state")
        .to_string();
    assert!(error.contains("sppm"), "{error}");
}

/// A scene file for the command line: an sppm render of a lit room of 8 samples per pixel whose
/// pass count is the sample count unless `-D max_passes=N` sets one.
const ROOM_XML: &str = r#"<scene version="3.0.0">
    <default name="max_passes" value="-1"/>
    <integrator type="sppm">
        <integer name="photon_count" value="2000"/>
        <integer name="max_passes" value="$max_passes"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world"><lookat origin="0, 0, 0.9" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="8"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="12"/><integer name="height" value="10"/>
            <string name="pixel_format" value="rgba"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <shape type="sphere">
        <float name="radius" value="2"/><boolean name="flip_normals" value="true"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.4, 0.3"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="0.3" y="0.5" z="-0.5"/><float name="radius" value="0.2"/>
        <emitter type="area"><rgb name="radiance" value="10, 9, 8"/></emitter>
    </shape>
</scene>"#;

/// Runs `prism` with `arguments` in `dir`: its exit status and what it wrote to stderr.
fn prism(dir: &Path, arguments: &[&str]) -> (i32, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .current_dir(dir)
        .args(arguments)
        .output()
        .unwrap();
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Every channel of two EXR files, compared bit for bit.
fn assert_identical_images(a: &Path, b: &Path) {
    let (a, b) = (read_exr(a).unwrap(), read_exr(b).unwrap());
    assert_eq!((a.width, a.height), (b.width, b.height));
    for (name, values) in &a.channels {
        let other = b.channel(name).unwrap();
        let same = values
            .iter()
            .zip(other)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "channel {name} differs");
    }
}

/// Through the command line: a chain of 3 passes checkpointed, then resumed to 8 on two threads,
/// gives the image of 8 passes in one go; `prism merge` of two chains says that its image has the
/// bias of one chain and no error estimate, and its state is refused on resume; where
/// `maxPasses` exceeds the sample count, a chain resumed past the sample count still ends at
/// `maxPasses`.
#[test]
fn sppm_checkpoints_resume_and_merge_through_the_command_line() {
    let dir = std::env::temp_dir().join(format!("prism-sppm-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("room.xml"), ROOM_XML).unwrap();
    let run = |arguments: &str| {
        let arguments: Vec<&str> = arguments.split_whitespace().collect();
        prism(&dir, &arguments)
    };
    let render = |arguments: &str| {
        let (status, text) = run(&format!("render room.xml {arguments}"));
        assert_eq!(status, 0, "{text}");
    };
    render("--threads 1 -o whole.exr");
    render("--threads 1 --sample-range 0..3 --checkpoint part.state -o part.exr");
    render("--threads 2 --resume part.state -o resumed.exr");
    assert_identical_images(&dir.join("resumed.exr"), &dir.join("whole.exr"));

    render("--threads 1 --sample-range 8..12 --checkpoint later.state -o later.exr");
    let (status, text) = run("merge part.state later.state -o merged.exr --state merged.state");
    assert_eq!(status, 0, "{text}");
    assert!(
        text.contains("pass-weighted mean of 2 independent sppm chains"),
        "{text}"
    );
    assert!(text.contains("biased as one chain"), "{text}");
    assert!(text.contains("no error estimate"), "{text}");
    let merged = read_exr(&dir.join("merged.exr")).unwrap();
    let variance = merged.channel("variance.Y").unwrap();
    assert!(variance.iter().all(|v| v.is_infinite()), "an error bar");
    assert!(merged.channel("A").unwrap().iter().all(|&a| a == 1.0));
    let (status, text) = run("render room.xml --sample-range 0..20 --resume merged.state -o x.exr");
    assert_eq!(status, 2, "{text}");
    assert!(text.contains("merge of 2 sppm chains"), "{text}");

    // With `maxPasses` 11 (more than the 8 samples), a chain stopped after 9 passes (by an
    // interruption, here raised from the library's preview) resumes to 11.
    render("-D max_passes=11 --threads 2 -o long.exr");
    let defines = [("max_passes".to_string(), "11".to_string())];
    let loaded = prism_mitsuba::load_scene(&dir.join("room.xml"), &defines).unwrap();
    let scene = loaded.scene;
    let interrupt = Arc::new(AtomicBool::new(false));
    let mut raise = |snapshot: &Snapshot| -> prism_core::error::Result<()> {
        if snapshot.samples.end == 9 {
            interrupt.store(true, Ordering::Relaxed);
        }
        Ok(())
    };
    let options = RenderOptions {
        interrupt: Some(interrupt.clone()),
        ..RenderOptions::fixed(8, loaded.seed, Some(1))
    };
    let stopped = render_with_preview(&scene, &options, None, Some(&mut raise as Preview)).unwrap();
    assert_eq!(stopped.samples, 0..9);
    Continuation::new(&scene, loaded.seed, scene.strata(8))
        .save(
            &Snapshot {
                samples: stopped.samples.clone(),
                pixels: &stopped.film.pixels,
                aovs: &stopped.film.aovs,
                integrator_state: stopped.integrator_state.as_ref(),
            },
            &dir.join("long.state"),
        )
        .unwrap();
    render("-D max_passes=11 --threads 1 --resume long.state -o long-resumed.exr");
    assert_identical_images(&dir.join("long-resumed.exr"), &dir.join("long.exr"));
    let _ = std::fs::remove_dir_all(&dir);
}
