//! Renders survive interruptions: SIGINT and SIGTERM stop a render cleanly with a state to resume
//! from, kill -9 loses at most the work since the last checkpoint, and resumed or merged renders
//! are bit-identical to uninterrupted ones.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use prism_core::sampling::rng::Pcg32;

use crate::common::scenes::assert_identical_images;

fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-reliability-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box/scene.xml")
}

/// Arguments of a small but slow enough render of the bundled Cornell box.
fn render_arguments(output: &Path, spp: u32) -> Vec<String> {
    vec![
        "render".into(),
        scene().to_str().unwrap().into(),
        "-D".into(),
        "resx=32".into(),
        "-D".into(),
        "resy=32".into(),
        "--spp".into(),
        spp.to_string(),
        "--threads".into(),
        "2".into(),
        "-o".into(),
        output.to_str().unwrap().into(),
    ]
}

fn prism(arguments: &[String]) -> (i32, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(arguments)
        .output()
        .unwrap();
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

fn spawn(arguments: &[String]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(arguments)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

/// The reference: the same render, uninterrupted.
fn reference(dir: &Path, spp: u32) -> PathBuf {
    let path = dir.join("reference.exr");
    let (status, text) = prism(&render_arguments(&path, spp));
    assert_eq!(status, 0, "{text}");
    path
}

fn wait(child: Child) -> (i32, String) {
    let output = child.wait_with_output().unwrap();
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Samples per pixel of the interrupted renders: enough that a render of the 32 × 32 box takes
/// seconds even on a fast machine, so it is still running when the signal comes (the tests fail
/// if it is not).
const LONG_SPP: u32 = 4000;

/// Starts a render that checkpoints every 0.05 s and returns once its first checkpoint is
/// written, with the render in progress.
fn start_checkpointing(output: &Path, state: &Path) -> Child {
    let mut arguments = render_arguments(output, LONG_SPP);
    arguments.extend([
        "--checkpoint".into(),
        state.to_str().unwrap().into(),
        "--checkpoint-every".into(),
        "0.05".into(),
    ]);
    let child = spawn(&arguments);
    let start = Instant::now();
    while !state.exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(state.exists(), "no checkpoint was written in a minute");
    child
}

/// Resumes the render of `output` from `state` to its end.
fn resume(output: &Path, state: &Path) {
    let mut arguments = render_arguments(output, LONG_SPP);
    arguments.extend(["--resume".into(), state.to_str().unwrap().into()]);
    let (status, text) = prism(&arguments);
    assert_eq!(status, 0, "{text}");
}

#[test]
fn sigint_then_resume_is_bit_identical_to_an_uninterrupted_render() {
    let dir = folder("sigint");
    let reference = reference(&dir, LONG_SPP);
    let output = dir.join("image.exr");
    let state = dir.join("image.state");
    let child = start_checkpointing(&output, &state);
    // Interrupt at a random moment in the render.
    let delay =
        Duration::from_secs_f32(0.3 * Pcg32::seeded(u64::from(std::process::id())).next_f32());
    std::thread::sleep(delay);
    signal(&child, "INT");
    let (status, text) = wait(child);
    assert_eq!(status, 130, "{text}");
    assert!(text.contains("--resume"), "{text}");
    resume(&output, &state);
    assert_identical_images(&output, &reference);
}

#[test]
fn sigterm_exits_with_143_and_leaves_a_state() {
    let dir = folder("sigterm");
    let output = dir.join("image.exr");
    let child = spawn(&render_arguments(&output, 100_000));
    std::thread::sleep(Duration::from_millis(400));
    signal(&child, "TERM");
    let (status, text) = wait(child);
    assert_eq!(status, 143, "{text}");
    assert!(
        dir.join("image.state").exists() && output.exists(),
        "{text}"
    );
}

#[test]
fn kill_9_between_checkpoints_resumes_from_the_last_one() {
    let dir = folder("kill9");
    let reference = reference(&dir, LONG_SPP);
    let output = dir.join("image.exr");
    let state = dir.join("image.state");
    let child = start_checkpointing(&output, &state);
    std::thread::sleep(Duration::from_millis(60));
    signal(&child, "KILL");
    let (status, text) = wait(child);
    assert_eq!(status, -1, "the render was not killed: {text}");
    resume(&output, &state);
    assert_identical_images(&output, &reference);
}

#[test]
fn merged_half_ranges_equal_the_full_render() {
    let dir = folder("merge");
    let spp = 16;
    let reference = reference(&dir, spp);
    let mut states = Vec::new();
    for (name, range) in [("a", "0..7"), ("b", "7..16")] {
        let state = dir.join(format!("{name}.state"));
        let mut arguments = render_arguments(&dir.join(format!("{name}.exr")), spp);
        arguments.extend([
            "--sample-range".into(),
            range.into(),
            "--checkpoint".into(),
            state.to_str().unwrap().into(),
        ]);
        let (status, text) = prism(&arguments);
        assert_eq!(status, 0, "{text}");
        states.push(state);
    }
    let merged = dir.join("merged.exr");
    let (status, text) = prism(&[
        "merge".into(),
        states[1].to_str().unwrap().into(),
        states[0].to_str().unwrap().into(),
        "-o".into(),
        merged.to_str().unwrap().into(),
    ]);
    assert_eq!(status, 0, "{text}");
    assert_identical_images(&merged, &reference);
    // Overlapping ranges and states of another render are refused.
    let (status, text) = prism(&[
        "merge".into(),
        states[0].to_str().unwrap().into(),
        states[0].to_str().unwrap().into(),
        "-o".into(),
        merged.to_str().unwrap().into(),
    ]);
    assert_eq!(status, 2, "{text}");
    assert!(text.contains("overlap"), "{text}");
}

#[test]
fn a_state_of_another_render_is_refused() {
    let dir = folder("mismatch");
    let output = dir.join("image.exr");
    let state = dir.join("image.state");
    let mut arguments = render_arguments(&output, 4);
    arguments.extend(["--checkpoint".into(), state.to_str().unwrap().into()]);
    assert_eq!(prism(&arguments).0, 0);
    for (flag, value, says) in [("--seed", "5", "seed"), ("--crop", "0,0,16,16", "crop")] {
        let mut resume = render_arguments(&output, 8);
        resume.extend([
            flag.into(),
            value.into(),
            "--resume".into(),
            state.to_str().unwrap().into(),
        ]);
        let (status, text) = prism(&resume);
        assert_eq!(status, 2, "{text}");
        assert!(text.contains(says), "{text}");
    }
    std::fs::write(&state, b"PRISMRS\0garbage").unwrap();
    let mut resume = render_arguments(&output, 8);
    resume.extend(["--resume".into(), state.to_str().unwrap().into()]);
    let (status, text) = prism(&resume);
    assert_eq!(status, 2, "{text}");
    assert!(text.contains("not a valid render state"), "{text}");
}
