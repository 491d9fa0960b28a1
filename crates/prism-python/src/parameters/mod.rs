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

pub mod listing;
mod values;

use std::collections::btree_map::Entry;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::sync::Arc;

use pyo3::exceptions::PyKeyError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PySet};

use crate::error::to_py;
use crate::scene::Scene;
use listing::{Listing, Parameter};
use prism_core::camera::perspective::horizontal_fov;
use prism_core::error::Error;
use prism_mitsuba::description::{PluginClass, PluginNode, Property, PropertyValue};
use prism_mitsuba::suggest::closest_match;
use values::{Kind, from_python, relative_ior, to_python};

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
        let value = from_python(key, &parameter.kind, value)?;
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
