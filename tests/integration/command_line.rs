//! The command line's help and output: at 80 columns (`COLUMNS=80`) no line of `prism --help`
//! or of any subcommand's `--help` is wider, and `prism render --help` groups its options under
//! headings and ends with examples; `--quiet` renders without a word, `--verbose`
//! says how long loading, the BVH build and rendering took.

use std::process::Command;

/// The help text of `prism ARGS --help` at a terminal width of `columns`.
fn help(args: &[&str], columns: usize) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(args)
        .arg("--help")
        .env("COLUMNS", columns.to_string())
        .output()
        .expect("the prism binary runs");
    assert!(output.status.success(), "prism {args:?} --help failed");
    String::from_utf8(output.stdout).expect("the help is UTF-8")
}

#[test]
fn no_help_line_is_wider_than_80_columns() {
    for args in [
        &[][..],
        &["render"],
        &["compare"],
        &["converge"],
        &["merge"],
        &["bench"],
        &["plugins"],
    ] {
        let text = help(args, 80);
        let wide: Vec<&str> = text.lines().filter(|l| l.chars().count() > 80).collect();
        assert!(
            wide.is_empty(),
            "prism {args:?} --help has lines over 80 columns:\n{}",
            wide.join("\n")
        );
    }
}

#[test]
fn render_help_groups_its_options_and_ends_with_three_examples() {
    let text = help(&["render"], 80);
    for heading in [
        "Scene:",
        "Output:",
        "Sampling:",
        "Stopping:",
        "Checkpoints and render farms:",
        "Progress and preview:",
        "Performance:",
    ] {
        assert!(
            text.lines().any(|l| l == heading),
            "no {heading} in:\n{text}"
        );
    }
    let examples = text
        .split_once("\nExamples:\n")
        .map(|(_, examples)| examples)
        .unwrap_or_else(|| panic!("no examples in:\n{text}"));
    let commands = examples
        .lines()
        .filter(|l| l.starts_with("  prism render "));
    assert_eq!(commands.count(), 3, "{examples}");
}

#[test]
fn defines_have_a_long_form() {
    let text = help(&["render"], 80);
    assert!(text.contains("-D, --define <NAME=VALUE>"), "{text}");
}

/// Renders the Cornell box at 16 × 16 pixels and 1 spp with the option `option` (into a
/// temporary file, removed) and returns what the command printed.
fn render_cornell_box_with(option: &str) -> std::process::Output {
    let out =
        std::env::temp_dir().join(format!("prism-option{}-{}.exr", option, std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args([
            "render",
            "scenes/cornell-box/scene.xml",
            "--spp",
            "1",
            option,
            "-o",
        ])
        .arg(&out)
        .args(["-D", "resx=16", "-D", "resy=16"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the prism binary runs");
    let _ = std::fs::remove_file(&out);
    let _ = std::fs::remove_file(out.with_extension("png"));
    assert!(output.status.success(), "{output:?}");
    output
}

#[test]
fn a_quiet_render_prints_nothing() {
    let output = render_cornell_box_with("--quiet");
    assert!(
        output.stdout.is_empty() && output.stderr.is_empty(),
        "{output:?}"
    );
}

#[test]
fn a_verbose_render_gives_its_times() {
    let output = render_cornell_box_with("-v");
    let text = String::from_utf8_lossy(&output.stderr);
    for line in [
        "prism: loading the scene took ",
        "prism: building the BVH took ",
        "prism: rendering took ",
    ] {
        assert!(
            text.lines()
                .any(|l| l.starts_with(line) && l.contains(" s")),
            "no line \"{line}...\" in:\n{text}"
        );
    }
    // The Cornell box's path tracer runs its paths in lanes, nearly all of them busy.
    let lanes = prism_core::render::LANES as f64;
    let busy = text
        .lines()
        .find_map(|l| l.strip_prefix("prism: paths in lanes: "))
        .and_then(|rest| rest.split(' ').next()?.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("no lane occupancy in:\n{text}"));
    assert!(
        busy > 0.5 * lanes && busy <= lanes,
        "{busy} of {lanes} lanes busy"
    );
}

/// A render takes the samples per pixel the scene's sampler asks for, whatever the
/// reconstruction: under filter MIS (a tent here) the sampler stratifies two blocks of half as
/// many, but the pixel still gets them all; `--spp` overrides the count.
#[test]
fn a_render_takes_the_scenes_sample_count_under_every_reconstruction() {
    let dir = std::env::temp_dir().join(format!("prism-spp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (sampler, filter, count, spp, expected) in [
        ("independent", "tent", "6", None, "6 spp"),
        ("independent", "box", "6", None, "6 spp"),
        ("stratified", "gaussian", "16", None, "16 spp"),
        ("independent", "tent", "6", Some("10"), "10 spp"),
    ] {
        let scene = dir.join("scene.xml");
        std::fs::write(
            &scene,
            format!(
                r#"<scene version="3.0.0">
    <sensor type="perspective">
        <sampler type="{sampler}"><integer name="sample_count" value="{count}"/></sampler>
        <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/><rfilter type="{filter}"/></film>
    </sensor>
    <emitter type="constant"/>
</scene>"#
            ),
        )
        .unwrap();
        let mut command = Command::new(env!("CARGO_BIN_EXE_prism"));
        command
            .arg("render")
            .arg(&scene)
            .arg("-o")
            .arg(dir.join("out.exr"));
        if let Some(spp) = spp {
            command.args(["--spp", spp]);
        }
        let output = command.output().expect("the prism binary runs");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(output.status.success(), "{stderr}");
        assert!(
            stderr.contains(&format!("(4×4, {expected})")),
            "{sampler} {count} with a {filter} filter, --spp {spp:?}: {stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
