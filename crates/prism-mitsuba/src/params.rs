//! Typed, checked access to a plugin's properties, with Mitsuba's defaults.
//!
//! A plugin builder asks for each parameter it understands; [`Params::finish`] then reports any
//! property or nested plugin nobody asked for, naming the supported ones and the closest match,
//! so that a misspelled parameter is an error with a location instead of a silent default.

use std::cell::{Cell, RefCell};

use glam::{DMat4, DVec3};

use super::description::{NestedPlugin, PluginClass, PluginNode, Property, PropertyValue};
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::math::{AnimatedTransform, Transform};

/// Reads the properties of one plugin node and remembers which were read.
pub struct Params<'a> {
    node: &'a PluginNode,
    used_properties: Vec<Cell<bool>>,
    used_children: Vec<Cell<bool>>,
    asked: RefCell<Vec<&'static str>>,
}

impl<'a> Params<'a> {
    pub fn new(node: &'a PluginNode) -> Self {
        Params {
            node,
            used_properties: node.properties.iter().map(|_| Cell::new(false)).collect(),
            used_children: node.children.iter().map(|_| Cell::new(false)).collect(),
            asked: RefCell::new(Vec::new()),
        }
    }

    pub fn node(&self) -> &'a PluginNode {
        self.node
    }

    /// Where the plugin element starts.
    pub fn location(&self) -> &'a SourceLocation {
        &self.node.location
    }

    /// The property called `name`, marked as used.
    pub fn property(&self, name: &'static str) -> Option<&'a Property> {
        self.asked.borrow_mut().push(name);
        let index = self.node.properties.iter().position(|p| p.name == name)?;
        self.used_properties[index].set(true);
        Some(&self.node.properties[index])
    }

    /// Where the property `name` is written, or the plugin's location when it is absent.
    pub fn location_of(&self, name: &str) -> &'a SourceLocation {
        self.node
            .properties
            .iter()
            .find(|p| p.name == name)
            .map(|p| &p.location)
            .unwrap_or(&self.node.location)
    }

    fn wrong_type(&self, property: &Property, expected: &str) -> Error {
        Error::input(
            &property.location,
            format!(
                "parameter \"{}\" of {} must be {expected}, but a {} was given",
                property.name,
                self.node.describe(),
                property.value.type_name()
            ),
        )
        .with_help(format!(
            "write it as <{} name=\"{}\" value=\"...\"/>",
            expected.trim_start_matches("a ").trim_start_matches("an "),
            property.name
        ))
    }

    /// A float (an integer is accepted too), if present.
    pub fn float_opt(&self, name: &'static str) -> Result<Option<f64>> {
        match self.property(name) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Float(v) => Ok(Some(v)),
                PropertyValue::Integer(v) => Ok(Some(v as f64)),
                _ => Err(self.wrong_type(p, "a float")),
            },
        }
    }

    /// A float, or `default` when absent.
    pub fn float(&self, name: &'static str, default: f64) -> Result<f64> {
        Ok(self.float_opt(name)?.unwrap_or(default))
    }

    /// An integer, if present.
    pub fn integer_opt(&self, name: &'static str) -> Result<Option<i64>> {
        match self.property(name) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Integer(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "an integer")),
            },
        }
    }

    /// An integer, or `default` when absent.
    pub fn integer(&self, name: &'static str, default: i64) -> Result<i64> {
        Ok(self.integer_opt(name)?.unwrap_or(default))
    }

    /// A boolean, or `default` when absent.
    pub fn boolean(&self, name: &'static str, default: bool) -> Result<bool> {
        match self.property(name) {
            None => Ok(default),
            Some(p) => match p.value {
                PropertyValue::Boolean(v) => Ok(v),
                _ => Err(self.wrong_type(p, "a boolean")),
            },
        }
    }

    /// A string, if present.
    pub fn string_opt(&self, name: &'static str) -> Result<Option<&'a str>> {
        match self.property(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                PropertyValue::String(v) => Ok(Some(v.as_str())),
                _ => Err(self.wrong_type(p, "a string")),
            },
        }
    }

    /// A string, or `default` when absent.
    pub fn string(&self, name: &'static str, default: &'a str) -> Result<&'a str> {
        Ok(self.string_opt(name)?.unwrap_or(default))
    }

    /// A transform, if present.
    pub fn transform_opt(&self, name: &'static str) -> Result<Option<DMat4>> {
        match self.property(name) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Transform(m) => Ok(Some(m)),
                _ => Err(self.wrong_type(p, "a transform")),
            },
        }
    }

    /// A transform, or the identity when absent.
    pub fn transform(&self, name: &'static str) -> Result<DMat4> {
        Ok(self.transform_opt(name)?.unwrap_or(DMat4::IDENTITY))
    }

    /// A transform that may be animated (`<transform>` or `<animation>`); the identity when
    /// absent. A singular transform is an error at its location.
    pub fn animated_transform(&self, name: &'static str) -> Result<AnimatedTransform> {
        let singular = |p: &Property| {
            Error::input(
                &p.location,
                format!(
                    "the \"{name}\" transform of {} is singular or not affine",
                    self.node.describe()
                ),
            )
            .with_help("check for a zero scale or a malformed matrix")
        };
        match self.property(name) {
            None => Ok(AnimatedTransform::fixed(Transform::IDENTITY)),
            Some(p) => match &p.value {
                PropertyValue::Transform(m) => Transform::new(*m)
                    .map(AnimatedTransform::fixed)
                    .ok_or_else(|| singular(p)),
                PropertyValue::Animation(keys) => {
                    AnimatedTransform::new(keys).map_err(|_| singular(p))
                }
                _ => Err(self.wrong_type(p, "a transform")),
            },
        }
    }

    /// A point, if present.
    pub fn point_opt(&self, name: &'static str) -> Result<Option<DVec3>> {
        match self.property(name) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Point(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "a point")),
            },
        }
    }

    /// A vector (a point is accepted too, as Mitsuba does), if present.
    pub fn vector_opt(&self, name: &'static str) -> Result<Option<DVec3>> {
        match self.property(name) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Vector(v) | PropertyValue::Point(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "a vector")),
            },
        }
    }

    /// A float that must lie in `[min, max]` (inclusive); an error names the range otherwise.
    pub fn float_in(&self, name: &'static str, default: f64, min: f64, max: f64) -> Result<f64> {
        let value = self.float(name, default)?;
        if !(value >= min && value <= max) {
            return Err(Error::input(
                self.location_of(name),
                format!(
                    "parameter \"{name}\" of {} is {value}, outside the valid range [{min}, {max}]",
                    self.node.describe()
                ),
            ));
        }
        Ok(value)
    }

    /// The nested plugins of one class, marked as used, in document order.
    pub fn children(&self, class: PluginClass) -> Vec<&'a NestedPlugin> {
        let mut found = Vec::new();
        for (index, child) in self.node.children.iter().enumerate() {
            if child.node.class == class {
                self.used_children[index].set(true);
                found.push(child);
            }
        }
        found
    }

    /// At most one nested plugin of a class; two or more are an error.
    pub fn single_child(&self, class: PluginClass) -> Result<Option<&'a NestedPlugin>> {
        let children = self.children(class);
        match children.as_slice() {
            [] => Ok(None),
            [one] => Ok(Some(*one)),
            [_, second, ..] => Err(Error::input(
                &second.location,
                format!(
                    "{} takes at most one nested {}, but several were given",
                    self.node.describe(),
                    class.tag()
                ),
            )
            .with_help("remove all but one of them")),
        }
    }

    /// The nested plugin given for parameter `name` (`<texture name="reflectance" .../>`), if any.
    pub fn named_child(&self, name: &'static str) -> Option<&'a NestedPlugin> {
        self.asked.borrow_mut().push(name);
        let index = self
            .node
            .children
            .iter()
            .position(|c| c.name.as_deref() == Some(name))?;
        self.used_children[index].set(true);
        Some(&self.node.children[index])
    }

    /// Reports the first property or nested plugin that no one asked for.
    pub fn finish(self) -> Result<()> {
        let asked = self.asked.borrow();
        for (property, used) in self.node.properties.iter().zip(&self.used_properties) {
            if !used.get() {
                return Err(unknown_parameter(
                    self.node,
                    &property.name,
                    &property.location,
                    &asked,
                ));
            }
        }
        for (child, used) in self.node.children.iter().zip(&self.used_children) {
            if !used.get() {
                let message = format!(
                    "{} does not take a nested {} ({})",
                    self.node.describe(),
                    child.node.class.tag(),
                    child.node.describe()
                );
                return Err(Error::input(&child.location, message)
                    .with_help("remove it, or check that it is nested in the right element"));
            }
        }
        Ok(())
    }
}

fn unknown_parameter(
    node: &PluginNode,
    name: &str,
    location: &SourceLocation,
    supported: &[&'static str],
) -> Error {
    let mut names: Vec<&str> = supported.to_vec();
    names.sort_unstable();
    names.dedup();
    let message = format!("unknown parameter \"{name}\" for {}", node.describe());
    let mut help = if names.is_empty() {
        "this plugin takes no parameters".to_string()
    } else {
        format!("supported parameters: {}", names.join(", "))
    };
    if let Some(closest) = closest_match(name, &names) {
        help = format!("did you mean \"{closest}\"? {help}");
    }
    Error::input(location, message).with_help(help)
}

/// The candidate closest to `name` by edit distance, if it is close enough to be a likely typo.
pub fn closest_match<'b>(name: &str, candidates: &[&'b str]) -> Option<&'b str> {
    candidates
        .iter()
        .map(|c| (edit_distance(name, c), *c))
        .filter(|(d, c)| *d <= (c.len().max(name.len()) / 3).max(1))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Levenshtein distance between two strings, counted in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitution = diagonal + usize::from(ca != *cb);
            diagonal = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_counts_single_edits() {
        assert_eq!(edit_distance("reflectance", "reflectance"), 0);
        assert_eq!(edit_distance("reflectanse", "reflectance"), 1);
        assert_eq!(edit_distance("fov", "fob"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
    }

    #[test]
    fn closest_match_suggests_only_near_names() {
        let names = ["radiance", "reflectance", "max_depth"];
        assert_eq!(closest_match("reflectanse", &names), Some("reflectance"));
        assert_eq!(closest_match("maxdepth", &names), Some("max_depth"));
        assert_eq!(closest_match("colour", &names), None);
    }
}
