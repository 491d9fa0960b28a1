//! The parsed form of a Mitsuba XML scene: a tree of plugins with typed properties.
//!
//! The XML reader ([`super::reader`]) produces this tree with every `$name` substituted, every
//! `<include>` spliced in, every `<ref>` resolved to the node it names and every transform composed;
//! each value keeps the file, line and column it came from. The scene builder then turns the tree
//! into renderable objects, reading properties through [`super::params::Params`], which reports
//! unknown, misspelled and wrongly typed parameters.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DMat4, DVec3};

use crate::element::quote;
use crate::file_cache;
use prism_core::error::{Error, Result, SourceLocation};

/// The kind of object an XML element declares; the element's tag name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PluginClass {
    Scene,
    Integrator,
    Sensor,
    Film,
    Rfilter,
    Sampler,
    Shape,
    Bsdf,
    Emitter,
    Texture,
    Spectrum,
    Medium,
    Phase,
    Volume,
}

impl PluginClass {
    pub const ALL: [PluginClass; 14] = [
        PluginClass::Scene,
        PluginClass::Integrator,
        PluginClass::Sensor,
        PluginClass::Film,
        PluginClass::Rfilter,
        PluginClass::Sampler,
        PluginClass::Shape,
        PluginClass::Bsdf,
        PluginClass::Emitter,
        PluginClass::Texture,
        PluginClass::Spectrum,
        PluginClass::Medium,
        PluginClass::Phase,
        PluginClass::Volume,
    ];

    /// The XML tag of this class.
    pub const fn tag(self) -> &'static str {
        match self {
            PluginClass::Scene => "scene",
            PluginClass::Integrator => "integrator",
            PluginClass::Sensor => "sensor",
            PluginClass::Film => "film",
            PluginClass::Rfilter => "rfilter",
            PluginClass::Sampler => "sampler",
            PluginClass::Shape => "shape",
            PluginClass::Bsdf => "bsdf",
            PluginClass::Emitter => "emitter",
            PluginClass::Texture => "texture",
            PluginClass::Spectrum => "spectrum",
            PluginClass::Medium => "medium",
            PluginClass::Phase => "phase",
            PluginClass::Volume => "volume",
        }
    }

    /// The class declared by an XML tag, if the tag declares a plugin.
    pub fn from_tag(tag: &str) -> Option<PluginClass> {
        PluginClass::ALL
            .into_iter()
            .find(|class| class.tag() == tag)
    }
}

/// Something in the scene file that Prism reads but renders otherwise than its words or another
/// renderer suggest (a Mitsuba 0.6 parameter it ignores, a `<rotate>` about an axis not of unit
/// length, ...): where it is written and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Warning {
    pub location: SourceLocation,
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: warning: {}", self.location, self.message)
    }
}

/// One plugin instance: `<bsdf type="diffuse" id="white"> ... </bsdf>`.
#[derive(Clone, Debug)]
pub struct PluginNode {
    pub class: PluginClass,
    /// The `type` attribute (`"scene"` for the root).
    pub plugin_type: String,
    /// The `id` attribute, if the element has one.
    pub id: Option<String>,
    /// Where the element starts.
    pub location: SourceLocation,
    /// Properties in document order; names are unique within a plugin.
    pub properties: Vec<Property>,
    /// Nested plugins and resolved references, in document order.
    pub children: Vec<NestedPlugin>,
    /// Folders searched, in order, for the files this plugin names (`<path>` entries first, then
    /// the folder of the file that holds the element, then the folder of the main scene file).
    pub search_paths: Arc<Vec<PathBuf>>,
}

/// A plugin nested in another, either written inline or as a `<ref id="..."/>`.
#[derive(Clone, Debug)]
pub struct NestedPlugin {
    /// The `name` attribute, if given (`<bsdf name="bsdf_0" ...>`); Mitsuba ignores it for most
    /// parents but some plugins (e.g. `blendbsdf`, textures on parameters) use it.
    pub name: Option<String>,
    pub node: Arc<PluginNode>,
    /// Where the nesting element (the inline element or the `<ref>`) starts.
    pub location: SourceLocation,
}

/// A named property: `<float name="fov" value="45"/>`.
#[derive(Clone, Debug)]
pub struct Property {
    pub name: String,
    pub value: PropertyValue,
    pub location: SourceLocation,
}

/// The value of a property, typed by its XML tag.
#[derive(Clone, Debug, PartialEq)]
pub enum PropertyValue {
    Float(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// `<rgb value="r, g, b"/>` (a single value `v` means `v, v, v`).
    Rgb([f64; 3]),
    Spectrum(SpectrumValue),
    Point(DVec3),
    Vector(DVec3),
    /// A `<transform>` with its operations composed in document order (each new operation is
    /// applied after the previous ones, i.e. left-multiplied).
    Transform(DMat4),
    /// An `<animation>`: (time, transform) keys in strictly increasing time, each invertible.
    Animation(Vec<(f64, DMat4)>),
    /// A list of numbers, which XML cannot write: the arrays of a mesh given inline (the pbrt-v4
    /// reader's `trianglemesh`).
    Numbers(Vec<f64>),
    /// An array of numbers of any number of dimensions, which XML cannot write either: a
    /// scene dictionary's nested lists or numpy array (Mitsuba's tensor parameters). `values`
    /// holds them with the last index fastest; `shape` has at least one dimension.
    Tensor {
        shape: Vec<usize>,
        values: Vec<f64>,
    },
}

impl PropertyValue {
    /// The XML tag that produces this kind of value, for messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            PropertyValue::Float(_) => "float",
            PropertyValue::Integer(_) => "integer",
            PropertyValue::Boolean(_) => "boolean",
            PropertyValue::String(_) => "string",
            PropertyValue::Rgb(_) => "rgb",
            PropertyValue::Spectrum(_) => "spectrum",
            PropertyValue::Point(_) => "point",
            PropertyValue::Vector(_) => "vector",
            PropertyValue::Transform(_) => "transform",
            PropertyValue::Animation(_) => "animation",
            PropertyValue::Numbers(_) => "list of numbers",
            PropertyValue::Tensor { .. } => "tensor",
        }
    }
}

/// The value of a `<spectrum>` property.
#[derive(Clone, Debug, PartialEq)]
pub enum SpectrumValue {
    /// `<spectrum value="0.5"/>`: the same value at every wavelength.
    Uniform(f64),
    /// `<spectrum value="400:0.1, 500:0.4, ..."/>` or a file of `wavelength value` lines:
    /// (wavelength in nm, value) pairs with strictly increasing wavelengths, interpolated
    /// linearly and zero outside their range (as Mitsuba 3 does).
    Samples(Vec<(f64, f64)>),
}

impl PluginNode {
    /// A short description for messages: `bsdf "diffuse"` or `bsdf "diffuse" (id "white")`.
    pub fn describe(&self) -> String {
        match &self.id {
            Some(id) => format!(
                "{} \"{}\" (id \"{id}\")",
                self.class.tag(),
                self.plugin_type
            ),
            None => format!("{} \"{}\"", self.class.tag(), self.plugin_type),
        }
    }

    /// Finds a file named by this plugin (see [`find_file`]).
    pub fn resolve_file(&self, name: &str, location: &SourceLocation) -> Result<PathBuf> {
        find_file(name, &self.search_paths, location)
    }
}

/// Finds the file `name`: an absolute path as it is, a relative one in `dirs`, in order (a file
/// the [`file_cache`] in scope holds is found even if it no longer exists); the error, at
/// `location`, says where it looked.
pub fn find_file(name: &str, dirs: &[PathBuf], location: &SourceLocation) -> Result<PathBuf> {
    let path = Path::new(name);
    let exists = |path: &Path| path.exists() || file_cache::holds(path);
    if path.is_absolute() {
        if exists(path) {
            return Ok(path.to_path_buf());
        }
    } else if let Some(found) = dirs.iter().map(|dir| dir.join(path)).find(|p| exists(p)) {
        return Ok(found);
    }
    let searched: Vec<String> = dirs
        .iter()
        .map(|dir| format!("\"{}\"", dir.display()))
        .collect();
    Err(
        Error::input(location, format!("file \"{}\" not found", quote(name))).with_help(format!(
            "check the file name; relative names are looked up in {}",
            if searched.is_empty() {
                "the current folder".to_string()
            } else {
                searched.join(", ")
            }
        )),
    )
}
