//! One XML element of a scene file after `$name` substitution, and the grammar of attribute values
//! (numbers, lists of numbers, 3-vectors) shared by properties and transform operations.
//!
//! Numbers follow Mitsuba 3's `string::stof`: decimal notation with an optional sign and exponent,
//! surrounding spaces allowed. Unlike Mitsuba we also reject `nan` and `inf`: no scene parameter
//! is meaningful with them and they would poison every computation downstream. Lists separate
//! their entries with commas and/or whitespace, as Mitsuba's `string::tokenize` does.

use glam::DVec3;

use crate::suggest::closest_match;
use prism_core::error::{Error, Result, SourceLocation};

/// One attribute: its name, its value after `$name` substitution, and where it is written.
pub(super) struct Attribute {
    pub name: String,
    pub value: String,
    pub location: SourceLocation,
}

/// An element's tag, where it starts, and its attributes in document order.
pub(super) struct Element {
    pub tag: String,
    pub location: SourceLocation,
    pub attributes: Vec<Attribute>,
}

impl Element {
    /// The attribute called `name`, if present.
    pub fn get(&self, name: &str) -> Option<&Attribute> {
        self.attributes.iter().find(|a| a.name == name)
    }

    /// The attribute called `name`; its absence is an error.
    pub fn require(&self, name: &str) -> Result<&Attribute> {
        self.get(name).ok_or_else(|| {
            Error::input(
                &self.location,
                format!("{} is missing the attribute \"{name}\"", self.describe()),
            )
            .with_help(format!("add {name}=\"...\" to the <{}> element", self.tag))
        })
    }

    /// Reports the first attribute not in `allowed`, as Mitsuba's `check_attributes` does.
    pub fn check_attributes(&self, allowed: &[&str]) -> Result<()> {
        for attribute in &self.attributes {
            if allowed.contains(&attribute.name.as_str()) {
                continue;
            }
            let mut help = if allowed.is_empty() {
                format!("<{}> takes no attributes", self.tag)
            } else {
                format!("<{}> takes the attributes {}", self.tag, allowed.join(", "))
            };
            if let Some(close) = closest_match(&attribute.name, allowed) {
                help = format!("did you mean \"{close}\"? {help}");
            }
            return Err(Error::input(
                &attribute.location,
                format!(
                    "unexpected attribute \"{}\" in {}",
                    quote(&attribute.name),
                    self.describe()
                ),
            )
            .with_help(help));
        }
        Ok(())
    }

    /// `<float name="fov">` (or `<translate>` when there is no name), for messages.
    pub fn describe(&self) -> String {
        match self.get("name") {
            Some(name) => format!("<{} name=\"{}\">", self.tag, quote(&name.value)),
            None => format!("<{}>", self.tag),
        }
    }

    /// An error about the value of `attribute`: `<float name="fov">: value="abc" {problem}`.
    pub fn invalid_value(&self, attribute: &Attribute, problem: &str, help: &str) -> Error {
        Error::input(
            &attribute.location,
            format!(
                "{}: {}=\"{}\" {problem}",
                self.describe(),
                attribute.name,
                quote(&attribute.value)
            ),
        )
        .with_help(help)
    }

    /// A finite number.
    pub fn number(&self, attribute: &Attribute) -> Result<f64> {
        parse_finite(&attribute.value)
            .ok_or_else(|| self.invalid_value(attribute, "is not a finite number", NUMBER_HELP))
    }

    /// A list of finite numbers separated by commas and/or whitespace.
    pub fn number_list(&self, attribute: &Attribute) -> Result<Vec<f64>> {
        tokens(&attribute.value)
            .map(|token| {
                parse_finite(token).ok_or_else(|| {
                    self.invalid_value(
                        attribute,
                        &format!(
                            "contains \"{}\", which is not a finite number",
                            quote(token)
                        ),
                        NUMBER_HELP,
                    )
                })
            })
            .collect()
    }

    /// The error for a list with the wrong number of entries; `expected` reads like "1 or 3".
    pub fn count_error(&self, attribute: &Attribute, found: usize, expected: &str) -> Error {
        self.invalid_value(
            attribute,
            &format!("has {found} numbers, but {expected} are expected"),
            "separate the numbers with commas or spaces",
        )
    }

    /// A 64-bit signed integer in decimal notation.
    pub fn integer(&self, attribute: &Attribute) -> Result<i64> {
        attribute.value.trim().parse().map_err(|_| {
            self.invalid_value(
                attribute,
                "is not an integer",
                "write a whole number such as 16, without a decimal point or exponent",
            )
        })
    }

    /// `true` or `false`, in any letter case (as Mitsuba accepts).
    pub fn boolean(&self, attribute: &Attribute) -> Result<bool> {
        let value = attribute.value.trim();
        if value.eq_ignore_ascii_case("true") {
            Ok(true)
        } else if value.eq_ignore_ascii_case("false") {
            Ok(false)
        } else {
            Err(self.invalid_value(
                attribute,
                "is not a boolean",
                "write value=\"true\" or value=\"false\"",
            ))
        }
    }

    /// A 3-vector written either as `value="a"` (meaning a, a, a) or `value="x, y, z"`, or as
    /// separate `x`, `y`, `z` attributes where a missing one takes `default` (Mitsuba's
    /// `expand_value_to_xyz` followed by `parse_vector`).
    pub fn xyz(&self, default: f64) -> Result<DVec3> {
        let components = ["x", "y", "z"].map(|axis| self.get(axis));
        if let Some(value) = self.get("value") {
            if let Some(mixed) = components.iter().flatten().next() {
                return Err(Error::input(
                    &mixed.location,
                    format!(
                        "{} mixes a value attribute with x/y/z attributes",
                        self.describe()
                    ),
                )
                .with_help("give either value=\"x, y, z\" or the separate x, y, z attributes"));
            }
            let numbers = self.number_list(value)?;
            return match numbers[..] {
                [v] => Ok(DVec3::splat(v)),
                [x, y, z] => Ok(DVec3::new(x, y, z)),
                _ => Err(self.count_error(value, numbers.len(), "1 or 3")),
            };
        }
        let mut result = DVec3::splat(default);
        for (axis, attribute) in components.iter().enumerate() {
            if let Some(attribute) = attribute {
                result[axis] = self.number(attribute)?;
            }
        }
        Ok(result)
    }
}

const NUMBER_HELP: &str = "write a decimal number such as 0.5, -2 or 1e-3";

/// A finite number, or `None` when `text` is not one.
pub(super) fn parse_finite(text: &str) -> Option<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|value| value.is_finite())
}

/// The entries of a list separated by commas and/or whitespace; empty entries are skipped.
pub(super) fn tokens(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|token| !token.is_empty())
}

/// `text` shortened for messages, so that a huge attribute cannot flood the terminal.
pub(crate) fn quote(text: &str) -> String {
    const LIMIT: usize = 60;
    if text.chars().count() <= LIMIT {
        text.to_string()
    } else {
        let head: String = text.chars().take(LIMIT - 3).collect();
        format!("{head}...")
    }
}
