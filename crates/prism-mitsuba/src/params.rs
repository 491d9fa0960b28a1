//! Typed, checked access to a plugin's properties, with Mitsuba's defaults.
//!
//! A plugin builder asks for each parameter by its declaration ([`crate::registry::ParamSpec`],
//! which holds the name and the default); [`Params::finish`] then reports any property or
//! nested plugin nobody asked for, naming the declared ones and the closest match, so that a
//! misspelled parameter is an error with a location instead of a silent default.
//! [`Params::finish_with_warnings`] turns the parameters declared [`Default::Ignored`] (Mitsuba
//! 0.6 forms Prism reads but does not implement) into one [`Warning`] each.

use std::borrow::Cow;
use std::cell::Cell;

use glam::{DMat4, DVec3};

use crate::description::{NestedPlugin, PluginNode, Property, PropertyValue, Warning};
use crate::registry::{Choice, Default, ParamKind, ParamSpec};
use crate::suggest::closest_match;
use prism_core::error::{Error, Result, SourceLocation};
use prism_core::math::{AnimatedTransform, Transform};

/// An array of numbers of given dimensions: a tensor parameter's value.
#[derive(Clone, Debug, PartialEq)]
pub struct Tensor<'a> {
    pub shape: Vec<usize>,
    /// The numbers, the last index fastest.
    pub values: Cow<'a, [f64]>,
}

/// Reads the properties of one plugin node through its plugin's declared parameters, and
/// remembers which were read.
pub struct Params<'a> {
    node: &'a PluginNode,
    declared: &'static [ParamSpec],
    used_properties: Vec<Cell<bool>>,
    used_children: Vec<Cell<bool>>,
}

impl<'a> Params<'a> {
    /// The parameters of `node`, a plugin whose parameters are `declared`.
    pub fn new(node: &'a PluginNode, declared: &'static [ParamSpec]) -> Self {
        Params {
            node,
            declared,
            used_properties: node.properties.iter().map(|_| Cell::new(false)).collect(),
            used_children: node.children.iter().map(|_| Cell::new(false)).collect(),
        }
    }

    pub fn node(&self) -> &'a PluginNode {
        self.node
    }

    /// Where the plugin element starts.
    pub fn location(&self) -> &'a SourceLocation {
        &self.node.location
    }

    /// Checks that a builder reads only what its plugin declares (a programming error, never
    /// a user's).
    fn check_declared(&self, spec: &ParamSpec) {
        assert!(
            self.declared.iter().any(|d| d.name == spec.name),
            "{} reads the undeclared parameter \"{}\"",
            self.node.describe(),
            spec.name
        );
    }

    /// The property of `spec`, marked as used.
    pub fn property(&self, spec: &ParamSpec) -> Option<&'a Property> {
        self.check_declared(spec);
        let index = self
            .node
            .properties
            .iter()
            .position(|p| p.name == spec.name)?;
        self.used_properties[index].set(true);
        Some(&self.node.properties[index])
    }

    /// Whether `spec` is given, as a property or a nested plugin.
    pub fn has(&self, spec: &ParamSpec) -> bool {
        self.property(spec).is_some() || self.named_child(spec).is_some()
    }

    /// Where the property `spec` is written, or the plugin's location when it is absent.
    pub fn location_of(&self, spec: &ParamSpec) -> &'a SourceLocation {
        self.node
            .properties
            .iter()
            .find(|p| p.name == spec.name)
            .map(|p| &p.location)
            .unwrap_or(&self.node.location)
    }

    fn wrong_type(&self, property: &Property, expected: &str) -> Error {
        let given = match &property.value {
            PropertyValue::Tensor { shape, .. } if shape.len() == 1 => {
                format!("list of {} numbers", shape[0])
            }
            PropertyValue::Tensor { shape, .. } => format!("tensor of shape {shape:?}"),
            value => value.type_name().to_string(),
        };
        Error::input(
            &property.location,
            format!(
                "parameter \"{}\" of {} must be {expected}, but a {given} was given",
                property.name,
                self.node.describe(),
            ),
        )
        .with_help(format!(
            "write it as <{} name=\"{}\" value=\"...\"/>",
            expected.trim_start_matches("a ").trim_start_matches("an "),
            property.name
        ))
    }

    /// A float (an integer is accepted too), if present.
    pub fn float_opt(&self, spec: &ParamSpec) -> Result<Option<f64>> {
        match self.property(spec) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Float(v) => Ok(Some(v)),
                PropertyValue::Integer(v) => Ok(Some(v as f64)),
                _ => Err(self.wrong_type(p, "a float")),
            },
        }
    }

    /// A float, or its declared default when absent.
    pub fn float(&self, spec: &ParamSpec) -> Result<f64> {
        let default = match spec.default {
            Default::Float(v) => v,
            Default::Integer(v) => v as f64,
            other => panic!("\"{}\" has no numeric default ({other:?})", spec.name),
        };
        Ok(self.float_opt(spec)?.unwrap_or(default))
    }

    /// An integer, if present.
    pub fn integer_opt(&self, spec: &ParamSpec) -> Result<Option<i64>> {
        match self.property(spec) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Integer(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "an integer")),
            },
        }
    }

    /// An integer, or its declared default when absent.
    pub fn integer(&self, spec: &ParamSpec) -> Result<i64> {
        let Default::Integer(default) = spec.default else {
            panic!("\"{}\" has no integer default", spec.name);
        };
        Ok(self.integer_opt(spec)?.unwrap_or(default))
    }

    /// A boolean, or its declared default when absent.
    pub fn boolean(&self, spec: &ParamSpec) -> Result<bool> {
        let Default::Boolean(default) = spec.default else {
            panic!("\"{}\" has no boolean default", spec.name);
        };
        match self.property(spec) {
            None => Ok(default),
            Some(p) => match p.value {
                PropertyValue::Boolean(v) => Ok(v),
                _ => Err(self.wrong_type(p, "a boolean")),
            },
        }
    }

    /// A string, if present.
    pub fn string_opt(&self, spec: &ParamSpec) -> Result<Option<&'a str>> {
        match self.property(spec) {
            None => Ok(None),
            Some(p) => match &p.value {
                PropertyValue::String(v) => Ok(Some(v.as_str())),
                _ => Err(self.wrong_type(p, "a string")),
            },
        }
    }

    /// A string, or its declared default when absent.
    pub fn string(&self, spec: &ParamSpec) -> Result<&'a str> {
        let Default::Str(default) = spec.default else {
            panic!("\"{}\" has no string default", spec.name);
        };
        Ok(self.string_opt(spec)?.unwrap_or(default))
    }

    /// The value of the option `spec` declares that the scene names (compared ignoring ASCII
    /// case), or of its default.
    pub fn choice<T: Copy + 'static>(&self, spec: &ParamSpec) -> Result<T> {
        let ParamKind::Choice(choices) = spec.kind else {
            panic!("\"{}\" is not a choice", spec.name);
        };
        let value = self.string(spec)?;
        let Some(choice) = choices.iter().find(|c| c.name.eq_ignore_ascii_case(value)) else {
            return Err(Error::input(
                self.location_of(spec),
                format!(
                    "unknown value \"{value}\" for parameter \"{}\" of {}",
                    spec.name,
                    self.node.describe()
                ),
            )
            .with_help(format!("use one of: {}", Choice::names(choices).join(", "))));
        };
        let Some(selected) = choice.value.downcast_ref::<T>() else {
            panic!("the options of \"{}\" select another type", spec.name);
        };
        Ok(*selected)
    }

    /// A transform, if present.
    pub fn transform_opt(&self, spec: &ParamSpec) -> Result<Option<DMat4>> {
        match self.property(spec) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Transform(m) => Ok(Some(m)),
                _ => Err(self.wrong_type(p, "a transform")),
            },
        }
    }

    /// A transform, or the identity when absent.
    pub fn transform(&self, spec: &ParamSpec) -> Result<DMat4> {
        Ok(self.transform_opt(spec)?.unwrap_or(DMat4::IDENTITY))
    }

    /// A transform that may be animated (`<transform>` or `<animation>`); the identity when
    /// absent. A singular transform is an error at its location.
    pub fn animated_transform(&self, spec: &ParamSpec) -> Result<AnimatedTransform> {
        let singular = |p: &Property| {
            Error::input(
                &p.location,
                format!(
                    "the \"{}\" transform of {} is singular or not affine",
                    spec.name,
                    self.node.describe()
                ),
            )
            .with_help("check for a zero scale or a malformed matrix")
        };
        match self.property(spec) {
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

    /// A list of numbers, if present.
    pub fn numbers_opt(&self, spec: &ParamSpec) -> Result<Option<&'a [f64]>> {
        match self.property(spec) {
            None => Ok(None),
            Some(p) => match &p.value {
                PropertyValue::Numbers(v) | PropertyValue::Tensor { values: v, .. } => {
                    Ok(Some(v.as_slice()))
                }
                _ => Err(self.wrong_type(p, "a list of numbers")),
            },
        }
    }

    /// A tensor, if present. A list of numbers is one of one dimension, a point or vector one
    /// of three numbers, and a 4 × 4 matrix (read as a transform) one of 4 × 4, row by row.
    pub fn tensor_opt(&self, spec: &ParamSpec) -> Result<Option<Tensor<'a>>> {
        let Some(p) = self.property(spec) else {
            return Ok(None);
        };
        let (shape, values) = match &p.value {
            PropertyValue::Tensor { shape, values } => {
                (shape.clone(), Cow::from(values.as_slice()))
            }
            PropertyValue::Numbers(values) => (vec![values.len()], Cow::from(values.as_slice())),
            PropertyValue::Point(v) | PropertyValue::Vector(v) => {
                (vec![3], Cow::from(v.to_array().to_vec()))
            }
            PropertyValue::Transform(m) => (
                vec![4, 4],
                Cow::from(m.transpose().to_cols_array().to_vec()),
            ),
            _ => {
                return Err(Error::input(
                    &p.location,
                    format!(
                        "parameter \"{}\" of {} must be a tensor, but a {} was given",
                        p.name,
                        self.node.describe(),
                        p.value.type_name()
                    ),
                )
                .with_help(
                    "give it in a scene dictionary as a numpy array or nested lists of numbers \
                     (XML has no form for tensors)",
                ));
            }
        };
        Ok(Some(Tensor { shape, values }))
    }

    /// The names of the tensor properties the plugin does not declare, marked as used (read
    /// past, as Mitsuba keeps such tensors as per-primitive attributes), in document order.
    /// A dictionary reads some tensors as other values: three numbers as a point, a 4 × 4 array
    /// as a transform, and those count as tensors here too.
    pub fn undeclared_tensors(&self) -> Vec<&'a str> {
        let mut found = Vec::new();
        for (index, property) in self.node.properties.iter().enumerate() {
            let tensor = matches!(
                property.value,
                PropertyValue::Tensor { .. }
                    | PropertyValue::Numbers(_)
                    | PropertyValue::Point(_)
                    | PropertyValue::Transform(_)
            );
            if tensor && !self.declared.iter().any(|d| d.name == property.name) {
                self.used_properties[index].set(true);
                found.push(property.name.as_str());
            }
        }
        found
    }

    /// A point, if present.
    pub fn point_opt(&self, spec: &ParamSpec) -> Result<Option<DVec3>> {
        match self.property(spec) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Point(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "a point")),
            },
        }
    }

    /// A vector (a point is accepted too, as Mitsuba does), if present.
    pub fn vector_opt(&self, spec: &ParamSpec) -> Result<Option<DVec3>> {
        match self.property(spec) {
            None => Ok(None),
            Some(p) => match p.value {
                PropertyValue::Vector(v) | PropertyValue::Point(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(p, "a vector")),
            },
        }
    }

    /// A float within the bounds `spec` declares (inclusive), or its declared default.
    pub fn float_in(&self, spec: &ParamSpec) -> Result<f64> {
        let (ParamKind::FloatIn(bounds), Default::Float(default)) = (spec.kind, spec.default)
        else {
            panic!("\"{}\" is not a bounded float with a default", spec.name);
        };
        assert!(!bounds.min_exclusive, "\"{}\" has an open bound", spec.name);
        self.float_between(spec, default, f64::from(bounds.min), f64::from(bounds.max))
    }

    /// A float in `[min, max]`, or `default` when absent (for a parameter whose default and
    /// range depend on another's value); an error names the range otherwise.
    pub fn float_between(&self, spec: &ParamSpec, default: f64, min: f64, max: f64) -> Result<f64> {
        let value = self.float_opt(spec)?.unwrap_or(default);
        if !(value >= min && value <= max) {
            return Err(Error::input(
                self.location_of(spec),
                format!(
                    "parameter \"{}\" of {} is {value}, outside the valid range [{min}, {max}]",
                    spec.name,
                    self.node.describe()
                ),
            ));
        }
        Ok(value)
    }

    /// The nested plugins of the class `spec` declares, marked as used, in document order.
    pub fn children(&self, spec: &ParamSpec) -> Vec<&'a NestedPlugin> {
        self.check_declared(spec);
        let ParamKind::Nested(class) = spec.kind else {
            panic!("\"{}\" is not a nested plugin", spec.name);
        };
        let mut found = Vec::new();
        for (index, child) in self.node.children.iter().enumerate() {
            if child.node.class == class {
                self.used_children[index].set(true);
                found.push(child);
            }
        }
        found
    }

    /// The `<spectrum>` properties whose names the plugin does not declare (the bands of a
    /// `specfilm`, named by the scene), marked as used, in document order.
    pub fn undeclared_spectra(&self) -> Vec<&'a Property> {
        let mut found = Vec::new();
        for (index, property) in self.node.properties.iter().enumerate() {
            if matches!(property.value, PropertyValue::Spectrum(_))
                && !self.declared.iter().any(|d| d.name == property.name)
            {
                self.used_properties[index].set(true);
                found.push(property);
            }
        }
        found
    }

    /// At most one nested plugin of the class `spec` declares; two or more are an error.
    pub fn single_child(&self, spec: &ParamSpec) -> Result<Option<&'a NestedPlugin>> {
        let children = self.children(spec);
        match children.as_slice() {
            [] => Ok(None),
            [one] => Ok(Some(*one)),
            [_, second, ..] => Err(Error::input(
                &second.location,
                format!(
                    "{} takes at most one nested {}, but several were given",
                    self.node.describe(),
                    second.node.class.tag()
                ),
            )
            .with_help("remove all but one of them")),
        }
    }

    /// The nested plugin given for parameter `spec` (`<texture name="reflectance" .../>`), if
    /// any.
    pub fn named_child(&self, spec: &ParamSpec) -> Option<&'a NestedPlugin> {
        self.check_declared(spec);
        let index = self
            .node
            .children
            .iter()
            .position(|c| c.name.as_deref() == Some(spec.name))?;
        self.used_children[index].set(true);
        Some(&self.node.children[index])
    }

    /// Reports the first property or nested plugin that no one asked for. A plugin that
    /// declares ignored parameters finishes with [`Params::finish_with_warnings`] instead.
    pub fn finish(self) -> Result<()> {
        assert!(
            !self.declared.iter().any(|d| d.default == Default::Ignored),
            "{} declares ignored parameters: finish it with finish_with_warnings",
            self.node.describe()
        );
        self.finish_with_warnings().map(|_| ())
    }

    /// As [`Params::finish`], and one warning for each parameter declared
    /// [`Default::Ignored`] that the node gives, in document order; `doc` of its declaration
    /// says what is ignored.
    pub fn finish_with_warnings(self) -> Result<Vec<Warning>> {
        let mut warnings = Vec::new();
        for (property, used) in self.node.properties.iter().zip(&self.used_properties) {
            let ignored = self
                .declared
                .iter()
                .find(|d| d.name == property.name && d.default == Default::Ignored);
            if let Some(spec) = ignored {
                used.set(true);
                warnings.push(Warning {
                    location: property.location.clone(),
                    message: format!(
                        "{} ignores \"{}\": {}",
                        self.node.describe(),
                        spec.name,
                        spec.doc
                    ),
                });
            }
        }
        let declared: Vec<&str> = self
            .declared
            .iter()
            .filter(|d| !matches!(d.kind, ParamKind::Nested(_)))
            .map(|d| d.name)
            .collect();
        for (property, used) in self.node.properties.iter().zip(&self.used_properties) {
            if !used.get() {
                return Err(unknown_parameter(
                    self.node,
                    &property.name,
                    &property.location,
                    &declared,
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
        Ok(warnings)
    }
}

fn unknown_parameter(
    node: &PluginNode,
    name: &str,
    location: &SourceLocation,
    supported: &[&str],
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
