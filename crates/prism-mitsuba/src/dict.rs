//! Mitsuba 3's dictionary form of a scene (`mitsuba.load_dict`), read into the same tree of
//! plugins ([`PluginNode`]) the XML reader builds, so that the factory checks it with the same
//! rules and messages.
//!
//! A dictionary is a plugin: its `"type"` entry names the plugin (the root's is `"scene"`), an
//! `"id"` entry names it for references, and every other entry is a parameter or a nested
//! plugin:
//!
//! * a boolean, integer, float or string is a property of that type;
//! * three numbers are a point (which every vector parameter accepts too, as in Mitsuba);
//! * any other list of numbers, or nested lists of numbers of a rectangular shape (a numpy
//!   array's `tolist()`), is a tensor (Mitsuba's `TensorXf` parameters, such as `sdfgrid`'s
//!   `grid`);
//! * a 4 × 4 matrix (row-major, acting on column vectors) is a transform;
//! * `{"type": "rgb", "value": v}` is an RGB colour, with `v` one number or three;
//! * `{"type": "spectrum", "value": v}` is a spectrum, with `v` one number or a list of
//!   (wavelength, value) pairs, or `{"type": "spectrum", "filename": "data.spd"}`;
//! * `{"type": "ref", "id": "name"}` refers to a plugin declared earlier;
//! * any other dictionary is a nested plugin, whose class (BSDF, shape, ...) its type decides.
//!
//! As in Mitsuba, a plugin nested directly in the scene without an `"id"` can be referred to
//! by its key. Where an XML reader's message names a file, line and column, ours names the
//! entry's key path, such as `scene.sphere.bsdf.reflectance`
//! ([`SourceLocation::key_path`]). Relative file names are looked up in the current folder.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use glam::{DMat4, DVec3};

use crate::description::{NestedPlugin, PluginClass, PluginNode, Property, PropertyValue};
use crate::element::{Attribute, Element, quote};
use crate::property_values;
use crate::reference::reference;
use crate::suggest::closest_match;
use prism_core::error::{Error, Result, SourceLocation};

/// A value in a scene dictionary.
#[derive(Clone, Debug, PartialEq)]
pub enum DictValue {
    Boolean(bool),
    Integer(i64),
    Float(f64),
    String(String),
    /// A list or tuple (of numbers, or of pairs for a spectrum's samples).
    List(Vec<DictValue>),
    /// A 4 × 4 matrix, row-major: `matrix[row][column]`.
    Matrix([[f64; 4]; 4]),
    Dict(Dict),
}

/// A dictionary: its entries in order, keys unique.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dict {
    pub entries: Vec<(String, DictValue)>,
}

impl Dict {
    /// The value at `key`.
    pub fn get(&self, key: &str) -> Option<&DictValue> {
        self.entries.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }
}

impl DictValue {
    /// What kind of value this is, for messages.
    fn kind(&self) -> &'static str {
        match self {
            DictValue::Boolean(_) => "a boolean",
            DictValue::Integer(_) => "an integer",
            DictValue::Float(_) => "a float",
            DictValue::String(_) => "a string",
            DictValue::List(_) => "a list",
            DictValue::Matrix(_) => "a 4×4 matrix",
            DictValue::Dict(_) => "a dictionary",
        }
    }

    /// The number this is, if it is one.
    fn number(&self) -> Option<f64> {
        match *self {
            DictValue::Integer(v) => Some(v as f64),
            DictValue::Float(v) => Some(v),
            _ => None,
        }
    }
}

/// Reads a scene dictionary (its `"type"` must be `"scene"`) into the tree of plugins.
pub fn read_scene_dict(root: &Dict) -> Result<Arc<PluginNode>> {
    let mut reader = DictReader {
        ids: HashMap::new(),
        search_paths: Arc::new(vec![PathBuf::from(".")]),
    };
    let location = SourceLocation::key_path("scene");
    match root.get("type") {
        Some(DictValue::String(t)) if t == "scene" => {}
        Some(DictValue::String(t)) => {
            return Err(Error::input(
                &location,
                format!(
                    "the root dictionary has type \"{}\", not \"scene\"",
                    quote(t)
                ),
            )
            .with_help("a scene dictionary starts with {\"type\": \"scene\", ...}"));
        }
        _ => return Err(missing_type(&location)),
    }
    reader.plugin(root, "scene", PluginClass::Scene, "scene")
}

/// Reads plugins, remembering those with an id.
struct DictReader {
    ids: HashMap<String, (Arc<PluginNode>, SourceLocation)>,
    search_paths: Arc<Vec<PathBuf>>,
}

impl DictReader {
    /// The plugin of class `class` and type `plugin_type` that `dict` at `path` describes.
    fn plugin(
        &mut self,
        dict: &Dict,
        path: &str,
        class: PluginClass,
        plugin_type: &str,
    ) -> Result<Arc<PluginNode>> {
        let location = SourceLocation::key_path(path);
        let id = match dict.get("id") {
            None => None,
            Some(DictValue::String(id)) if !id.is_empty() => Some(id.clone()),
            Some(other) => {
                return Err(Error::input(
                    &SourceLocation::key_path(&format!("{path}.id")),
                    format!("the id is {}, not a name", other.kind()),
                )
                .with_help("give the object a name, for example \"id\": \"floor\""));
            }
        };
        let mut properties = Vec::new();
        let mut children = Vec::new();
        for (key, value) in &dict.entries {
            if key == "type" || key == "id" {
                continue;
            }
            let key_path = format!("{path}.{key}");
            let entry_location = SourceLocation::key_path(&key_path);
            if key.is_empty() {
                return Err(Error::input(&entry_location, "empty key")
                    .with_help("give the parameter a name, for example \"reflectance\""));
            }
            let property = |value| Property {
                name: key.clone(),
                value,
                location: entry_location.clone(),
            };
            match value {
                DictValue::Dict(nested) => match self.nested(nested, &key_path, key)? {
                    Nested::Property(value) => properties.push(property(value)),
                    Nested::Plugin(node) => children.push(NestedPlugin {
                        name: Some(key.clone()),
                        node,
                        location: entry_location,
                    }),
                },
                other => properties.push(property(plain_value(other, &entry_location)?)),
            }
        }
        let node = Arc::new(PluginNode {
            class,
            plugin_type: plugin_type.to_string(),
            id: id.clone(),
            location: location.clone(),
            properties,
            children,
            search_paths: self.search_paths.clone(),
        });
        if let Some(id) = id {
            self.declare(&id, &node, &location)?;
        }
        Ok(node)
    }

    /// A nested dictionary: a property (`rgb`, `spectrum`), a reference or a plugin.
    fn nested(&mut self, dict: &Dict, path: &str, key: &str) -> Result<Nested> {
        let location = SourceLocation::key_path(path);
        let Some(DictValue::String(plugin_type)) = dict.get("type") else {
            return Err(missing_type(&location));
        };
        match plugin_type.as_str() {
            "rgb" | "spectrum" => self.colour(dict, path, key, plugin_type),
            "ref" => self.reference(dict, path),
            _ => {
                let class = class_of(plugin_type, &location)?;
                let node = self.plugin(dict, path, class, plugin_type)?;
                // A plugin nested in the scene can be referred to by its key.
                if node.id.is_none() && path.matches('.').count() == 1 {
                    self.declare(key, &node, &location)?;
                }
                Ok(Nested::Plugin(node))
            }
        }
    }

    /// `{"type": "rgb", "value": ...}` or `{"type": "spectrum", ...}`, read by the XML reader's
    /// rules for `<rgb>` and `<spectrum>`.
    fn colour(&self, dict: &Dict, path: &str, key: &str, tag: &str) -> Result<Nested> {
        let location = SourceLocation::key_path(path);
        let allowed: &[&str] = if tag == "rgb" {
            &["type", "value"]
        } else {
            &["type", "value", "filename"]
        };
        let mut attributes = vec![Attribute {
            name: "name".to_string(),
            value: key.to_string(),
            location: location.clone(),
        }];
        for (entry, value) in &dict.entries {
            let entry_location = SourceLocation::key_path(&format!("{path}.{entry}"));
            if !allowed.contains(&entry.as_str()) {
                let mut help = format!("{{\"type\": \"{tag}\"}} takes {}", allowed.join(", "));
                if let Some(close) = closest_match(entry, allowed) {
                    help = format!("did you mean \"{close}\"? {help}");
                }
                return Err(Error::input(
                    &entry_location,
                    format!("unexpected entry \"{}\" in an {tag} value", quote(entry)),
                )
                .with_help(help));
            }
            if entry == "type" {
                continue;
            }
            attributes.push(Attribute {
                name: entry.clone(),
                value: attribute_text(value, &entry_location)?,
                location: entry_location,
            });
        }
        let element = Element {
            tag: tag.to_string(),
            location,
            attributes,
        };
        Ok(Nested::Property(if tag == "rgb" {
            PropertyValue::Rgb(property_values::rgb(&element)?)
        } else {
            property_values::spectrum(&element, &self.search_paths)?
        }))
    }

    /// `{"type": "ref", "id": "name"}`: the plugin declared earlier under that id.
    fn reference(&self, dict: &Dict, path: &str) -> Result<Nested> {
        let location = SourceLocation::key_path(path);
        if let Some((key, _)) = dict.entries.iter().find(|(k, _)| k != "type" && k != "id") {
            return Err(Error::input(
                &SourceLocation::key_path(&format!("{path}.{key}")),
                format!("unexpected entry \"{}\" in a reference", quote(key)),
            )
            .with_help("a reference is {\"type\": \"ref\", \"id\": \"...\"}"));
        }
        let Some(DictValue::String(id)) = dict.get("id") else {
            return Err(Error::input(&location, "the reference has no \"id\"")
                .with_help("write {\"type\": \"ref\", \"id\": \"...\"}"));
        };
        match self.ids.get(id) {
            Some((node, _)) => Ok(Nested::Plugin(node.clone())),
            None => {
                let known: Vec<&str> = self.ids.keys().map(String::as_str).collect();
                let mut help =
                    "declare the object (with this id, or under this key in the scene) before \
                     the entries that refer to it"
                        .to_string();
                if let Some(close) = closest_match(id, &known) {
                    help = format!("did you mean \"{close}\"? {help}");
                }
                Err(Error::input(
                    &location,
                    format!("reference to unknown id \"{}\"", quote(id)),
                )
                .with_help(help))
            }
        }
    }

    /// Registers `node` under `id`; a second object with the same id is an error.
    fn declare(
        &mut self,
        id: &str,
        node: &Arc<PluginNode>,
        location: &SourceLocation,
    ) -> Result<()> {
        if let Some((_, previous)) = self.ids.get(id) {
            return Err(Error::input(
                location,
                format!(
                    "duplicate id \"{}\" (first declared at {previous})",
                    quote(id)
                ),
            )
            .with_help("ids must be unique in the whole scene; rename one"));
        }
        self.ids
            .insert(id.to_string(), (node.clone(), location.clone()));
        Ok(())
    }
}

/// What a nested dictionary turned out to be.
enum Nested {
    Property(PropertyValue),
    Plugin(Arc<PluginNode>),
}

fn missing_type(location: &SourceLocation) -> Error {
    Error::input(location, "the dictionary has no \"type\"").with_help(
        "name the plugin, for example {\"type\": \"diffuse\", ...}, or write a colour as \
         {\"type\": \"rgb\", \"value\": [r, g, b]}",
    )
}

/// The class of the plugin called `plugin_type`; an unknown name is an error listing the
/// known ones.
fn class_of(plugin_type: &str, location: &SourceLocation) -> Result<PluginClass> {
    let classes = reference();
    if let Some(class) = classes
        .iter()
        .find(|c| c.plugins.iter().any(|p| p.name == plugin_type))
    {
        return Ok(class.class);
    }
    let mut names: Vec<&str> = classes
        .iter()
        .flat_map(|c| c.plugins.iter().map(|p| p.name))
        .chain(["rgb", "spectrum", "ref"])
        .collect();
    names.sort_unstable();
    names.dedup();
    let mut help = format!("supported types: {}", names.join(", "));
    if let Some(close) = closest_match(plugin_type, &names) {
        help = format!("did you mean \"{close}\"? {help}");
    }
    Err(Error::input(
        location,
        format!("unknown plugin type \"{}\"", quote(plugin_type)),
    )
    .with_help(help))
}

/// The property a value other than a dictionary gives.
fn plain_value(value: &DictValue, location: &SourceLocation) -> Result<PropertyValue> {
    Ok(match value {
        DictValue::Boolean(v) => PropertyValue::Boolean(*v),
        DictValue::Integer(v) => PropertyValue::Integer(*v),
        DictValue::Float(v) => {
            if !v.is_finite() {
                return Err(
                    Error::input(location, format!("{v} is not a finite number"))
                        .with_help("give a finite number"),
                );
            }
            PropertyValue::Float(*v)
        }
        DictValue::String(v) => PropertyValue::String(v.clone()),
        DictValue::Matrix(rows) => {
            let matrix = DMat4::from_cols_array_2d(rows).transpose();
            if !matrix.is_finite() {
                return Err(
                    Error::input(location, "the matrix has entries that are not finite")
                        .with_help("give a transform of finite numbers"),
                );
            }
            PropertyValue::Transform(matrix)
        }
        DictValue::List(items) => {
            let numbers: Option<Vec<f64>> = items.iter().map(DictValue::number).collect();
            match (numbers.as_deref(), tensor_of(value)) {
                (Some(&[x, y, z]), _) if x.is_finite() && y.is_finite() && z.is_finite() => {
                    PropertyValue::Point(DVec3::new(x, y, z))
                }
                (_, Some((shape, values))) => {
                    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
                        return Err(Error::input(
                            location,
                            format!("the tensor holds {v}, which is not a finite number"),
                        )
                        .with_help("give finite numbers"));
                    }
                    PropertyValue::Tensor { shape, values }
                }
                _ => {
                    return Err(Error::input(
                        location,
                        format!(
                            "a list of {} entries is not a value Prism reads",
                            items.len()
                        ),
                    )
                    .with_help(
                        "give a point or vector as three finite numbers, a transform as a 4×4 \
                         matrix, a colour as {\"type\": \"rgb\", \"value\": [r, g, b]}",
                    ));
                }
            }
        }
        DictValue::Dict(_) => unreachable!("nested dictionaries are read as plugins"),
    })
}

/// The shape and values (last index fastest) of `value`, (nested) lists of numbers whose
/// lists at each depth all have the same length (a 4 × 4 block of them may have been read as a
/// matrix); None for anything else, and for empty lists.
fn tensor_of(value: &DictValue) -> Option<(Vec<usize>, Vec<f64>)> {
    let mut shape = Vec::new();
    let mut level = value;
    loop {
        match level {
            DictValue::List(items) => {
                shape.push(items.len());
                level = items.first()?;
            }
            DictValue::Matrix(_) => {
                shape.extend([4, 4]);
                break;
            }
            _ => break,
        }
    }
    if shape.is_empty() {
        return None;
    }
    let mut values = Vec::new();
    gather(value, &shape, &mut values).then_some((shape, values))
}

/// Appends the numbers of `value`, which must have the shape `shape`; false where it does not.
fn gather(value: &DictValue, shape: &[usize], values: &mut Vec<f64>) -> bool {
    match (value, shape.split_first()) {
        (DictValue::List(items), Some((&length, inner))) => {
            items.len() == length && items.iter().all(|item| gather(item, inner, values))
        }
        (DictValue::Matrix(rows), Some((4, [4]))) => {
            values.extend(rows.iter().flatten());
            true
        }
        (_, None) => value.number().map(|v| values.push(v)).is_some(),
        _ => false,
    }
}

/// A value of an `rgb` or `spectrum` dictionary written as the XML attribute it stands for:
/// numbers as they are (Rust prints a float so that it reads back exactly), a list of numbers
/// separated by commas, a list of (wavelength, value) pairs as `wavelength:value` entries.
fn attribute_text(value: &DictValue, location: &SourceLocation) -> Result<String> {
    let invalid = || {
        Error::input(
            location,
            format!("{} is not a colour or spectrum value", value.kind()),
        )
        .with_help(
            "give one number, three numbers [r, g, b], a list of (wavelength, value) pairs or a \
             file name",
        )
    };
    match value {
        DictValue::String(text) => Ok(text.clone()),
        DictValue::Integer(_) | DictValue::Float(_) => Ok(number_text(value).ok_or_else(invalid)?),
        DictValue::List(items) => {
            let entries: Option<Vec<String>> = items
                .iter()
                .map(|item| match item {
                    DictValue::List(pair) => match pair.as_slice() {
                        [wavelength, value] => Some(format!(
                            "{}:{}",
                            number_text(wavelength)?,
                            number_text(value)?
                        )),
                        _ => None,
                    },
                    number => number_text(number),
                })
                .collect();
            Ok(entries.ok_or_else(invalid)?.join(", "))
        }
        _ => Err(invalid()),
    }
}

/// A number as text that reads back exactly; None for anything else.
fn number_text(value: &DictValue) -> Option<String> {
    match value {
        DictValue::Integer(v) => Some(v.to_string()),
        DictValue::Float(v) => Some(v.to_string()),
        _ => None,
    }
}

/// The transforms of a dictionary's `to_world`, built by the operations of the XML reader's
/// `<transform>` (Mitsuba's `ScalarTransform4f`); matrices act on column vectors.
pub mod transform {
    use glam::{DMat4, DVec3};

    /// `<translate>`: the translation by `offset`.
    pub fn translate(offset: DVec3) -> DMat4 {
        crate::transform_ops::translation(offset)
    }

    /// `<scale>`: the scaling by `factors` along x, y and z.
    pub fn scale(factors: DVec3) -> DMat4 {
        crate::transform_ops::scaling(factors)
    }

    /// `<rotate>` of a Mitsuba 3 scene: by `angle` degrees about `axis` as given (right-handed
    /// for a unit axis; a longer or shorter one also stretches and shears, as in Mitsuba 3); the
    /// error names the problem with the axis.
    pub fn rotate(axis: DVec3, angle: f64) -> Result<DMat4, &'static str> {
        crate::transform_ops::rotation(axis, angle)
    }

    /// `<lookat>`: the camera-to-world matrix looking from `origin` to `target` with `up`
    /// (zero: any direction perpendicular to the view); the error names the problem.
    pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Result<DMat4, &'static str> {
        crate::transform_ops::look_at(origin, target, up)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::factory::build_scene;
    use crate::reader::read_scene_str;
    use std::path::Path;

    fn dict(entries: Vec<(&str, DictValue)>) -> DictValue {
        DictValue::Dict(Dict {
            entries: entries
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
        })
    }

    fn text(v: &str) -> DictValue {
        DictValue::String(v.to_string())
    }

    fn numbers(values: &[f64]) -> DictValue {
        DictValue::List(values.iter().map(|&v| DictValue::Float(v)).collect())
    }

    fn scene(entries: Vec<(&str, DictValue)>) -> Dict {
        let mut all = vec![("type", text("scene"))];
        all.extend(entries);
        let DictValue::Dict(d) = dict(all) else {
            unreachable!()
        };
        d
    }

    fn sensor() -> DictValue {
        dict(vec![
            ("type", text("perspective")),
            ("fov", DictValue::Integer(40)),
            (
                "film",
                dict(vec![
                    ("type", text("hdrfilm")),
                    ("width", DictValue::Integer(8)),
                    ("height", DictValue::Integer(6)),
                ]),
            ),
        ])
    }

    #[test]
    fn every_plugin_name_names_one_class() {
        let classes = reference();
        let mut seen: HashMap<&str, PluginClass> = HashMap::new();
        for class in &classes {
            for plugin in &class.plugins {
                if let Some(other) = seen.insert(plugin.name, class.class) {
                    panic!(
                        "\"{}\" is both a {} and a {}",
                        plugin.name,
                        other.tag(),
                        class.class.tag()
                    );
                }
            }
        }
        for special in ["rgb", "spectrum", "ref"] {
            assert!(!seen.contains_key(special), "{special} is a plugin name");
        }
    }

    #[test]
    fn a_dictionary_gives_the_tree_its_xml_gives() {
        let xml = r#"<scene version="3.0.0">
            <sensor type="perspective"><float name="fov" value="40"/>
                <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/></film>
            </sensor>
            <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.2, 0.5, 0.7"/></bsdf>
            <shape type="sphere"><point name="center" value="0, 1, 2"/><float name="radius" value="0.5"/><ref id="white"/></shape>
            <emitter type="constant"/>
        </scene>"#;
        let from_xml = read_scene_str(xml, Path::new("scene.xml"), &[]).unwrap();
        let from_dict = read_scene_dict(&scene(vec![
            ("sensor", sensor()),
            (
                "white",
                dict(vec![
                    ("type", text("diffuse")),
                    (
                        "reflectance",
                        dict(vec![
                            ("type", text("rgb")),
                            ("value", numbers(&[0.2, 0.5, 0.7])),
                        ]),
                    ),
                ]),
            ),
            (
                "ball",
                dict(vec![
                    ("type", text("sphere")),
                    ("center", numbers(&[0.0, 1.0, 2.0])),
                    ("radius", DictValue::Float(0.5)),
                    (
                        "bsdf",
                        dict(vec![("type", text("ref")), ("id", text("white"))]),
                    ),
                ]),
            ),
            ("sky", dict(vec![("type", text("constant"))])),
        ]))
        .unwrap();
        let a = build_scene(&from_xml).unwrap().scene;
        let b = build_scene(&from_dict).unwrap().scene;
        assert_eq!(a.film.size, b.film.size);
        assert_eq!(
            format!("{:?}", a.world.materials),
            format!("{:?}", b.world.materials)
        );
        let options = prism_core::render::RenderOptions::fixed(4, 1, Some(1));
        let image_a = prism_core::render::render(&a, &options).unwrap().film;
        let image_b = prism_core::render::render(&b, &options).unwrap().film;
        assert_eq!(image_a.xyz(), image_b.xyz());
        assert!(image_a.xyz().iter().any(|p| p[1] > 0.0));
        let shape = &from_dict.children[2];
        assert_eq!(
            shape.node.properties[0].value,
            PropertyValue::Point(DVec3::new(0.0, 1.0, 2.0))
        );
        assert!(Arc::ptr_eq(
            &shape.node.children[0].node,
            &from_dict.children[1].node
        ));
    }

    #[test]
    fn spectra_and_transforms_read_as_in_xml() {
        let mut rows = [[0.0; 4]; 4];
        for (i, row) in rows.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        rows[0][3] = 5.0;
        let root = scene(vec![(
            "thing",
            dict(vec![
                ("type", text("diffuse")),
                (
                    "reflectance",
                    dict(vec![
                        ("type", text("spectrum")),
                        (
                            "value",
                            DictValue::List(vec![numbers(&[400.0, 0.1]), numbers(&[700.0, 0.3])]),
                        ),
                    ]),
                ),
                ("to_world", DictValue::Matrix(rows)),
            ]),
        )]);
        let node = read_scene_dict(&root).unwrap();
        let bsdf = &node.children[0].node;
        assert_eq!(
            bsdf.properties[0].value,
            PropertyValue::Spectrum(crate::description::SpectrumValue::Samples(vec![
                (400.0, 0.1),
                (700.0, 0.3)
            ]))
        );
        assert_eq!(
            bsdf.properties[1].value,
            PropertyValue::Transform(DMat4::from_translation(DVec3::new(5.0, 0.0, 0.0)))
        );
    }

    fn error_of(root: Dict) -> Error {
        match read_scene_dict(&root).and_then(|node| build_scene(&node).map(|_| ())) {
            Ok(()) => panic!("expected an error"),
            Err(e) => e,
        }
    }

    #[test]
    fn errors_name_the_key_path() {
        let misspelled = error_of(scene(vec![
            ("sensor", sensor()),
            (
                "sphere",
                dict(vec![
                    ("type", text("sphere")),
                    (
                        "bsdf",
                        dict(vec![
                            ("type", text("diffuse")),
                            ("reflectanse", DictValue::Float(0.5)),
                        ]),
                    ),
                ]),
            ),
        ]));
        let location = misspelled.location.clone().unwrap();
        assert!(location.is_key_path());
        assert_eq!(location.to_string(), "scene.sphere.bsdf.reflectanse");
        assert!(
            misspelled
                .to_string()
                .contains("did you mean \"reflectance\""),
            "{misspelled}"
        );

        let unknown = error_of(scene(vec![("x", dict(vec![("type", text("difuse"))]))]));
        assert_eq!(unknown.location.clone().unwrap().to_string(), "scene.x");
        assert!(
            unknown.to_string().contains("did you mean \"diffuse\""),
            "{unknown}"
        );

        let dangling = error_of(scene(vec![(
            "s",
            dict(vec![
                ("type", text("sphere")),
                (
                    "bsdf",
                    dict(vec![("type", text("ref")), ("id", text("nothing"))]),
                ),
            ]),
        )]));
        assert_eq!(dangling.location.unwrap().to_string(), "scene.s.bsdf");

        let bad_rgb = error_of(scene(vec![(
            "b",
            dict(vec![
                ("type", text("diffuse")),
                (
                    "reflectance",
                    dict(vec![("type", text("rgb")), ("value", numbers(&[0.1, 0.2]))]),
                ),
            ]),
        )]));
        assert_eq!(
            bad_rgb.location.unwrap().to_string(),
            "scene.b.reflectance.value"
        );
        assert!(
            bad_rgb.message.contains("has 2 numbers"),
            "{}",
            bad_rgb.message
        );

        let list = error_of(scene(vec![(
            "s",
            dict(vec![
                ("type", text("sphere")),
                ("center", numbers(&[1.0, 2.0])),
            ]),
        )]));
        assert_eq!(list.location.unwrap().to_string(), "scene.s.center");

        let root = error_of(Dict {
            entries: vec![("type".to_string(), text("sphere"))],
        });
        assert!(root.message.contains("not \"scene\""), "{}", root.message);
    }
}
