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

#[test]
fn a_quiet_render_prints_nothing() {
    let out = std::env::temp_dir().join(format!("prism-quiet-{}.exr", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args([
            "render",
            "scenes/cornell-box/scene.xml",
            "--spp",
            "1",
            "--quiet",
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
    assert!(
        output.stdout.is_empty() && output.stderr.is_empty(),
        "{output:?}"
    );
}

#[test]
fn a_verbose_render_gives_its_times() {
    let out = std::env::temp_dir().join(format!("prism-verbose-{}.exr", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args([
            "render",
            "scenes/cornell-box/scene.xml",
            "--spp",
            "1",
            "-v",
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
}
