//! Scene parameters and the renaming of old scenes.
//!
//! A scene declares parameters with `<default name="spp" value="64"/>` and uses them as `$spp` in
//! any attribute value; the command line's `-D spp=16` overrides a default. The rules follow
//! Mitsuba 3 (`substitute_parameters` and the `Default` tag in `src/core/parser.cpp`):
//! - a parameter exists from its `<default>` onwards, in document order (includes included);
//!   a `-D` define exists from the start and wins over any `<default>` of the same name, and when
//!   two `<default>`s declare one name the first wins;
//! - at each `$`, the longest parameter name that follows is substituted (so `$resx` is not read
//!   as `$res` followed by `x`); the substituted text is not scanned again;
//! - `\$` stands for a literal `$`;
//! - a `$` that names no parameter is an error.
//!
//! Mitsuba 3 only warns about a `-D` define that the scene never uses; we make it an error,
//! since it is almost always a misspelt name whose intended override silently did not happen.
//! A define counts as used when a `<default>` declares it or a `$name` substitutes it.

use super::element::quote;
use crate::suggest::closest_match;
use prism_core::error::{Error, Result, SourceLocation};

/// Longest attribute value that substitution may produce, to bound memory on hostile input.
const MAX_SUBSTITUTED_LENGTH: usize = 16 << 20;

/// The parameters known at the current point of the document.
pub(super) struct Parameters {
    /// Sorted by decreasing name length, so that the first match at a `$` is the longest.
    entries: Vec<Parameter>,
}

struct Parameter {
    name: String,
    value: String,
    /// `Some(i)` for the i-th `-D` define of the command line, `None` for a `<default>`.
    define_index: Option<usize>,
    used: bool,
}

impl Parameters {
    /// Starts with the command line's `-D name=value` defines.
    pub fn new(defines: &[(String, String)]) -> Result<Self> {
        let mut parameters = Parameters {
            entries: Vec::new(),
        };
        for (index, (name, value)) in defines.iter().enumerate() {
            if name.is_empty() {
                return Err(
                    Error::usage(format!("-D ={value}: a define needs a parameter name"))
                        .with_help("write -D name=value"),
                );
            }
            if parameters.find(name).is_some() {
                return Err(Error::usage(format!(
                    "-D {name}=...: the parameter \"{name}\" is defined twice"
                ))
                .with_help("give each -D parameter once"));
            }
            parameters.insert(Parameter {
                name: name.clone(),
                value: value.clone(),
                define_index: Some(index),
                used: false,
            });
        }
        Ok(parameters)
    }

    fn find(&self, name: &str) -> Option<usize> {
        self.entries.iter().position(|p| p.name == name)
    }

    fn insert(&mut self, parameter: Parameter) {
        let at = self
            .entries
            .iter()
            .position(|p| p.name.len() < parameter.name.len())
            .unwrap_or(self.entries.len());
        self.entries.insert(at, parameter);
    }

    /// Handles `<default name value>`: declares the parameter unless a define or an earlier
    /// default already did.
    pub fn declare_default(&mut self, name: &str, value: &str) {
        match self.find(name) {
            Some(index) => self.entries[index].used = true,
            None => self.insert(Parameter {
                name: name.to_string(),
                value: value.to_string(),
                define_index: None,
                used: true,
            }),
        }
    }

    /// Replaces every `$name` in `text`; `location` is the attribute's, for errors.
    pub fn substitute(&mut self, text: &str, location: &SourceLocation) -> Result<String> {
        if !text.contains('$') {
            return Ok(text.to_string());
        }
        let mut result = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(dollar) = rest.find('$') {
            let before = &rest[..dollar];
            let after = &rest[dollar + 1..];
            if let Some(escaped) = before.strip_suffix('\\') {
                result.push_str(escaped);
                result.push('$');
                rest = after;
                continue;
            }
            result.push_str(before);
            let Some(parameter) = self
                .entries
                .iter_mut()
                .find(|p| after.starts_with(p.name.as_str()))
            else {
                return Err(self.undefined(after, location));
            };
            parameter.used = true;
            result.push_str(&parameter.value);
            rest = &after[parameter.name.len()..];
            if result.len() > MAX_SUBSTITUTED_LENGTH {
                return Err(Error::input(
                    location,
                    "substituting parameters makes this attribute longer than 16 MiB",
                )
                .with_help("check the values of the parameters used here"));
            }
        }
        result.push_str(rest);
        Ok(result)
    }

    /// The error for a `$` followed by `after`, which starts with no known parameter name.
    fn undefined(&self, after: &str, location: &SourceLocation) -> Error {
        let name: String = after
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        if name.is_empty() {
            return Error::input(location, "a \"$\" that does not start a parameter name")
                .with_help("parameters are written $name; write \\$ for a literal dollar sign");
        }
        let name = quote(&name);
        let known: Vec<&str> = self.entries.iter().map(|p| p.name.as_str()).collect();
        let mut help = format!(
            "declare it with <default name=\"{name}\" value=\"...\"/> before its first use, \
             or pass -D {name}=... on the command line"
        );
        if let Some(close) = closest_match(&name, &known) {
            help = format!("did you mean \"${close}\"? Otherwise {help}");
        }
        Error::input(location, format!("undefined parameter \"${name}\"")).with_help(help)
    }

    /// Reports the first `-D` define (in command-line order) that the scene neither declares
    /// nor uses.
    pub fn check_defines_used(&self) -> Result<()> {
        let Some(unused) = self
            .entries
            .iter()
            .filter(|p| p.define_index.is_some() && !p.used)
            .min_by_key(|p| p.define_index)
        else {
            return Ok(());
        };
        let mut defaults: Vec<&str> = self
            .entries
            .iter()
            .filter(|p| p.define_index.is_none())
            .map(|p| p.name.as_str())
            .collect();
        defaults.sort_unstable();
        let mut help = if defaults.is_empty() {
            "the scene declares no <default> parameters".to_string()
        } else {
            format!(
                "the scene's <default> parameters are: {}",
                defaults.join(", ")
            )
        };
        if let Some(close) = closest_match(&unused.name, &defaults) {
            help = format!("did you mean \"{close}\"? {help}");
        }
        Err(Error::usage(format!(
            "-D {}={}: the scene never declares or uses a parameter \"{}\"",
            unused.name, unused.value, unused.name
        ))
        .with_help(help))
    }
}

/// Mitsuba 3's renaming of parameter names in scenes older than version 2.0.0
/// (`camel_to_underscore_case` in `src/core/parser.cpp`): an uppercase ASCII letter that follows
/// a lowercase one starts a new word; it and the uppercase letters right after it are lowered and
/// the word is joined with `_`. `toWorld` becomes `to_world`, `intIOR` becomes `int_ior`.
pub(super) fn camel_to_snake(name: &str) -> String {
    let chars: Vec<char> = name.chars().collect();
    let mut result = String::with_capacity(name.len() + 4);
    let mut i = 0;
    while let Some(&c) = chars.get(i) {
        let follows_lowercase = i > 0 && chars.get(i - 1).is_some_and(|p| p.is_ascii_lowercase());
        if follows_lowercase && c.is_ascii_uppercase() {
            result.push('_');
            result.push(c.to_ascii_lowercase());
            while let Some(next) = chars.get(i + 1).filter(|n| n.is_ascii_uppercase()) {
                result.push(next.to_ascii_lowercase());
                i += 1;
            }
        } else {
            result.push(c);
        }
        i += 1;
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn location() -> SourceLocation {
        SourceLocation::new("test.xml", 1, 1)
    }

    #[test]
    fn camel_case_names_become_snake_case() {
        assert_eq!(camel_to_snake("toWorld"), "to_world");
        assert_eq!(camel_to_snake("sampleCount"), "sample_count");
        assert_eq!(camel_to_snake("intIOR"), "int_ior");
        assert_eq!(camel_to_snake("fovAxis"), "fov_axis");
        assert_eq!(camel_to_snake("diffuseReflectance"), "diffuse_reflectance");
        assert_eq!(camel_to_snake("already_snake"), "already_snake");
        assert_eq!(camel_to_snake("ABC"), "ABC");
        assert_eq!(camel_to_snake(""), "");
        assert_eq!(camel_to_snake("aBcD"), "a_bc_d");
    }

    #[test]
    fn longest_name_wins_and_escapes_are_literal() {
        let mut p = Parameters::new(&[]).unwrap();
        p.declare_default("res", "1");
        p.declare_default("resx", "640");
        assert_eq!(p.substitute("$resx,$res", &location()).unwrap(), "640,1");
        assert_eq!(p.substitute("cost \\$5", &location()).unwrap(), "cost $5");
        assert_eq!(p.substitute("no dollar", &location()).unwrap(), "no dollar");
    }

    #[test]
    fn defines_override_defaults_and_first_default_wins() {
        let mut p = Parameters::new(&[("spp".into(), "4".into())]).unwrap();
        p.declare_default("spp", "64");
        p.declare_default("depth", "3");
        p.declare_default("depth", "9");
        assert_eq!(p.substitute("$spp/$depth", &location()).unwrap(), "4/3");
        p.check_defines_used().unwrap();
    }

    #[test]
    fn substituted_text_is_not_scanned_again() {
        let mut p = Parameters::new(&[("a".into(), "$b".into())]).unwrap();
        p.declare_default("b", "x");
        assert_eq!(p.substitute("$a", &location()).unwrap(), "$b");
    }

    #[test]
    fn undefined_parameters_and_stray_dollars_are_errors() {
        let mut p = Parameters::new(&[]).unwrap();
        p.declare_default("spp", "64");
        let err = p.substitute("$sp", &location()).unwrap_err();
        assert!(err.message.contains("\"$sp\""), "{err}");
        let help = err.help.unwrap();
        assert!(
            help.contains("<default name=\"sp\"") && help.contains("-D sp="),
            "{help}"
        );
        let err = p.substitute("5$", &location()).unwrap_err();
        assert!(
            err.message.contains("does not start a parameter name"),
            "{err}"
        );
    }

    #[test]
    fn unused_and_duplicate_defines_are_errors() {
        let mut p = Parameters::new(&[("spx".into(), "4".into())]).unwrap();
        p.declare_default("spp", "64");
        let err = p.check_defines_used().unwrap_err();
        assert!(err.message.contains("\"spx\""), "{err}");
        assert!(err.help.unwrap().contains("did you mean \"spp\""));
        assert!(Parameters::new(&[("a".into(), "1".into()), ("a".into(), "2".into())]).is_err());
        assert!(Parameters::new(&[(String::new(), "1".into())]).is_err());
    }
}
