//! The signposts name what exists, and all of it: the module table of prism-core's crate docs
//! against its `pub mod` lines and the layers of docs/architecture.md; the README's integrators
//! against the integrators the plugin reference lists (docs/plugins.md, which a unit test of
//! prism-mitsuba keeps equal to the registry); the crates the README and docs/architecture.md
//! name against the workspace's members; the folders scenes/README.md describes against
//! `scenes/`.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &str) -> String {
    let path = root().join(path);
    fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The text between the line `heading` and the next heading.
fn section<'a>(text: &'a str, heading: &str) -> &'a str {
    let start = text
        .find(&format!("{heading}\n"))
        .unwrap_or_else(|| panic!("no heading {heading:?}"))
        + heading.len()
        + 1;
    let rest = &text[start..];
    let end = rest
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .find(|&i| {
            let hashes = rest[i..].chars().take_while(|&c| c == '#').count();
            hashes > 0 && rest[i + hashes..].starts_with(' ')
        })
        .unwrap_or(rest.len());
    &rest[..end]
}

/// The first backquoted word of `line` after `prefix`, if `line` starts with `prefix`.
fn quoted_after<'a>(line: &'a str, prefix: &str) -> Option<&'a str> {
    let rest = line.trim_start().strip_prefix(prefix)?;
    let rest = rest.strip_prefix('`')?;
    Some(&rest[..rest.find('`')?])
}

fn assert_same(what: &str, named: &BTreeSet<String>, existing: &BTreeSet<String>) {
    let missing: Vec<_> = existing.difference(named).collect();
    let extra: Vec<_> = named.difference(existing).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "{what}: omits {missing:?}, names {extra:?}, which do not exist"
    );
}

/// Prism-core's top-level modules in the order of their first appearance in the `layers`
/// block of docs/architecture.md.
fn core_layers() -> Vec<String> {
    let architecture = read("docs/architecture.md");
    let block = architecture
        .split("```layers\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("docs/architecture.md has a ```layers block");
    let mut modules: Vec<String> = Vec::new();
    let core = block
        .split("[prism-core]\n")
        .nth(1)
        .expect("a [prism-core] section");
    for line in core.lines().take_while(|l| !l.starts_with('[')) {
        for entry in line.split_whitespace() {
            let top = entry.split("::").next().unwrap().to_string();
            if !modules.contains(&top) {
                modules.push(top);
            }
        }
    }
    modules
}

#[test]
fn the_core_module_table_lists_every_module_in_layer_order() {
    let lib = read("crates/prism-core/src/lib.rs");
    let declared: BTreeSet<String> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';').to_string())
        .collect();
    let table: Vec<String> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("//! | [`"))
        .map(|l| l[..l.find('`').unwrap()].to_string())
        .collect();
    assert_same(
        "crates/prism-core/src/lib.rs's module table",
        &table.iter().cloned().collect(),
        &declared,
    );
    assert_eq!(
        table.len(),
        declared.len(),
        "a module is listed twice in lib.rs's table"
    );
    assert_eq!(
        table,
        core_layers(),
        "lib.rs's module table is not in the order of docs/architecture.md's layers"
    );
}

#[test]
fn the_readme_lists_every_integrator() {
    let plugins = read("docs/plugins.md");
    let registered: BTreeSet<String> = section(&plugins, "## integrator")
        .lines()
        .filter_map(|l| quoted_after(l, "| "))
        .map(str::to_string)
        .collect();
    assert!(
        registered.contains("path"),
        "docs/plugins.md lists no integrators"
    );
    let readme = read("README.md");
    let listed: BTreeSet<String> = section(&readme, "## Integrators")
        .lines()
        .filter_map(|l| quoted_after(l, "* "))
        .map(str::to_string)
        .collect();
    assert_same("README.md's Integrators", &listed, &registered);
}

/// The workspace's crates: the root package and every member's, by package name.
fn workspace_crates() -> BTreeSet<String> {
    let package_name = |manifest: &Path| -> String {
        let text =
            fs::read_to_string(manifest).unwrap_or_else(|e| panic!("{}: {e}", manifest.display()));
        let package = text.split("[package]").nth(1).expect("a [package] table");
        let line = package
            .lines()
            .find(|l| l.trim_start().starts_with("name"))
            .expect("a package name");
        line.split('"').nth(1).expect("a quoted name").to_string()
    };
    let manifest = read("Cargo.toml");
    let members = manifest
        .lines()
        .find_map(|l| l.strip_prefix("members = "))
        .expect("a members list in Cargo.toml");
    let mut crates: BTreeSet<String> = members
        .split('"')
        .skip(1)
        .step_by(2)
        .map(|dir| package_name(&root().join(dir).join("Cargo.toml")))
        .collect();
    crates.insert(package_name(&root().join("Cargo.toml")));
    crates
}

/// Number words, by value.
const NUMBERS: [&str; 9] = [
    "no", "one", "two", "three", "four", "five", "six", "seven", "eight",
];

#[test]
fn the_readme_and_the_architecture_name_every_crate() {
    let crates = workspace_crates();
    assert!(crates.len() >= 4, "{crates:?}");

    let readme = read("README.md");
    let paragraph = readme
        .split("\n\n")
        .find(|p| p.starts_with("The code is a cargo workspace"))
        .expect("README.md's paragraph on the workspace");
    // Each crate is named in backquotes followed by what it is, in parentheses.
    let pieces: Vec<&str> = paragraph.split('`').collect();
    let named: BTreeSet<String> = (1..pieces.len())
        .step_by(2)
        .filter(|&i| pieces.get(i + 1).is_some_and(|next| next.starts_with(" (")))
        .map(|i| pieces[i].to_string())
        .collect();
    assert_same("README.md's list of crates", &named, &crates);
    let count = NUMBERS
        .get(crates.len())
        .expect("a number word for the count of crates");
    assert!(
        paragraph.contains(&format!("workspace of {count} crates")),
        "README.md does not say the workspace has {count} crates"
    );

    let architecture = read("docs/architecture.md");
    let table: BTreeSet<String> = section(&architecture, "## Crates")
        .lines()
        .filter_map(|l| quoted_after(l, "| "))
        .map(str::to_string)
        .collect();
    assert_same("docs/architecture.md's table of crates", &table, &crates);
}

#[test]
fn the_scenes_readme_describes_every_folder() {
    let scenes = root().join("scenes");
    let folders: BTreeSet<String> = fs::read_dir(&scenes)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.file_type().unwrap().is_dir())
        .map(|e| e.file_name().into_string().unwrap())
        .collect();
    let readme = read("scenes/README.md");
    let rows: Vec<&str> = readme
        .lines()
        .filter_map(|l| quoted_after(l, "| "))
        .collect();
    for row in &rows {
        assert!(
            row.ends_with('/') && scenes.join(row).is_dir(),
            "scenes/README.md describes {row}, which is not a folder of scenes/"
        );
    }
    let described: BTreeSet<String> = rows
        .iter()
        .map(|row| row.split('/').next().unwrap().to_string())
        .collect();
    assert_same("scenes/README.md", &described, &folders);
}
