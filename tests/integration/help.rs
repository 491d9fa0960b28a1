//! The command line's help fits a terminal: at 80 columns (`COLUMNS=80`) no line of `prism
//! --help` or of any subcommand's `--help` is wider, and the help names every option it has.

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
fn defines_have_a_long_form() {
    let text = help(&["render"], 80);
    assert!(text.contains("-D, --define <NAME=VALUE>"), "{text}");
}
