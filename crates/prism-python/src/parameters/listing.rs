//! The parameters a scene's description holds, plugin by plugin in document order, and their
//! keys: the plugins' names, and the properties' names with Mitsuba's suffixes.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use super::values::{Kind, relative_ior};
use prism_core::camera::perspective::FovAxis;
use prism_mitsuba::description::{
    NestedPlugin, PluginClass, PluginNode, PropertyValue, SpectrumValue,
};
use prism_mitsuba::factory::sensor::film;
use prism_mitsuba::reference::reference;
use prism_mitsuba::registry::{Default, ParamKind, ParamSpec};

/// The child indices that lead from the root of a description to one of its plugins.
pub(super) type NodePath = Vec<usize>;

/// One parameter: where it is in the description and what it holds.
#[derive(Clone, Debug)]
pub(super) struct Parameter {
    /// The plugin's name (the key without the parameter's part).
    pub(super) plugin: String,
    /// The plugin's description, `bsdf "diffuse"`, for the table.
    pub(super) describe: String,
    pub(super) class: PluginClass,
    pub(super) node: NodePath,
    /// The property the value is written in.
    pub(super) property: String,
    pub(super) kind: Kind,
    /// The plugin's default, for a parameter its description does not write.
    pub(super) default: Option<PropertyValue>,
}

impl Parameter {
    /// The parameter written in `property` of the plugin `node`, called `plugin`, at `path`.
    fn new(
        node: &PluginNode,
        plugin: &str,
        path: &NodePath,
        property: &str,
        kind: Kind,
        default: Option<PropertyValue>,
    ) -> Parameter {
        Parameter {
            plugin: plugin.to_string(),
            describe: node.describe(),
            class: node.class,
            node: path.clone(),
            property: property.to_string(),
            kind,
            default,
        }
    }
}

/// The parameters of a description, gathered plugin by plugin in document order.
#[derive(Default)]
pub(super) struct Listing {
    pub(super) parameters: Vec<(String, Parameter)>,
    seen: HashSet<*const PluginNode>,
    /// Each plugin's declared parameters, by class and type.
    declared: HashMap<(PluginClass, &'static str), &'static [ParamSpec]>,
}

impl Listing {
    /// The parameters of the plugins in the scene `root`.
    pub(super) fn plugins(&mut self, root: &Arc<PluginNode>) {
        for class in reference() {
            for plugin in class.plugins {
                self.declared
                    .insert((class.class, plugin.name), plugin.params);
            }
        }
        let names = child_names(root, None);
        for (index, (child, name)) in root.children.iter().zip(names).enumerate() {
            self.plugin(&child.node, name, vec![index]);
        }
    }

    /// The parameters of the plugin `node`, called `name`, at `path`, and of those it nests.
    fn plugin(&mut self, node: &Arc<PluginNode>, name: String, path: NodePath) {
        if !self.seen.insert(Arc::as_ptr(node)) {
            return;
        }
        let written = node.properties.iter().map(|p| (&p.name, &p.value, None));
        let defaults = self.unwritten_defaults(node);
        let defaults = (defaults.iter()).map(|(name, value)| (name, value, Some(value.clone())));
        for (property, value, default) in written.chain(defaults) {
            let Some((mut suffix, kind)) = property_kind(value) else {
                continue;
            };
            if suffix.is_empty() && self.is_textured(node, property) {
                suffix = ".value";
            }
            let parameter = Parameter::new(node, &name, &path, property, kind, default);
            (self.parameters).push((format!("{name}.{property}{suffix}"), parameter));
        }
        if let Some(kind) = horizontal_fov_kind(node) {
            let parameter = Parameter::new(node, &name, &path, "fov", kind, None);
            self.parameters.push((format!("{name}.x_fov"), parameter));
        }
        if let Some(kind) = self.relative_ior_kind(node) {
            let parameter = Parameter::new(node, &name, &path, "int_ior", kind, None);
            self.parameters.push((format!("{name}.eta"), parameter));
        }
        let names = child_names(node, Some(&name));
        for (index, (child, child_name)) in node.children.iter().zip(names).enumerate() {
            let mut child_path = path.clone();
            child_path.push(index);
            self.plugin(&child.node, child_name, child_path);
        }
    }

    /// The parameters of the plugin `node` that its description leaves at a default number,
    /// integer or boolean (those neither written as properties nor given as nested plugins),
    /// with their defaults, in the order the plugin declares them.
    fn unwritten_defaults(&self, node: &PluginNode) -> Vec<(String, PropertyValue)> {
        let Some(specs) = self.declared.get(&(node.class, node.plugin_type.as_str())) else {
            return Vec::new();
        };
        let given = |name: &str| {
            node.properties.iter().any(|p| p.name == name)
                || (node.children.iter()).any(|c| c.name.as_deref() == Some(name))
        };
        (specs.iter())
            .filter(|spec| !given(spec.name))
            .filter_map(|spec| {
                let value = match (spec.default, spec.kind) {
                    (
                        Default::Float(v),
                        ParamKind::Float
                        | ParamKind::FloatIn(_)
                        | ParamKind::FloatTexture(_)
                        | ParamKind::Spectrum { .. }
                        | ParamKind::Volume(_),
                    ) => PropertyValue::Float(v),
                    (Default::Integer(n), ParamKind::Integer) => PropertyValue::Integer(n),
                    (Default::Boolean(b), ParamKind::Boolean) => PropertyValue::Boolean(b),
                    _ => return None,
                };
                Some((spec.name.to_string(), value))
            })
            .collect()
    }

    /// Mitsuba's `eta` of a plugin that declares `int_ior` and `ext_ior`, when both are numbers
    /// or names (not spectra).
    fn relative_ior_kind(&self, node: &PluginNode) -> Option<Kind> {
        let specs = self
            .declared
            .get(&(node.class, node.plugin_type.as_str()))?;
        let default = |name: &str| {
            let spec = specs.iter().find(|spec| spec.name == name)?;
            match spec.default {
                Default::Str(index) => Some(index),
                _ => None,
            }
        };
        let (interior, exterior) = (default("int_ior")?, default("ext_ior")?);
        relative_ior(node, interior, exterior)?;
        Some(Kind::RelativeIor { interior, exterior })
    }

    /// Whether the plugin's parameter `name` is a spectrum or texture (a nested plugin in
    /// Mitsuba, whose number is its `value`).
    fn is_textured(&self, node: &PluginNode, name: &str) -> bool {
        let declared = self.declared.get(&(node.class, node.plugin_type.as_str()));
        let spec = declared.and_then(|specs| specs.iter().find(|spec| spec.name == name));
        spec.is_some_and(|spec| {
            matches!(
                spec.kind,
                ParamKind::Spectrum { .. } | ParamKind::Volume(_) | ParamKind::FloatTexture(_)
            )
        })
    }
}

/// The names of the plugins `node` nests, `parent` being its own name (None for the scene):
/// each one's `id`; else its `name` (a dictionary's key, an XML `name` attribute) or its
/// class, numbered from 0 when several siblings share it, after the parent's name and a dot.
pub(super) fn child_names(node: &PluginNode, parent: Option<&str>) -> Vec<String> {
    // Mitsuba's `twosided` calls the BSDFs it nests `brdf_0` and `brdf_1`.
    let twosided = node.class == PluginClass::Bsdf && node.plugin_type == "twosided";
    let slot = |child: &NestedPlugin| -> String {
        match &child.name {
            Some(name) => name.clone(),
            None if twosided => "brdf".to_string(),
            None => child.node.class.tag().to_string(),
        }
    };
    let mut counts: HashMap<String, usize> = HashMap::new();
    for child in node.children.iter().filter(|c| c.node.id.is_none()) {
        *counts.entry(slot(child)).or_default() += 1;
    }
    let mut numbers: HashMap<String, usize> = HashMap::new();
    (node.children.iter())
        .map(|child| {
            if let Some(id) = &child.node.id {
                return id.clone();
            }
            let slot = slot(child);
            let name = if counts[&slot] > 1 || (twosided && child.name.is_none()) {
                let number = numbers.entry(slot.clone()).or_default();
                *number += 1;
                format!("{slot}_{}", *number - 1)
            } else {
                slot
            };
            match parent {
                Some(parent) => format!("{parent}.{name}"),
                None => name,
            }
        })
        .collect()
}

/// The key suffix and kind of a property's value; None for a value that is not a parameter
/// (a string, an animation, a pbrt-v4 scene's inline list of numbers, a tensor).
fn property_kind(value: &PropertyValue) -> Option<(&'static str, Kind)> {
    Some(match value {
        PropertyValue::Float(_) => ("", Kind::Float),
        PropertyValue::Integer(_) => ("", Kind::Integer),
        PropertyValue::Boolean(_) => ("", Kind::Boolean),
        PropertyValue::Rgb(_) => (".value", Kind::Rgb),
        PropertyValue::Spectrum(SpectrumValue::Uniform(_)) => (".value", Kind::UniformSpectrum),
        PropertyValue::Spectrum(SpectrumValue::Samples(samples)) => {
            let wavelengths = samples.iter().map(|&(wavelength, _)| wavelength).collect();
            (".values", Kind::SpectrumValues { wavelengths })
        }
        PropertyValue::Point(_) => ("", Kind::Point),
        PropertyValue::Vector(_) => ("", Kind::Vector),
        PropertyValue::Transform(_) => ("", Kind::Transform),
        PropertyValue::String(_)
        | PropertyValue::Animation(_)
        | PropertyValue::Numbers(_)
        | PropertyValue::Tensor { .. } => {
            return None;
        }
    })
}

/// The horizontal field of view of a `perspective` or `thinlens` sensor whose `fov` is
/// written, on the film it nests (hdrfilm's default size when it nests none).
fn horizontal_fov_kind(node: &PluginNode) -> Option<Kind> {
    let is_camera = node.class == PluginClass::Sensor
        && matches!(node.plugin_type.as_str(), "perspective" | "thinlens");
    let property = |node: &PluginNode, name: &str| {
        (node.properties.iter())
            .find(|p| p.name == name)
            .map(|p| p.value.clone())
    };
    if !is_camera || !matches!(property(node, "fov"), Some(PropertyValue::Float(_))) {
        return None;
    }
    let axis = match property(node, "fov_axis") {
        None => FovAxis::X,
        Some(PropertyValue::String(axis)) => match axis.as_str() {
            "x" => FovAxis::X,
            "y" => FovAxis::Y,
            "diagonal" => FovAxis::Diagonal,
            "smaller" => FovAxis::Smaller,
            "larger" => FovAxis::Larger,
            _ => return None,
        },
        Some(_) => return None,
    };
    let film = (node.children.iter()).find(|c| c.node.class == PluginClass::Film);
    let size = |spec: &ParamSpec| {
        let written = film.and_then(|film| property(&film.node, spec.name));
        match (written, spec.default) {
            (Some(PropertyValue::Integer(n)), _) | (None, Default::Integer(n)) => Some(n as f64),
            _ => None,
        }
    };
    let aspect = size(&film::WIDTH)? / size(&film::HEIGHT)?;
    Some(Kind::HorizontalFov { axis, aspect })
}

/// The name `traverse` gives `plugin`, a plugin of the scene `root` (where it first appears in
/// document order, as `traverse` meets it); None when the scene does not hold it.
pub fn plugin_name(root: &PluginNode, plugin: &Arc<PluginNode>) -> Option<String> {
    fn search(node: &PluginNode, name: Option<&str>, plugin: &Arc<PluginNode>) -> Option<String> {
        let names = child_names(node, name);
        for (child, child_name) in node.children.iter().zip(names) {
            if Arc::ptr_eq(&child.node, plugin) {
                return Some(child_name);
            }
            if let Some(found) = search(&child.node, Some(&child_name), plugin) {
                return Some(found);
            }
        }
        None
    }
    search(root, None, plugin)
}
