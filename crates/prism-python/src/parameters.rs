//! `traverse(scene)`: the scene's parameters as a mapping from keys named as Mitsuba 3's
//! `mi.traverse` names them (`red.reflectance.value`, `sensor.to_world`, `sensor.x_fov`,
//! `light.emitter.radiance.value`, ...) to their values; `params[key] = value` records a
//! change and `params.update()` applies the changes.
//!
//! A parameter is a value written in the scene's description (a property of one of its
//! plugins), or a number, integer or boolean that its plugin declares and the description
//! leaves at its default (set, it is written). An update writes the new values into a copy of
//! the description (plugins that share a node keep sharing it) and builds the scene again
//! from it, reading no file again ([`crate::scene::Scene::rebuild`]): the scene is the one the
//! edited description loads from scratch, by construction. When no changed parameter belongs
//! to a `<shape>`, the hierarchy over the shapes is kept.
//!
//! Keys: a plugin with an `id` is called by it; one without by its `name` (its key in a
//! dictionary) or else its class, numbered from 0 when several siblings share it, after its
//! parent's name and a dot (`light.emitter`, `sensor.film`; in the scene itself `sensor`,
//! `shape_0`, `shape_1`). A property is `<plugin>.<name>`, a colour, a spectrum or a number
//! where a texture may stand `<plugin>.<name>.value` (`.values` for a spectrum sampled at
//! wavelengths); a `perspective` or `thinlens` sensor with a `fov` has `<sensor>.x_fov`, its
//! horizontal field of view, and a BSDF with `int_ior` and `ext_ior` has `<bsdf>.eta`, their
//! ratio.

use std::collections::btree_map::Entry;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::sync::Arc;

use glam::{DMat4, DVec3};
use numpy::IntoPyArray;
use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PySet, PyString};

use crate::error::to_py;
use crate::scene::Scene;
use crate::transform::Transform;
use prism_core::camera::perspective::{FovAxis, horizontal_fov};
use prism_core::error::Error;
use prism_core::spectrum::ior::named_ior;
use prism_mitsuba::description::{
    NestedPlugin, PluginClass, PluginNode, Property, PropertyValue, SpectrumValue,
};
use prism_mitsuba::factory::sensor::film;
use prism_mitsuba::reference::reference;
use prism_mitsuba::registry::{Default, ParamKind, ParamSpec};
use prism_mitsuba::suggest::closest_match;

/// The child indices that lead from the root of a description to one of its plugins.
type NodePath = Vec<usize>;

/// What a parameter holds, and so which Python values it takes.
#[derive(Clone, Debug)]
enum Kind {
    Float,
    Integer,
    Boolean,
    /// An `<rgb>` colour: three numbers (one number means three equal ones).
    Rgb,
    /// A `<spectrum>` of one value at every wavelength.
    UniformSpectrum,
    /// The values of a `<spectrum>` sampled at `wavelengths` (nm), which stay.
    SpectrumValues {
        wavelengths: Vec<f64>,
    },
    Point,
    Vector,
    Transform,
    /// The horizontal field of view of a camera whose `fov` is measured along `axis` on a film
    /// of `aspect` = width / height; set, it becomes `fov` along `fov_axis` "x".
    HorizontalFov {
        axis: FovAxis,
        aspect: f64,
    },
    /// Mitsuba's `eta` of a dielectric interface, `int_ior` / `ext_ior` (each a number or a
    /// name; absent, the named default `interior` or `exterior`); set, it becomes `int_ior`
    /// over an `ext_ior` of 1.
    RelativeIor {
        interior: &'static str,
        exterior: &'static str,
    },
}

impl Kind {
    /// The parameter's type, for the table and for messages.
    fn describe(&self) -> &'static str {
        match self {
            Kind::Float
            | Kind::UniformSpectrum
            | Kind::HorizontalFov { .. }
            | Kind::RelativeIor { .. } => "float",
            Kind::Integer => "int",
            Kind::Boolean => "bool",
            Kind::Rgb => "rgb",
            Kind::SpectrumValues { .. } => "spectrum values",
            Kind::Point => "point",
            Kind::Vector => "vector",
            Kind::Transform => "Transform",
        }
    }
}

/// One parameter: where it is in the description and what it holds.
#[derive(Clone, Debug)]
struct Parameter {
    /// The plugin's name (the key without the parameter's part).
    plugin: String,
    /// The plugin's description, `bsdf "diffuse"`, for the table.
    describe: String,
    class: PluginClass,
    node: NodePath,
    /// The property the value is written in.
    property: String,
    kind: Kind,
    /// The plugin's default, for a parameter its description does not write.
    default: Option<PropertyValue>,
}

/// The argument of [`SceneParameters::keep`]: one pattern or several.
#[derive(FromPyObject)]
pub enum Patterns {
    One(String),
    Many(Vec<String>),
}

/// The parameters of a scene, by key, and the changes recorded but not yet applied.
#[pyclass(module = "prism_renderer", mapping)]
pub struct SceneParameters {
    scene: Py<Scene>,
    parameters: BTreeMap<String, Parameter>,
    /// Keys in the order of the description (document order).
    keys: Vec<String>,
    /// The changed values, by key, as the description will hold them.
    changes: BTreeMap<String, PropertyValue>,
}

/// The parameters of `scene`, to read and change.
#[pyfunction]
pub fn traverse(scene: Bound<'_, Scene>) -> PyResult<SceneParameters> {
    let mut listing = Listing::default();
    let description = (scene.try_borrow().map_err(|_| rendering(scene.py()))?)
        .description()
        .clone();
    listing.plugins(&description);
    // Where two plugins would give one key (an `id` equal to another plugin's generated
    // name), the first in document order has it.
    let mut parameters = BTreeMap::new();
    let mut keys = Vec::new();
    for (key, parameter) in listing.parameters {
        if let Entry::Vacant(entry) = parameters.entry(key.clone()) {
            entry.insert(parameter);
            keys.push(key);
        }
    }
    Ok(SceneParameters {
        scene: scene.unbind(),
        parameters,
        keys,
        changes: BTreeMap::new(),
    })
}

/// The error for a scene held by a render that changes it (one with a crop window).
fn rendering(py: Python<'_>) -> PyErr {
    to_py(
        py,
        &Error::usage("the scene is rendering: read or change its parameters after the render"),
    )
}

#[pymethods]
impl SceneParameters {
    /// The keys, in the order of the scene's description.
    fn keys(&self) -> Vec<String> {
        self.keys.clone()
    }

    /// `(key, value)` for every parameter, in the order of [`Self::keys`].
    fn items<'py>(&self, py: Python<'py>) -> PyResult<Vec<(String, Bound<'py, PyAny>)>> {
        (self.keys.iter())
            .map(|key| Ok((key.clone(), self.__getitem__(py, key)?)))
            .collect()
    }

    fn __len__(&self) -> usize {
        self.keys.len()
    }

    fn __contains__(&self, key: &str) -> bool {
        self.parameters.contains_key(key)
    }

    fn __iter__(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let keys = self.keys.clone().into_pyobject(py)?;
        Ok(keys.try_iter()?.into_any().unbind())
    }

    /// The parameter's value: its change if one is recorded, else the scene's.
    fn __getitem__<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        let parameter = self.parameter(key)?;
        if let Some(value) = self.changes.get(key) {
            return to_python(py, value);
        }
        let scene = self.scene.try_borrow(py).map_err(|_| rendering(py))?;
        let node = node_at(scene.description(), &parameter.node);
        if let Kind::RelativeIor { interior, exterior } = parameter.kind {
            let eta = relative_ior(node, interior, exterior).expect("listed with numeric indices");
            return Ok(eta.into_pyobject(py)?.into_any());
        }
        let value = (node.properties.iter())
            .find(|p| p.name == parameter.property)
            .map(|p| &p.value)
            .or(parameter.default.as_ref());
        match (&parameter.kind, value) {
            (Kind::HorizontalFov { axis, aspect }, Some(PropertyValue::Float(fov))) => {
                Ok(horizontal_fov(*fov, *axis, *aspect)
                    .into_pyobject(py)?
                    .into_any())
            }
            (_, Some(value)) => to_python(py, value),
            (_, None) => unreachable!("a listed parameter is written or has a default"),
        }
    }

    /// Records a change of the parameter `key` to `value`, checked against its type and shape;
    /// [`Self::update`] applies it.
    fn __setitem__(&mut self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let parameter = self.parameter(key)?;
        let value = from_python(key, parameter, value)?;
        self.changes.insert(key.to_string(), value);
        Ok(())
    }

    /// Applies the changes recorded (after setting `values`, a dictionary of keys to values, if
    /// given): the scene is built again from its description with the new values, as if
    /// loaded from scratch, reading no file again. Returns, as Mitsuba's `update`, the changed
    /// plugins with the keys changed in each, as `(plugin, {keys})` pairs. When the new values
    /// are refused (a roughness out of range, ...), PrismError is raised, the scene is left
    /// as it was and the changes stay recorded.
    #[pyo3(signature = (values = None))]
    fn update<'py>(
        &mut self,
        py: Python<'py>,
        values: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Vec<(String, Bound<'py, PySet>)>> {
        if let Some(values) = values {
            for (key, value) in values.iter() {
                let key: String = key.extract()?;
                self.__setitem__(&key, &value)?;
            }
        }
        if self.changes.is_empty() {
            return Ok(Vec::new());
        }
        let scene = self.scene.bind(py);
        let mut scene = scene.try_borrow_mut().map_err(|_| rendering(py))?;
        let mut edits: HashMap<*const PluginNode, Vec<(String, PropertyValue)>> = HashMap::new();
        let mut same_shapes = true;
        for (key, value) in &self.changes {
            let parameter = &self.parameters[key];
            let node = node_at(scene.description(), &parameter.node);
            same_shapes &= parameter.class != PluginClass::Shape;
            let edits = edits.entry(Arc::as_ptr(node)).or_default();
            edits.push((parameter.property.clone(), value.clone()));
            match parameter.kind {
                Kind::HorizontalFov { .. } => {
                    edits.push(("fov_axis".into(), PropertyValue::String("x".into())));
                }
                Kind::RelativeIor { .. } => {
                    edits.push(("ext_ior".into(), PropertyValue::Float(1.0)))
                }
                _ => {}
            }
        }
        let description = edited(scene.description(), &edits, &mut HashMap::new());
        scene.rebuild(py, description, same_shapes)?;
        let mut plugins: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
        for key in self.changes.keys() {
            let plugin = &self.parameters[key].plugin;
            plugins.entry(plugin).or_default().push(key);
        }
        let updated = (plugins.into_iter())
            .map(|(plugin, keys)| Ok((plugin.to_string(), PySet::new(py, keys)?)))
            .collect::<PyResult<Vec<_>>>()?;
        self.changes.clear();
        Ok(updated)
    }

    /// Keeps only the parameters whose keys `patterns` match: a regular expression or a list of
    /// them, each matched at the start of a key (Python's `re.match`), as Mitsuba's `keep`
    /// (changes recorded for the other keys are dropped); None keeps them all. A pattern that
    /// matches no key raises `KeyError`.
    fn keep(&mut self, py: Python<'_>, patterns: Option<Patterns>) -> PyResult<()> {
        let patterns = match patterns {
            None => return Ok(()),
            Some(Patterns::One(pattern)) => vec![pattern],
            Some(Patterns::Many(patterns)) => patterns,
        };
        let re = py.import("re")?;
        let mut kept = HashSet::new();
        for pattern in &patterns {
            let compiled = re.call_method1("compile", (pattern,))?;
            let mut matched = false;
            for key in &self.keys {
                if !compiled.call_method1("match", (key,))?.is_none() {
                    kept.insert(key.clone());
                    matched = true;
                }
            }
            if !matched {
                return Err(self.unknown(pattern));
            }
        }
        self.keys.retain(|key| kept.contains(key));
        self.parameters.retain(|key, _| kept.contains(key));
        self.changes.retain(|key, _| kept.contains(key));
        Ok(())
    }

    /// A table of the parameters: key, type and plugin.
    fn __repr__(&self) -> String {
        let width = self
            .keys
            .iter()
            .map(|k| k.chars().count())
            .max()
            .unwrap_or(0);
        let mut text = String::from("SceneParameters[\n");
        for key in &self.keys {
            let parameter = &self.parameters[key];
            let changed = if self.changes.contains_key(key) {
                " (changed)"
            } else {
                ""
            };
            text += &format!(
                "  {key:width$}  {:15}  {}{changed}\n",
                parameter.kind.describe(),
                parameter.describe
            );
        }
        text + "]"
    }
}

impl SceneParameters {
    /// The parameter `key`; else a `KeyError` that suggests the closest key.
    fn parameter(&self, key: &str) -> PyResult<&Parameter> {
        self.parameters.get(key).ok_or_else(|| self.unknown(key))
    }

    /// The `KeyError` for `key`, which no parameter has: it suggests the closest key.
    fn unknown(&self, key: &str) -> PyErr {
        let keys: Vec<&str> = self.keys.iter().map(String::as_str).collect();
        let hint = match closest_match(key, &keys) {
            Some(close) => format!("; did you mean \"{close}\"?"),
            None => String::new(),
        };
        PyKeyError::new_err(format!(
            "the scene has no parameter \"{key}\"{hint} (params.keys() lists them)"
        ))
    }
}

/// The plugin at `path` below `root`.
fn node_at<'a>(root: &'a Arc<PluginNode>, path: &[usize]) -> &'a Arc<PluginNode> {
    path.iter()
        .fold(root, |node, &child| &node.children[child].node)
}

/// The description `node` with the property values `edits` gives for its plugins (by their
/// address in it) written in; a plugin with no edit below it is shared, not copied, and a
/// plugin referenced from several places is copied once (`copies`), so that they all still
/// refer to one plugin.
fn edited(
    node: &Arc<PluginNode>,
    edits: &HashMap<*const PluginNode, Vec<(String, PropertyValue)>>,
    copies: &mut HashMap<*const PluginNode, Arc<PluginNode>>,
) -> Arc<PluginNode> {
    let address = Arc::as_ptr(node);
    if let Some(copy) = copies.get(&address) {
        return copy.clone();
    }
    let children: Vec<_> = (node.children.iter())
        .map(|child| edited(&child.node, edits, copies))
        .collect();
    let own = edits.get(&address);
    let unchanged = own.is_none()
        && (node.children.iter())
            .zip(&children)
            .all(|(child, copy)| Arc::ptr_eq(&child.node, copy));
    let copy = if unchanged {
        node.clone()
    } else {
        let mut copy = PluginNode::clone(node);
        for (child, new) in copy.children.iter_mut().zip(children) {
            child.node = new;
        }
        for (name, value) in own.into_iter().flatten() {
            match copy.properties.iter_mut().find(|p| &p.name == name) {
                Some(property) => property.value = value.clone(),
                None => copy.properties.push(Property {
                    name: name.clone(),
                    value: value.clone(),
                    location: node.location.clone(),
                }),
            }
        }
        Arc::new(copy)
    };
    copies.insert(address, copy.clone());
    copy
}

/// The parameters of a description, gathered plugin by plugin in document order.
#[derive(Default)]
struct Listing {
    parameters: Vec<(String, Parameter)>,
    seen: HashSet<*const PluginNode>,
    /// Each plugin's declared parameters, by class and type.
    declared: HashMap<(PluginClass, &'static str), &'static [ParamSpec]>,
}

impl Listing {
    /// The parameters of the plugins in the scene `root`.
    fn plugins(&mut self, root: &Arc<PluginNode>) {
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

/// The names of the plugins `node` nests, `parent` being its own name (None for the scene):
/// each one's `id`; else its `name` (a dictionary's key, an XML `name` attribute) or its
/// class, numbered from 0 when several siblings share it, after the parent's name and a dot.
fn child_names(node: &PluginNode, parent: Option<&str>) -> Vec<String> {
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
/// (a string, an animation).
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
        PropertyValue::String(_) | PropertyValue::Animation(_) => return None,
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

/// `int_ior` / `ext_ior` of the plugin `node`, each a number or a name, or absent the named
/// default (`interior`, `exterior`); None when either is a spectrum.
fn relative_ior(node: &PluginNode, interior: &str, exterior: &str) -> Option<f64> {
    let index = |name: &str, default: &str| {
        let value = (node.properties.iter()).find(|p| p.name == name);
        match value.map(|p| &p.value) {
            Some(PropertyValue::Float(v)) => Some(*v),
            Some(PropertyValue::String(named)) => named_ior(named).map(f64::from),
            None => named_ior(default).map(f64::from),
            Some(_) => None,
        }
    };
    Some(index("int_ior", interior)? / index("ext_ior", exterior)?)
}

/// A value of the description as the Python value of the parameter.
fn to_python<'py>(py: Python<'py>, value: &PropertyValue) -> PyResult<Bound<'py, PyAny>> {
    let array = |values: Vec<f64>| values.into_pyarray(py).into_any();
    Ok(match value {
        PropertyValue::Float(v) => v.into_pyobject(py)?.into_any(),
        PropertyValue::Integer(v) => v.into_pyobject(py)?.into_any(),
        PropertyValue::Boolean(v) => PyBool::new(py, *v).to_owned().into_any(),
        PropertyValue::Rgb(rgb) => array(rgb.to_vec()),
        PropertyValue::Spectrum(SpectrumValue::Uniform(v)) => v.into_pyobject(py)?.into_any(),
        PropertyValue::Spectrum(SpectrumValue::Samples(samples)) => {
            array(samples.iter().map(|&(_, v)| v).collect())
        }
        PropertyValue::Point(p) | PropertyValue::Vector(p) => array(p.to_array().to_vec()),
        PropertyValue::Transform(matrix) => {
            Transform { matrix: *matrix }.into_pyobject(py)?.into_any()
        }
        PropertyValue::String(_) | PropertyValue::Animation(_) => {
            unreachable!("strings and animations are not parameters")
        }
    })
}

/// The Python `value` given for the parameter `key` as the description's value; a value of
/// another type or shape is an error that says what the parameter takes.
fn from_python(
    key: &str,
    parameter: &Parameter,
    value: &Bound<'_, PyAny>,
) -> PyResult<PropertyValue> {
    let py = value.py();
    let refuse = |takes: &str| {
        let shown = value
            .repr()
            .map(|r| r.to_string())
            .unwrap_or_else(|_| "the value".into());
        let shown: String = if shown.chars().count() > 60 {
            shown.chars().take(57).chain("...".chars()).collect()
        } else {
            shown
        };
        to_py(
            py,
            &Error::usage(format!("\"{key}\" cannot be set to {shown}"))
                .with_help(format!("\"{key}\" takes {takes}")),
        )
    };
    let number = |takes: &str| -> PyResult<f64> {
        let is_number = !value.is_instance_of::<PyBool>()
            && (value.is_instance_of::<PyFloat>()
                || value.is_instance_of::<PyInt>()
                || is_numpy_number(value));
        match is_number.then(|| value.extract::<f64>()) {
            Some(Ok(v)) if v.is_finite() => Ok(v),
            _ => Err(refuse(takes)),
        }
    };
    let numbers = |count: usize, takes: &str| -> PyResult<Vec<f64>> {
        if value.is_instance_of::<PyString>() {
            return Err(refuse(takes));
        }
        match value.extract::<Vec<f64>>() {
            Ok(v) if v.len() == count && v.iter().all(|x| x.is_finite()) => Ok(v),
            _ => Err(refuse(takes)),
        }
    };
    Ok(match &parameter.kind {
        Kind::Float => PropertyValue::Float(number("a finite number")?),
        Kind::HorizontalFov { .. } => {
            let fov = number("an angle in degrees between 0 and 180")?;
            if !(fov > 0.0 && fov < 180.0) {
                return Err(refuse("an angle in degrees between 0 and 180"));
            }
            PropertyValue::Float(fov)
        }
        Kind::RelativeIor { .. } => {
            let eta = number("a positive number")?;
            if eta <= 0.0 {
                return Err(refuse("a positive number"));
            }
            PropertyValue::Float(eta)
        }
        Kind::UniformSpectrum => {
            PropertyValue::Spectrum(SpectrumValue::Uniform(number("a finite number")?))
        }
        Kind::Integer => match value.extract::<i64>() {
            Ok(v) if !value.is_instance_of::<PyBool>() => PropertyValue::Integer(v),
            _ => return Err(refuse("an integer of 64 bits")),
        },
        Kind::Boolean => match value.cast::<PyBool>() {
            Ok(b) => PropertyValue::Boolean(b.is_true()),
            Err(_) => return Err(refuse("True or False")),
        },
        Kind::Rgb => {
            const TAKES: &str = "three finite numbers (red, green, blue) or one for all three";
            match number(TAKES) {
                Ok(v) => PropertyValue::Rgb([v; 3]),
                Err(_) => {
                    let v = numbers(3, TAKES)?;
                    PropertyValue::Rgb([v[0], v[1], v[2]])
                }
            }
        }
        Kind::SpectrumValues { wavelengths } => {
            let count = wavelengths.len();
            let takes = format!("{count} finite numbers, one per wavelength of the spectrum");
            let values = numbers(count, &takes)?;
            let samples = wavelengths.iter().copied().zip(values).collect();
            PropertyValue::Spectrum(SpectrumValue::Samples(samples))
        }
        Kind::Point => {
            PropertyValue::Point(DVec3::from_slice(&numbers(3, "three finite numbers")?))
        }
        Kind::Vector => {
            PropertyValue::Vector(DVec3::from_slice(&numbers(3, "three finite numbers")?))
        }
        Kind::Transform => {
            const TAKES: &str = "a Transform or a 4 × 4 matrix of finite numbers";
            if let Ok(transform) = value.cast::<Transform>() {
                PropertyValue::Transform(transform.get().matrix)
            } else {
                let rows = value.extract::<Vec<[f64; 4]>>().ok().and_then(|rows| {
                    let rows: [[f64; 4]; 4] = rows.try_into().ok()?;
                    rows.as_flattened()
                        .iter()
                        .all(|x| x.is_finite())
                        .then_some(rows)
                });
                match rows {
                    Some(rows) => {
                        PropertyValue::Transform(DMat4::from_cols_array_2d(&rows).transpose())
                    }
                    None => return Err(refuse(TAKES)),
                }
            }
        }
    })
}

/// Whether `value` is a numpy number or a numpy array of no dimensions (a number of another
/// type than Python's `float` or `int`).
fn is_numpy_number(value: &Bound<'_, PyAny>) -> bool {
    value.hasattr("dtype").unwrap_or(false)
        && value.hasattr("__float__").unwrap_or(false)
        && value
            .getattr("ndim")
            .and_then(|n| n.extract::<usize>())
            .map(|n| n == 0)
            .unwrap_or(false)
}
