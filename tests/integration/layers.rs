//! The layers of docs/architecture.md hold: no module refers to a module of its crate in a
//! layer above its own, nor to a peer in its own layer, so that no dependency cycle between
//! modules can come back. (Cargo keeps the crates themselves in order: prism-core below
//! prism-mitsuba below the command line.)
//!
//! The table is the fenced `layers` block of docs/architecture.md: a `[crate]` line, then one
//! line per layer from the lowest up, each naming one or more module paths. A module belongs to
//! the most specific entry that contains it; a module in no entry may only declare and re-export
//! its own submodules. References are read from the code (comments, strings and the trailing
//! `#[cfg(test)]` module left out): `use` trees and `crate::`, `super::` and `self::` paths,
//! with re-exports (`pub use`) followed to the module that defines the item.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The repository's root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The layer table of docs/architecture.md: for each crate, its layers from the lowest.
fn layer_table() -> BTreeMap<String, Vec<Vec<String>>> {
    let path = root().join("docs/architecture.md");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let start = text
        .find("```layers\n")
        .expect("docs/architecture.md has a ```layers block");
    let block = &text[start + "```layers\n".len()..];
    let block = &block[..block.find("```").expect("the layers block ends")];
    let mut table: BTreeMap<String, Vec<Vec<String>>> = BTreeMap::new();
    let mut current = None;
    for line in block.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            current = Some(name.to_string());
            table.entry(name.to_string()).or_default();
        } else {
            let name = current.clone().expect("a layer before any [crate] line");
            let entries = line.split_whitespace().map(String::from).collect();
            table.get_mut(&name).unwrap().push(entries);
        }
    }
    table
}

/// The modules of a crate whose sources are in `src`: module path ("" for the crate root,
/// "a::b" for src/a/b.rs or src/a/b/mod.rs) → file.
fn modules(src: &Path) -> BTreeMap<String, PathBuf> {
    let mut found = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let relative = path.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = relative
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if matches!(
                parts.last().map(String::as_str),
                Some("mod" | "lib" | "main")
            ) {
                parts.pop();
            }
            found.insert(parts.join("::"), path);
        }
    }
    found
}

/// The code of a file with comments, string and character literals blanked, and without the
/// `#[cfg(test)]` module at its end (tests may use anything).
fn code(text: &str) -> String {
    let bytes: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < bytes.len() {
        let at = |k: usize| bytes.get(k).copied().unwrap_or('\0');
        let rest = |k: usize| at(i + k);
        match (bytes[i], rest(1)) {
            ('/', '/') => {
                while i < bytes.len() && bytes[i] != '\n' {
                    i += 1;
                }
            }
            ('/', '*') => {
                i += 2;
                while i < bytes.len() && !(bytes[i] == '*' && at(i + 1) == '/') {
                    i += 1;
                }
                i += 2;
            }
            ('r', '#') if rest(2) == '"' => {
                i += 3;
                while i < bytes.len() && !(bytes[i] == '"' && at(i + 1) == '#') {
                    i += 1;
                }
                i += 2;
                out.push_str("\"\"");
            }
            ('"', _) => {
                i += 1;
                while i < bytes.len() && bytes[i] != '"' {
                    i += if bytes[i] == '\\' { 2 } else { 1 };
                }
                i += 1;
                out.push_str("\"\"");
            }
            ('\'', c) if c != '\0' && (rest(2) == '\'' || c == '\\') => {
                i += 1;
                while i < bytes.len() && bytes[i] != '\'' {
                    i += if bytes[i] == '\\' { 2 } else { 1 };
                }
                i += 1;
                out.push_str("' '");
            }
            (c, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    match out.find("#[cfg(test)]") {
        Some(start)
            if out[start..]
                .trim_start_matches("#[cfg(test)]")
                .trim_start()
                .starts_with("mod ") =>
        {
            out.truncate(start);
            out
        }
        _ => out,
    }
}

/// The paths a `use` tree names, each as its segments (`a::{b, c::d}` gives a::b and a::c::d).
fn expand_use_tree(tree: &str) -> Vec<Vec<String>> {
    // Renames (`a::B as C`) name a::B.
    let mut words: Vec<&str> = tree.split_whitespace().collect();
    while let Some(at) = words.iter().position(|w| *w == "as") {
        words.drain(at..(at + 2).min(words.len()));
    }
    let tree: String = words.concat();
    let mut paths = Vec::new();
    expand(&tree, &mut Vec::new(), &mut paths);
    paths
}

fn expand(tree: &str, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    let Some(open) = tree.find('{') else {
        let mut path = prefix.clone();
        path.extend(tree.split("::").filter(|s| !s.is_empty()).map(String::from));
        out.push(path);
        return;
    };
    let head: Vec<String> = tree[..open]
        .split("::")
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect();
    let inner = &tree[open + 1..tree.rfind('}').unwrap()];
    let (mut depth, mut start) = (0, 0);
    let mut parts = Vec::new();
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    let len = prefix.len();
    prefix.extend(head);
    for part in parts.into_iter().filter(|p| !p.is_empty()) {
        if part == "self" {
            out.push(prefix.clone());
        } else {
            expand(part, prefix, out);
        }
    }
    prefix.truncate(len);
}

/// The paths one `use` statement names, and whether it is `pub` (a re-export).
type UseStatement = (bool, Vec<Vec<String>>);

/// A file's `use` statements, and the code without them.
fn use_statements(code: &str) -> (Vec<UseStatement>, String) {
    let mut found = Vec::new();
    let mut others = String::new();
    let mut rest = code;
    while let Some(at) = find_word(rest, "use") {
        let before = rest[..at].trim_end();
        let public = before.ends_with("pub") || before.ends_with("pub(crate)");
        others.push_str(&rest[..at]);
        let statement = &rest[at + 3..];
        let end = statement.find(';').unwrap_or(statement.len());
        found.push((public, expand_use_tree(&statement[..end])));
        rest = &statement[end..];
    }
    others.push_str(rest);
    (found, others)
}

/// The byte offset of `word` standing alone in `text`.
fn find_word(text: &str, word: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = text[from..].find(word) {
        let at = from + i;
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        let is_ident = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
        if !is_ident(before) && !is_ident(after) {
            return Some(at);
        }
        from = at + word.len();
    }
    None
}

/// Paths written in code outside `use` statements: `crate::a::b`, `super::a`, `self::a`.
fn inline_paths(code: &str) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    for start in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(i) = code[from..].find(start) {
            let at = from + i;
            from = at + start.len();
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let tail: String = code[at..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            found.push(
                tail.split("::")
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect(),
            );
        }
    }
    found
}

/// One crate's modules, what each refers to, and what each re-exports.
struct Crate {
    modules: BTreeMap<String, PathBuf>,
    /// Per module: the module paths its code refers to, resolved.
    references: BTreeMap<String, BTreeSet<String>>,
}

fn parent(module: &str) -> String {
    module
        .rsplit_once("::")
        .map_or(String::new(), |(p, _)| p.to_string())
}

fn join(module: &str, name: &str) -> String {
    if module.is_empty() {
        name.to_string()
    } else {
        format!("{module}::{name}")
    }
}

impl Crate {
    fn read(src: &Path) -> Crate {
        let modules = modules(src);
        let codes: BTreeMap<String, String> = modules
            .iter()
            .map(|(m, p)| (m.clone(), code(&std::fs::read_to_string(p).unwrap())))
            .collect();
        // Absolute paths of every use and inline path, per module.
        let mut paths: BTreeMap<String, Vec<(bool, Vec<String>)>> = BTreeMap::new();
        for (module, code) in &codes {
            let mut list = Vec::new();
            let (uses, rest) = use_statements(code);
            for (public, paths) in uses {
                for path in paths {
                    list.push((public, path));
                }
            }
            for path in inline_paths(&rest) {
                list.push((false, path));
            }
            let absolute = list
                .into_iter()
                .filter_map(|(public, path)| absolute(&modules, module, &path).map(|p| (public, p)))
                .collect();
            paths.insert(module.clone(), absolute);
        }
        // Re-exports: (module, item) → the absolute path it stands for.
        let mut exports: BTreeMap<(String, String), Vec<String>> = BTreeMap::new();
        for (module, list) in &paths {
            for (public, path) in list {
                if *public && let Some(item) = path.last() {
                    exports.insert((module.clone(), item.clone()), path.clone());
                }
            }
        }
        let references = paths
            .iter()
            .map(|(module, list)| {
                let resolved = list
                    .iter()
                    .map(|(_, path)| resolve(&modules, &exports, path))
                    .collect();
                (module.clone(), resolved)
            })
            .collect();
        Crate {
            modules,
            references,
        }
    }
}

/// A path written in `module` as an absolute path of the crate (None for other crates).
fn absolute(
    modules: &BTreeMap<String, PathBuf>,
    module: &str,
    path: &[String],
) -> Option<Vec<String>> {
    let mut base = module.to_string();
    let mut segments = path;
    match segments.first().map(String::as_str) {
        Some("crate") => {
            base = String::new();
            segments = &segments[1..];
        }
        Some("self") => segments = &segments[1..],
        Some("super") => {
            while segments.first().map(String::as_str) == Some("super") {
                base = parent(&base);
                segments = &segments[1..];
            }
        }
        Some(first) if modules.contains_key(&join(module, first)) => {}
        _ => return None,
    }
    let mut absolute: Vec<String> = if base.is_empty() {
        Vec::new()
    } else {
        base.split("::").map(String::from).collect()
    };
    absolute.extend(segments.iter().cloned());
    Some(absolute)
}

/// The module an absolute path refers to: its longest prefix that is a module, followed through
/// re-exports of the item after it.
fn resolve(
    modules: &BTreeMap<String, PathBuf>,
    exports: &BTreeMap<(String, String), Vec<String>>,
    path: &[String],
) -> String {
    let mut path = path.to_vec();
    for _ in 0..16 {
        let mut module = String::new();
        let mut length = 0;
        for k in (0..=path.len()).rev() {
            let candidate = path[..k].join("::");
            if modules.contains_key(&candidate) {
                module = candidate;
                length = k;
                break;
            }
        }
        match path
            .get(length)
            .and_then(|item| exports.get(&(module.clone(), item.clone())))
        {
            Some(target) if target.as_slice() != path.as_slice() => {
                let mut next = target.clone();
                next.extend(path[length + 1..].iter().cloned());
                path = next;
            }
            _ => return module,
        }
    }
    panic!("re-exports of {} go round in circles", path.join("::"))
}

/// The entry of the table a module belongs to: the most specific that contains it, with its
/// layer.
fn entry_of<'t>(layers: &'t [Vec<String>], module: &str) -> Option<(&'t str, usize)> {
    let mut best: Option<(&str, usize)> = None;
    for (layer, entries) in layers.iter().enumerate() {
        for entry in entries {
            let contains = module == entry || module.starts_with(&format!("{entry}::"));
            if contains && best.is_none_or(|(b, _)| entry.len() > b.len()) {
                best = Some((entry, layer));
            }
        }
    }
    best
}

#[test]
fn modules_use_only_the_layers_below_their_own() {
    let table = layer_table();
    let crates = [
        ("prism-core", root().join("crates/prism-core/src")),
        ("prism-mitsuba", root().join("crates/prism-mitsuba/src")),
        ("prism", root().join("src")),
        ("prism-python", root().join("crates/prism-python/src")),
    ];
    let mut problems = Vec::new();
    for (name, src) in crates {
        let layers = table
            .get(name)
            .unwrap_or_else(|| panic!("the layer table has no [{name}]"));
        let krate = Crate::read(&src);
        for entries in layers {
            for entry in entries {
                if !krate.modules.contains_key(entry) {
                    problems.push(format!(
                        "{name}: the table names {entry}, which is no module"
                    ));
                }
            }
        }
        for (module, references) in &krate.references {
            let own = entry_of(layers, module);
            for target in references {
                let is_descendant = target.starts_with(&format!("{module}::"))
                    || (module.is_empty() && !target.is_empty());
                if target == module || is_descendant && own.is_none() {
                    continue;
                }
                let Some((own_entry, own_layer)) = own else {
                    problems.push(format!("{name}: {module} is in no layer but uses {target}"));
                    continue;
                };
                match entry_of(layers, target) {
                    Some((entry, _)) if entry == own_entry => {}
                    Some((_, layer)) if layer < own_layer => {}
                    Some((entry, layer)) => problems.push(format!(
                        "{name}: {module} (layer {own_layer}, {own_entry}) uses {target} (layer {layer}, {entry}){}",
                        if layer == own_layer { ", a peer" } else { ", above it" }
                    )),
                    None if target.is_empty() => {}
                    None => problems.push(format!(
                        "{name}: {module} uses {target}, which is in no layer"
                    )),
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "layer violations:\n{}",
        problems.join("\n")
    );
}
