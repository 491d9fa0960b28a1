//! Reads Mitsuba 3 XML scene files into the tree of [`super::description`].
//!
//! Mitsuba 3's own reader (`src/core/xml.cpp`, since 3.7 `src/core/parser.cpp`) is the reference
//! for what a scene means; this module follows it and says where it differs. Reading has two
//! passes:
//!
//! 1. The document walk turns elements into *drafts* (plugins whose nested references are still
//!    ids), in document order. On the way it substitutes `$name` parameters in every attribute
//!    (`substitution.rs`), splices `<include>`d files in place, upgrades files older than
//!    version 2.0.0, records `<path>` folders and checks every element and attribute.
//! 2. Resolution turns drafts into `Arc<PluginNode>`s, children first. A `<ref id="x"/>` becomes
//!    the very node that declares `id="x"` (wherever it is in the scene, before or after the
//!    reference, as in Mitsuba); a reference that would make a plugin contain itself is an error.
//!
//! The rules, element by element:
//! - The root is `<scene version="major.minor.patch">` (an optional `id` is allowed).
//! - Plugins: `<bsdf type="..." id="..." name="...">` and the other tags of [`PluginClass`];
//!   `<spectrum>` is a plugin only with a `type` attribute, otherwise a property.
//! - Properties: `<float>`, `<integer>`, `<boolean>`, `<string>`, `<rgb>`, `<srgb>` (Mitsuba
//!   0.6), `<spectrum>`,
//!   `<point>`, `<vector>` and `<transform>` (see `transform_ops.rs`), each with a `name`
//!   unique within its plugin (nested plugins' names included).
//! - `<ref id="..." name="..."/>`, `<default name="..." value="..."/>`, `<alias id="..." as="..."/>`
//!   (a second id for an object declared earlier), `<include filename="..."/>` and
//!   `<path value="..."/>` (only directly inside the root `<scene>`).
//! - Text other than whitespace, unknown elements and unknown attributes are errors.
//! - Comments may contain `--` and end in `-`, as in Mitsuba (`comments.rs`).
//!
//! Files older than 2.0.0 are upgraded as Mitsuba 3 does: parameter names go from camelCase to
//! snake_case (`camel_to_snake`), `<lookAt>` becomes `<lookat>`, a diffuse BSDF's
//! `diffuse_reflectance` becomes `reflectance`, and `<float>`s named `uoffset`, `voffset`,
//! `uscale`, `vscale` become a `to_uv` transform (translate, then scale). Each file is upgraded
//! according to its own version, and names are renamed after `$name` substitution.
//!
//! Included files: `filename` is looked up relative to the including file's folder, then in the
//! search paths. The included file's root must be a `<scene>` (its `version` is optional and
//! defaults to the current one); its children are read as if written in place of the
//! `<include>`. Mitsuba also accepts a single plugin as the root of an included file; we do not.
//! Includes nest at most [`MAX_INCLUDE_DEPTH`] deep, Mitsuba's limit.
//!
//! Search paths: every node gets the `<path>` folders seen so far (latest first), then the folder
//! of the file that holds its element, then the folder of the main scene file. (Mitsuba applies
//! every `<path>` to all plugins, since it resolves files after parsing; here a `<path>` applies
//! to the plugins after it, which is what a reader of the file expects.)
//!
//! Robustness: the reader never panics. Elements nest at most [`MAX_NESTING`] deep, resolution
//! uses an explicit stack, and positions are computed from a line index (a scene of a million
//! elements costs a million binary searches, not a million scans).

mod comments;

use std::cell::Cell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DMat4, DVec3};
use roxmltree::{Node, NodeType};

use super::description::{
    NestedPlugin, PluginClass, PluginNode, Property, PropertyValue, Warning, find_file,
};
use super::element::{Attribute, Element, quote};
use super::property_values;
use super::substitution::{Parameters, camel_to_snake};
use super::transform_ops::{self, Dialect};
use crate::suggest::closest_match;
use comments::tolerate_hyphens_in_comments;
use prism_core::error::{Error, Result, SourceLocation};

/// Deepest nesting of elements accepted; deeper documents are certainly not scenes.
pub const MAX_NESTING: usize = 256;
/// Deepest nesting of `<include>`s (Mitsuba's `MI_XML_INCLUDE_MAX_RECURSION`).
pub const MAX_INCLUDE_DEPTH: usize = 15;

/// A scene file read: its root `<scene>`, and what the reader warns about in document order
/// (a `<rotate>` whose axis is not of unit length, ...: see `transform_ops.rs`).
pub struct SceneDocument {
    pub root: Arc<PluginNode>,
    pub warnings: Vec<Warning>,
}

/// Reads a scene file; `defines` are the command line's `-D name=value` overrides.
pub fn read_scene_file(path: &Path, defines: &[(String, String)]) -> Result<Arc<PluginNode>> {
    read_scene_document(path, defines).map(|document| document.root)
}

/// As [`read_scene_file`], with the reader's warnings.
pub fn read_scene_document(path: &Path, defines: &[(String, String)]) -> Result<SceneDocument> {
    read_scene_str_document(&scene_text(path)?, path, defines)
}

/// The text of the scene file at `path`, or the error a user sees for a missing one.
fn scene_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|err| {
        if err.kind() == std::io::ErrorKind::NotFound {
            Error::usage(format!("scene file \"{}\" not found", path.display()))
                .with_help("check the path of the scene file")
        } else {
            Error::io(path, &err, "read the scene file")
        }
    })
}

/// Same, from a string; `path` names the (possibly virtual) file for messages and relative lookups.
pub fn read_scene_str(
    text: &str,
    path: &Path,
    defines: &[(String, String)],
) -> Result<Arc<PluginNode>> {
    read_scene_str_document(text, path, defines).map(|document| document.root)
}

/// As [`read_scene_str`], with the reader's warnings.
pub fn read_scene_str_document(
    text: &str,
    path: &Path,
    defines: &[(String, String)],
) -> Result<SceneDocument> {
    let mut reader = Reader {
        parameters: Parameters::new(defines)?,
        drafts: Vec::new(),
        ids: HashMap::new(),
        main_dir: folder_of(path),
        path_dirs: Vec::new(),
        search_path_cache: HashMap::new(),
        warnings: Vec::new(),
    };
    reader.read_main(text, path)?;
    let root = resolve(std::mem::take(&mut reader.drafts), &reader.ids)?;
    reader.parameters.check_defines_used()?;
    Ok(SceneDocument {
        root,
        warnings: reader.warnings,
    })
}

/// The folder of `path`, or `.` for a bare file name.
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The draft of the root `<scene>`.
const ROOT: usize = 0;

/// A plugin read from the document whose nested references are not resolved yet.
struct Draft {
    class: PluginClass,
    plugin_type: String,
    id: Option<String>,
    location: SourceLocation,
    properties: Vec<Property>,
    children: Vec<DraftChild>,
    search_paths: Arc<Vec<PathBuf>>,
    /// Names of properties and named children, with where each is written, to report duplicates.
    names: HashMap<String, SourceLocation>,
    /// The texture coordinate floats of a version < 2.0.0 file (see [`LegacyUv`]).
    legacy_uv: LegacyUv,
}

impl Draft {
    /// As [`PluginNode::describe`].
    fn describe(&self) -> String {
        match &self.id {
            Some(id) => format!(
                "{} \"{}\" (id \"{}\")",
                self.class.tag(),
                quote(&self.plugin_type),
                quote(id)
            ),
            None => format!("{} \"{}\"", self.class.tag(), quote(&self.plugin_type)),
        }
    }
}

/// A nested plugin: inline (an index into the drafts) or a reference by id.
struct DraftChild {
    name: Option<String>,
    target: Target,
    location: SourceLocation,
}

enum Target {
    Inline(usize),
    Reference(String),
}

/// `<float name="uoffset|voffset|uscale|vscale">` of an old file, which Mitsuba 3 turns into the
/// transform `to_uv = scale(uscale, vscale, 1) * translate(uoffset, voffset, 0)`.
#[derive(Default)]
struct LegacyUv {
    /// In the order of [`LEGACY_UV_NAMES`].
    values: [Option<f64>; 4],
    /// Where the first of them is written.
    location: Option<SourceLocation>,
}

const LEGACY_UV_NAMES: [&str; 4] = ["uoffset", "voffset", "uscale", "vscale"];

/// Where an id is declared.
struct IdEntry {
    index: usize,
    location: SourceLocation,
}

/// One file being read.
struct Source<'t> {
    file: Arc<Path>,
    dir: PathBuf,
    text: &'t str,
    /// Byte offsets where lines start.
    line_starts: Vec<usize>,
    /// The file's version is older than 2.0.0.
    legacy: bool,
    /// 0 for the main file, 1 for a file it includes, and so on.
    include_depth: usize,
    /// The last (byte offset, 0-based column) computed. The walk asks for positions mostly in
    /// increasing order, so columns are counted on from there: a minified scene, all on one
    /// line, then costs linear rather than quadratic time.
    last_column: Cell<(usize, usize)>,
}

impl<'t> Source<'t> {
    fn new(path: &Path, text: &'t str, include_depth: usize) -> Self {
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(offset, _)| offset + 1))
            .collect();
        Source {
            file: Arc::from(path),
            dir: folder_of(path),
            text,
            line_starts,
            legacy: false,
            include_depth,
            last_column: Cell::new((0, 0)),
        }
    }

    /// The line and column (in characters) of a byte offset.
    fn location(&self, offset: usize) -> SourceLocation {
        let line = self.line_starts.partition_point(|&start| start <= offset);
        let start = line
            .checked_sub(1)
            .and_then(|index| self.line_starts.get(index))
            .copied()
            .unwrap_or(0);
        let (last_offset, last_column) = self.last_column.get();
        let (from, column_at_from) = if (start..=offset).contains(&last_offset) {
            (last_offset, last_column)
        } else {
            (start, 0)
        };
        let column = column_at_from
            + self
                .text
                .get(from..offset)
                .map_or(offset.saturating_sub(from), |s| s.chars().count());
        self.last_column.set((offset, column));
        SourceLocation {
            file: self.file.clone(),
            line: u32::try_from(line).unwrap_or(u32::MAX),
            column: u32::try_from(column + 1).unwrap_or(u32::MAX),
        }
    }
}

/// The state of the document walk (pass 1).
struct Reader {
    parameters: Parameters,
    drafts: Vec<Draft>,
    ids: HashMap<String, IdEntry>,
    main_dir: PathBuf,
    /// `<path>` folders, latest first.
    path_dirs: Vec<PathBuf>,
    /// Search paths by the folder of the file holding an element; cleared by `<path>`.
    search_path_cache: HashMap<PathBuf, Arc<Vec<PathBuf>>>,
    warnings: Vec<Warning>,
}

/// Parses XML; a syntax error is reported where the parser found it.
fn parse_xml<'t>(source: &Source<'t>) -> Result<roxmltree::Document<'t>> {
    roxmltree::Document::parse(source.text).map_err(|err| {
        let position = err.pos();
        let message = err.to_string().replace(&format!(" at {position}"), "");
        let location = SourceLocation {
            file: source.file.clone(),
            line: position.row,
            column: position.col,
        };
        Error::input(&location, format!("malformed XML: {message}"))
            .with_help("fix the XML syntax at this position")
    })
}

/// The version attribute as (major, minor, patch).
fn parse_version(attribute: &Attribute) -> Result<(u32, u32, u32)> {
    let parts: Vec<Option<u32>> = attribute
        .value
        .trim()
        .split('.')
        .map(|part| part.trim().parse().ok())
        .collect();
    match parts[..] {
        [Some(major), Some(minor), Some(patch)] => Ok((major, minor, patch)),
        _ => Err(Error::input(
            &attribute.location,
            format!("could not read the version \"{}\"", quote(&attribute.value)),
        )
        .with_help("write it as major.minor.patch, for example version=\"3.0.0\"")),
    }
}

impl Reader {
    /// Reads the main scene file into the root draft and everything below it.
    fn read_main(&mut self, text: &str, path: &Path) -> Result<()> {
        let text = tolerate_hyphens_in_comments(text);
        let mut source = Source::new(path, &text, 0);
        let document = parse_xml(&source)?;
        let root = document.root_element();
        let location = source.location(root.range().start);
        if root.tag_name().name() != "scene" || root.tag_name().namespace().is_some() {
            return Err(Error::input(
                &location,
                format!(
                    "the root element is <{}>, but a scene file must start with <scene>",
                    quote(root.tag_name().name())
                ),
            )
            .with_help("wrap the content in <scene version=\"3.0.0\"> ... </scene>"));
        }
        let element = self.element(&source, root, None)?;
        element.check_attributes(&["version", "id"])?;
        let version = element.get("version").ok_or_else(|| {
            Error::input(&location, "<scene> has no version attribute").with_help(
                "write <scene version=\"3.0.0\">; Mitsuba needs the version to upgrade old scenes",
            )
        })?;
        source.legacy = parse_version(version)? < (2, 0, 0);
        let id = match element.get("id") {
            Some(id) => Some(self.declare_id(id, ROOT)?),
            None => None,
        };
        let search_paths = self.search_paths(&source);
        self.drafts.push(Draft {
            class: PluginClass::Scene,
            plugin_type: "scene".to_string(),
            id,
            location,
            properties: Vec::new(),
            children: Vec::new(),
            search_paths,
            names: HashMap::new(),
            legacy_uv: LegacyUv::default(),
        });
        self.read_children(&source, root, ROOT, 1)?;
        self.finish_plugin(ROOT)
    }

    /// Builds an [`Element`]: substitutes `$name` parameters in the attribute values and applies
    /// the renaming of old files. `parent` is the draft that will hold the element.
    #[inline(never)]
    fn element(&mut self, source: &Source, node: Node, parent: Option<usize>) -> Result<Element> {
        let location = source.location(node.range().start);
        let tag_name = node.tag_name();
        if tag_name.namespace().is_some() {
            return Err(Error::input(
                &location,
                format!("unexpected namespaced element <{}>", quote(tag_name.name())),
            )
            .with_help("Mitsuba scene files use plain tags without XML namespaces"));
        }
        let mut tag = tag_name.name().to_string();
        if source.legacy && tag == "lookAt" {
            tag = "lookat".to_string();
        }
        let in_diffuse_bsdf = parent
            .and_then(|p| self.drafts.get(p))
            .is_some_and(|draft| {
                draft.class == PluginClass::Bsdf && draft.plugin_type == "diffuse"
            });
        let mut attributes = Vec::new();
        for attribute in node.attributes() {
            let attribute_location = source.location(attribute.range().start);
            if attribute.namespace().is_some() {
                return Err(Error::input(
                    &attribute_location,
                    format!(
                        "unexpected namespaced attribute \"{}\" in <{tag}>",
                        quote(attribute.name())
                    ),
                )
                .with_help("Mitsuba scene files use plain attributes without XML namespaces"));
            }
            let mut value = self
                .parameters
                .substitute(attribute.value(), &attribute_location)?;
            if source.legacy && attribute.name() == "name" && tag != "default" {
                value = camel_to_snake(&value);
                if in_diffuse_bsdf && value == "diffuse_reflectance" {
                    value = "reflectance".to_string();
                }
            }
            attributes.push(Attribute {
                name: attribute.name().to_string(),
                value,
                location: attribute_location,
            });
        }
        Ok(Element {
            tag,
            location,
            attributes,
        })
    }

    /// Reads the content of `node` into the draft `parent`; child elements are at `depth`.
    fn read_children(
        &mut self,
        source: &Source,
        node: Node,
        parent: usize,
        depth: usize,
    ) -> Result<()> {
        for child in node.children() {
            match child.node_type() {
                NodeType::Element => self.read_element(source, child, parent, depth)?,
                NodeType::Text => check_text(source, child, node)?,
                _ => {} // comments and processing instructions
            }
        }
        Ok(())
    }

    /// Reads one element nested in the draft `parent`.
    ///
    /// This function, [`Self::read_children`] and [`Self::read_plugin`] recurse once per level of
    /// nesting, so they keep little on the stack and leave the work to helpers (unoptimized
    /// builds give every local its own stack slot).
    fn read_element(
        &mut self,
        source: &Source,
        node: Node,
        parent: usize,
        depth: usize,
    ) -> Result<()> {
        let element = self.element(source, node, Some(parent))?;
        if depth > MAX_NESTING {
            return Err(too_deep(&element));
        }
        match plugin_class(&element) {
            Some(class) => self.read_plugin(source, node, &element, class, parent, depth),
            None if element.tag == "include" => {
                expect_no_content(source, node, &element)?;
                self.read_include(source, &element, parent, depth)
            }
            None => self.read_leaf(source, node, &element, parent),
        }
    }

    /// `<bsdf type="..." id="..." name="...">` and the other plugin elements.
    fn read_plugin(
        &mut self,
        source: &Source,
        node: Node,
        element: &Element,
        class: PluginClass,
        parent: usize,
        depth: usize,
    ) -> Result<()> {
        let index = self.start_plugin(source, element, class, parent)?;
        self.read_children(source, node, index, depth + 1)?;
        self.finish_plugin(index)
    }

    /// An element that contains no plugins: a property, `<ref>`, `<default>`, `<alias>` or
    /// `<path>`, or an element that does not belong here.
    #[inline(never)]
    fn read_leaf(
        &mut self,
        source: &Source,
        node: Node,
        element: &Element,
        parent: usize,
    ) -> Result<()> {
        let tag = element.tag.as_str();
        match tag {
            "float" | "integer" | "boolean" | "string" | "rgb" | "srgb" | "spectrum" | "point"
            | "vector" | "transform" => self.read_property(source, node, element, parent),
            "animation" => self.read_animation(source, node, element, parent),
            "ref" => {
                expect_no_content(source, node, element)?;
                self.read_ref(element, parent)
            }
            "default" => {
                expect_no_content(source, node, element)?;
                element.check_attributes(&["name", "value"])?;
                let name = element.require("name")?;
                let value = element.require("value")?;
                if name.value.is_empty() {
                    return Err(Error::input(&name.location, "<default> has an empty name")
                        .with_help("write <default name=\"spp\" value=\"64\"/>"));
                }
                self.parameters.declare_default(&name.value, &value.value);
                Ok(())
            }
            "alias" => {
                expect_no_content(source, node, element)?;
                self.read_alias(element)
            }
            "path" => {
                expect_no_content(source, node, element)?;
                self.read_path(source, element, parent)
            }
            "scene" => Err(
                Error::input(&element.location, "<scene> can only be the root element")
                    .with_help("to combine scene files, use <include filename=\"other.xml\"/>"),
            ),
            _ if transform_ops::OPERATIONS.contains(&tag) => Err(Error::input(
                &element.location,
                format!("<{tag}> can only appear inside a <transform>"),
            )
            .with_help(format!(
                "wrap it: <transform name=\"to_world\"> <{tag} .../> </transform>"
            ))),
            _ => Err(unknown_element(element)),
        }
    }

    /// Checks a plugin element, adds its draft and makes it a child of `parent`; returns the
    /// draft's index.
    #[inline(never)]
    fn start_plugin(
        &mut self,
        source: &Source,
        element: &Element,
        class: PluginClass,
        parent: usize,
    ) -> Result<usize> {
        element.check_attributes(&["type", "id", "name"])?;
        let plugin_type = element.require("type")?;
        if plugin_type.value.is_empty() {
            return Err(Error::input(
                &plugin_type.location,
                format!("<{}> has an empty type", element.tag),
            )
            .with_help(format!(
                "name the plugin, for example <{} type=\"...\">",
                element.tag
            )));
        }
        let index = self.drafts.len();
        let id = match element.get("id") {
            Some(id) => Some(self.declare_id(id, index)?),
            None => None,
        };
        let name = self.child_name(element, parent)?;
        let search_paths = self.search_paths(source);
        self.drafts.push(Draft {
            class,
            plugin_type: plugin_type.value.clone(),
            id,
            location: element.location.clone(),
            properties: Vec::new(),
            children: Vec::new(),
            search_paths,
            names: HashMap::new(),
            legacy_uv: LegacyUv::default(),
        });
        self.drafts[parent].children.push(DraftChild {
            name,
            target: Target::Inline(index),
            location: element.location.clone(),
        });
        Ok(index)
    }

    /// Registers an id for the draft `index`; a second declaration of an id is an error.
    fn declare_id(&mut self, id: &Attribute, index: usize) -> Result<String> {
        if id.value.is_empty() {
            return Err(Error::input(&id.location, "empty id")
                .with_help("give the object a name, for example id=\"floor\", or remove id"));
        }
        if let Some(previous) = self.ids.get(&id.value) {
            return Err(Error::input(
                &id.location,
                format!(
                    "duplicate id \"{}\" (first declared at {})",
                    quote(&id.value),
                    previous.location
                ),
            )
            .with_help("ids must be unique in the whole scene, included files too; rename one"));
        }
        self.ids.insert(
            id.value.clone(),
            IdEntry {
                index,
                location: id.location.clone(),
            },
        );
        Ok(id.value.clone())
    }

    /// The optional `name` of a nested plugin or reference, registered in its parent.
    fn child_name(&mut self, element: &Element, parent: usize) -> Result<Option<String>> {
        match element.get("name") {
            Some(name) => {
                self.register_name(parent, &name.value, &name.location)?;
                Ok(Some(name.value.clone()))
            }
            None => Ok(None),
        }
    }

    /// Records that the draft `parent` has a property or child called `name`; twice is an error.
    fn register_name(
        &mut self,
        parent: usize,
        name: &str,
        location: &SourceLocation,
    ) -> Result<()> {
        if name.is_empty() {
            return Err(Error::input(location, "empty name")
                .with_help("give the parameter name, for example name=\"reflectance\""));
        }
        let draft = &mut self.drafts[parent];
        if let Some(previous) = draft.names.get(name) {
            return Err(Error::input(
                location,
                format!(
                    "{} is given the parameter \"{}\" twice (first at {previous})",
                    draft.describe(),
                    quote(name)
                ),
            )
            .with_help("remove one of them"));
        }
        draft.names.insert(name.to_string(), location.clone());
        Ok(())
    }

    /// Adds the `to_uv` transform of an old file's texture coordinate floats, if any.
    fn finish_plugin(&mut self, index: usize) -> Result<()> {
        let draft = &mut self.drafts[index];
        let Some(location) = draft.legacy_uv.location.take() else {
            return Ok(());
        };
        let [u_offset, v_offset, u_scale, v_scale] = draft.legacy_uv.values;
        let offset = DVec3::new(u_offset.unwrap_or(0.0), v_offset.unwrap_or(0.0), 0.0);
        let scale = DVec3::new(u_scale.unwrap_or(1.0), v_scale.unwrap_or(1.0), 1.0);
        let to_uv = DMat4::from_diagonal(scale.extend(1.0)) * DMat4::from_translation(offset);
        self.register_name(index, "to_uv", &location)?;
        self.drafts[index].properties.push(Property {
            name: "to_uv".to_string(),
            value: PropertyValue::Transform(to_uv),
            location,
        });
        Ok(())
    }

    /// `<float>`, `<integer>`, `<boolean>`, `<string>`, `<rgb>`, `<srgb>`, `<spectrum>` (without a type),
    /// `<point>`, `<vector>` and `<transform>`.
    fn read_property(
        &mut self,
        source: &Source,
        node: Node,
        element: &Element,
        parent: usize,
    ) -> Result<()> {
        let tag = element.tag.as_str();
        let allowed: &[&str] = match tag {
            "spectrum" => &["name", "value", "filename"],
            "point" | "vector" => &["name", "value", "x", "y", "z"],
            "transform" => &["name"],
            _ => &["name", "value"],
        };
        element.check_attributes(allowed)?;
        let name = element.require("name")?;
        let value = match tag {
            "transform" => PropertyValue::Transform(self.read_transform(source, node, element)?),
            _ => {
                expect_no_content(source, node, element)?;
                self.property_value(source, element)?
            }
        };
        self.register_name(parent, &name.value, &name.location)?;
        if let PropertyValue::Float(v) = value
            && source.legacy
            && let Some(slot) = LEGACY_UV_NAMES.iter().position(|n| *n == name.value)
        {
            let uv = &mut self.drafts[parent].legacy_uv;
            uv.values[slot] = Some(v);
            uv.location.get_or_insert_with(|| element.location.clone());
            return Ok(());
        }
        self.drafts[parent].properties.push(Property {
            name: name.value.clone(),
            value,
            location: element.location.clone(),
        });
        Ok(())
    }

    /// The value of a property element other than `<transform>`.
    fn property_value(&mut self, source: &Source, element: &Element) -> Result<PropertyValue> {
        Ok(match element.tag.as_str() {
            "float" => PropertyValue::Float(element.number(element.require("value")?)?),
            "integer" => PropertyValue::Integer(element.integer(element.require("value")?)?),
            "boolean" => PropertyValue::Boolean(element.boolean(element.require("value")?)?),
            "rgb" => PropertyValue::Rgb(property_values::rgb(element)?),
            "srgb" => PropertyValue::Rgb(property_values::srgb_color(element)?),
            "spectrum" => {
                let search_paths = self.search_paths(source);
                property_values::spectrum(element, &search_paths)?
            }
            "point" => PropertyValue::Point(element.xyz(0.0)?),
            "vector" => PropertyValue::Vector(element.xyz(0.0)?),
            _ => PropertyValue::String(element.require("value")?.value.clone()),
        })
    }

    /// Composes the operations of a `<transform>`, each new one on the left.
    fn read_transform(&mut self, source: &Source, node: Node, element: &Element) -> Result<DMat4> {
        let mut matrix = DMat4::IDENTITY;
        for child in node.children() {
            match child.node_type() {
                NodeType::Element => {
                    let operation = self.element(source, child, None)?;
                    expect_no_content(source, child, &operation)?;
                    let dialect = if source.legacy {
                        Dialect::Mitsuba06
                    } else {
                        Dialect::Mitsuba3
                    };
                    let (operation_matrix, warning) =
                        transform_ops::operation_matrix(&operation, dialect)?;
                    self.warnings.extend(warning);
                    matrix = operation_matrix * matrix;
                    if !matrix.is_finite() {
                        return Err(Error::input(
                            &operation.location,
                            format!(
                                "{} overflows: after <{}> it has non-finite entries",
                                element.describe(),
                                operation.tag
                            ),
                        )
                        .with_help("check the magnitudes of the numbers in this transform"));
                    }
                }
                NodeType::Text => check_text(source, child, node)?,
                _ => {}
            }
        }
        Ok(matrix)
    }

    /// `<animation name="to_world">` with `<transform time="t">` keys (Mitsuba 0.6's syntax for
    /// moving shapes and cameras); `toWorld` is accepted as a name in files of any version. Keys
    /// must be in strictly increasing time and invertible.
    fn read_animation(
        &mut self,
        source: &Source,
        node: Node,
        element: &Element,
        parent: usize,
    ) -> Result<()> {
        element.check_attributes(&["name"])?;
        let name = element.require("name")?;
        let property_name = if name.value == "toWorld" {
            "to_world".to_string()
        } else {
            name.value.clone()
        };
        let mut keys: Vec<(f64, DMat4)> = Vec::new();
        for child in node.children() {
            match child.node_type() {
                NodeType::Element => {
                    let key = self.element(source, child, None)?;
                    if key.tag != "transform" {
                        return Err(Error::input(
                            &key.location,
                            format!("<{}> cannot appear in an <animation>", quote(&key.tag)),
                        )
                        .with_help("an animation holds <transform time=\"...\"> keys"));
                    }
                    key.check_attributes(&["time"])?;
                    let time = key.number(key.require("time")?)?;
                    if let Some(&(previous, _)) = keys.last()
                        && !(time > previous)
                    {
                        return Err(Error::input(
                            &key.location,
                            format!("animation key at time {time} comes after the key at time {previous}"),
                        )
                        .with_help("list the keys of an animation in increasing time"));
                    }
                    let matrix = self.read_transform(source, child, &key)?;
                    let det = matrix.determinant();
                    if !(det.abs() > 1e-30) || !det.is_finite() {
                        return Err(Error::input(
                            &key.location,
                            format!("the animation key at time {time} is a singular transform"),
                        )
                        .with_help("check for a zero scale"));
                    }
                    keys.push((time, matrix));
                }
                NodeType::Text => check_text(source, child, node)?,
                _ => {}
            }
        }
        if keys.is_empty() {
            return Err(
                Error::input(&element.location, "an <animation> needs at least one key")
                    .with_help("add <transform time=\"0\"> ... </transform> keys"),
            );
        }
        self.register_name(parent, &property_name, &name.location)?;
        self.drafts[parent].properties.push(Property {
            name: property_name,
            value: PropertyValue::Animation(keys),
            location: element.location.clone(),
        });
        Ok(())
    }

    /// `<ref id="..." name="..."/>`: resolved after the whole scene is read.
    fn read_ref(&mut self, element: &Element, parent: usize) -> Result<()> {
        element.check_attributes(&["id", "name"])?;
        let id = element.require("id")?.value.clone();
        let name = self.child_name(element, parent)?;
        self.drafts[parent].children.push(DraftChild {
            name,
            target: Target::Reference(id),
            location: element.location.clone(),
        });
        Ok(())
    }

    /// `<alias id="a" as="b"/>`: `b` becomes a second id of the object declared as `a`, which
    /// must come earlier in the document (as in Mitsuba).
    fn read_alias(&mut self, element: &Element) -> Result<()> {
        element.check_attributes(&["id", "as"])?;
        let id = element.require("id")?;
        let alias = element.require("as")?;
        let Some(target) = self.ids.get(&id.value) else {
            return Err(unknown_id(&id.value, &id.location, &self.ids)
                .with_help("an <alias> must come after the object whose id it names"));
        };
        let index = target.index;
        self.declare_id(alias, index)?;
        Ok(())
    }

    /// `<include filename="..."/>`: the included `<scene>`'s children are read in its place.
    fn read_include(
        &mut self,
        source: &Source,
        element: &Element,
        parent: usize,
        depth: usize,
    ) -> Result<()> {
        element.check_attributes(&["filename"])?;
        let filename = element.require("filename")?;
        if source.include_depth >= MAX_INCLUDE_DEPTH {
            return Err(Error::input(
                &element.location,
                format!("<include>s are nested more than {MAX_INCLUDE_DEPTH} deep"),
            )
            .with_help("check whether included files include each other"));
        }
        let mut dirs = vec![source.dir.clone()];
        for dir in self.search_paths(source).iter() {
            if !dirs.contains(dir) {
                dirs.push(dir.clone());
            }
        }
        let path = find_file(&filename.value, &dirs, &filename.location)?;
        let text = std::fs::read_to_string(&path).map_err(|err| {
            Error::io(&path, &err, "read the included file").at(&element.location)
        })?;
        let text = tolerate_hyphens_in_comments(&text);
        let mut included = Source::new(&path, &text, source.include_depth + 1);
        let document = parse_xml(&included).map_err(|err| {
            let position = err.location.map(|l| l.to_string()).unwrap_or_default();
            Error::input(
                &element.location,
                format!(
                    "could not read the included file: {position}: {}",
                    err.message
                ),
            )
            .with_help("fix the XML syntax of the included file")
        })?;
        let root = document.root_element();
        let root_element = self.element(&included, root, None)?;
        if root_element.tag != "scene" {
            return Err(Error::input(
                &root_element.location,
                format!(
                    "the root element of an included file is <{}>, but it must be <scene>",
                    quote(&root_element.tag)
                ),
            )
            .with_help("wrap the content in <scene version=\"3.0.0\"> ... </scene>"));
        }
        root_element.check_attributes(&["version"])?;
        if let Some(version) = root_element.get("version") {
            included.legacy = parse_version(version)? < (2, 0, 0);
        }
        self.read_children(&included, root, parent, depth)
    }

    /// `<path value="..."/>`: a folder to search for files, first.
    fn read_path(&mut self, source: &Source, element: &Element, parent: usize) -> Result<()> {
        element.check_attributes(&["value"])?;
        let value = element.require("value")?;
        if parent != ROOT {
            return Err(Error::input(
                &element.location,
                "<path> can only appear directly inside the root <scene>",
            )
            .with_help("move it to the top level of the scene"));
        }
        let folder = Path::new(&value.value);
        let candidates: Vec<PathBuf> = if folder.is_absolute() {
            vec![folder.to_path_buf()]
        } else {
            std::iter::once(source.dir.join(folder))
                .chain(self.search_paths(source).iter().map(|dir| dir.join(folder)))
                .collect()
        };
        let Some(found) = candidates.into_iter().find(|dir| dir.is_dir()) else {
            return Err(Error::input(
                &value.location,
                format!("<path>: folder \"{}\" not found", quote(&value.value)),
            )
            .with_help(format!(
                "relative folders are looked up from \"{}\"",
                source.dir.display()
            )));
        };
        self.path_dirs.retain(|dir| *dir != found);
        self.path_dirs.insert(0, found);
        self.search_path_cache.clear();
        Ok(())
    }

    /// The search paths of an element of `source` at the current point of the document.
    fn search_paths(&mut self, source: &Source) -> Arc<Vec<PathBuf>> {
        if let Some(paths) = self.search_path_cache.get(&source.dir) {
            return paths.clone();
        }
        let mut paths: Vec<PathBuf> = Vec::new();
        for dir in self.path_dirs.iter().chain([&source.dir, &self.main_dir]) {
            if !paths.contains(dir) {
                paths.push(dir.clone());
            }
        }
        let paths = Arc::new(paths);
        self.search_path_cache
            .insert(source.dir.clone(), paths.clone());
        paths
    }
}

/// The plugin class an element declares, if it is a plugin: a [`PluginClass`] tag other than
/// `scene`, where `<spectrum>` is a plugin only with a `type` attribute.
fn plugin_class(element: &Element) -> Option<PluginClass> {
    match PluginClass::from_tag(&element.tag)? {
        PluginClass::Scene => None,
        PluginClass::Spectrum if element.get("type").is_none() => None,
        class => Some(class),
    }
}

#[cold]
fn too_deep(element: &Element) -> Error {
    Error::input(
        &element.location,
        format!("elements are nested more than {MAX_NESTING} deep"),
    )
    .with_help("a scene never needs such deep nesting; check the file for a generator bug")
}

/// Text inside `container` must be whitespace (Mitsuba: "unexpected content").
#[inline(never)]
fn check_text(source: &Source, text: Node, container: Node) -> Result<()> {
    let content = text.text().unwrap_or("").trim();
    if content.is_empty() {
        return Ok(());
    }
    let offset = text.range().start + text.text().unwrap_or("").find(content).unwrap_or(0);
    Err(Error::input(
        &source.location(offset),
        format!(
            "unexpected text \"{}\" inside <{}>",
            quote(content),
            container.tag_name().name()
        ),
    )
    .with_help("values go in attributes such as value=\"...\"; remove the text or comment it out"))
}

/// Elements that hold no content: any child element or text is an error.
fn expect_no_content(source: &Source, node: Node, element: &Element) -> Result<()> {
    for child in node.children() {
        match child.node_type() {
            NodeType::Element => {
                return Err(Error::input(
                    &source.location(child.range().start),
                    format!(
                        "<{}> cannot contain elements, but it contains <{}>",
                        element.tag,
                        quote(child.tag_name().name())
                    ),
                )
                .with_help(format!(
                    "close <{}> with \"/>\" and move the inner element out of it",
                    element.tag
                )));
            }
            NodeType::Text => check_text(source, child, node)?,
            _ => {}
        }
    }
    Ok(())
}

/// Every tag a scene may contain, for messages.
const KNOWN_TAGS: [&str; 33] = [
    "alias",
    "animation",
    "boolean",
    "bsdf",
    "default",
    "emitter",
    "film",
    "float",
    "include",
    "integer",
    "integrator",
    "lookat",
    "matrix",
    "medium",
    "path",
    "phase",
    "point",
    "ref",
    "rfilter",
    "rgb",
    "rotate",
    "sampler",
    "scale",
    "sensor",
    "shape",
    "spectrum",
    "srgb",
    "string",
    "texture",
    "transform",
    "translate",
    "vector",
    "volume",
];

fn unknown_element(element: &Element) -> Error {
    let mut help = format!("the elements of a scene are <{}>", KNOWN_TAGS.join(">, <"));
    if let Some(close) = closest_match(&element.tag, &KNOWN_TAGS) {
        help = format!("did you mean <{close}>? {help}");
    }
    if element.tag == "lookAt" {
        help = "write <lookat>; <lookAt> is accepted only in files with a version before 2.0.0"
            .to_string();
    }
    Error::input(
        &element.location,
        format!("unknown element <{}>", quote(&element.tag)),
    )
    .with_help(help)
}

/// The error for a reference to an id that nothing declares, with the closest ids.
fn unknown_id(id: &str, location: &SourceLocation, ids: &HashMap<String, IdEntry>) -> Error {
    let mut known: Vec<&str> = ids.keys().map(String::as_str).collect();
    known.sort_unstable();
    let mut close = Vec::new();
    while close.len() < 3 {
        let Some(found) = closest_match(id, &known) else {
            break;
        };
        close.push(format!("\"{found}\""));
        known.retain(|k| *k != found);
    }
    let help = if !close.is_empty() {
        format!("did you mean {}?", close.join(" or "))
    } else if ids.is_empty() {
        "the scene declares no ids; add id=\"...\" to the object to reference".to_string()
    } else {
        "declare an object with this id; it may come before or after the reference".to_string()
    };
    Error::input(location, format!("no object has the id \"{}\"", quote(id))).with_help(help)
}

/// Pass 2: turns the drafts into nodes, children first, sharing the node of each id among its
/// references. A depth-first walk with an explicit stack finds references that would make a
/// plugin contain itself.
fn resolve(mut drafts: Vec<Draft>, ids: &HashMap<String, IdEntry>) -> Result<Arc<PluginNode>> {
    // The draft index of every child, with references looked up.
    let mut targets: Vec<Vec<usize>> = Vec::with_capacity(drafts.len());
    for draft in &drafts {
        let mut indices = Vec::with_capacity(draft.children.len());
        for child in &draft.children {
            indices.push(match &child.target {
                Target::Inline(index) => *index,
                Target::Reference(id) => match ids.get(id) {
                    Some(entry) => entry.index,
                    None => return Err(unknown_id(id, &child.location, ids)),
                },
            });
        }
        targets.push(indices);
    }

    let mut built: Vec<Option<Arc<PluginNode>>> = vec![None; drafts.len()];
    let mut on_stack = vec![false; drafts.len()];
    // (draft, index of its next child to visit)
    let mut stack: Vec<(usize, usize)> = vec![(ROOT, 0)];
    on_stack[ROOT] = true;
    while let Some(top) = stack.last_mut() {
        let (index, next) = *top;
        if let Some(&target) = targets[index].get(next) {
            top.1 += 1;
            if built[target].is_some() {
                continue;
            }
            if on_stack[target] {
                let child = &drafts[index].children[next];
                return Err(cycle_error(&drafts, &stack, target, child));
            }
            on_stack[target] = true;
            stack.push((target, 0));
            continue;
        }
        stack.pop();
        on_stack[index] = false;
        let draft = &mut drafts[index];
        let mut children = Vec::with_capacity(draft.children.len());
        for (child, &target) in draft.children.iter_mut().zip(&targets[index]) {
            let Some(node) = built[target].clone() else {
                return Err(Error::input(
                    &child.location,
                    "internal error: a nested plugin was not built before its parent",
                ));
            };
            children.push(NestedPlugin {
                name: child.name.take(),
                node,
                location: child.location.clone(),
            });
        }
        built[index] = Some(Arc::new(PluginNode {
            class: draft.class,
            plugin_type: std::mem::take(&mut draft.plugin_type),
            id: draft.id.take(),
            location: draft.location.clone(),
            properties: std::mem::take(&mut draft.properties),
            children,
            search_paths: draft.search_paths.clone(),
        }));
    }
    built
        .into_iter()
        .next()
        .flatten()
        .ok_or_else(|| Error::usage("internal error: the scene root was not built"))
}

/// The error for the reference `child` to `target`, a draft that is on the `stack` of plugins
/// being resolved (so the reference is inside it).
fn cycle_error(
    drafts: &[Draft],
    stack: &[(usize, usize)],
    target: usize,
    child: &DraftChild,
) -> Error {
    let start = stack
        .iter()
        .position(|&(index, _)| index == target)
        .unwrap_or(0);
    let chain: Vec<String> = stack
        .get(start..)
        .unwrap_or(&[])
        .iter()
        .map(|&(index, _)| drafts[index].describe())
        .collect();
    let id = match &child.target {
        Target::Reference(id) => quote(id),
        Target::Inline(_) => String::new(),
    };
    Error::input(
        &child.location,
        format!(
            "the reference to \"{id}\" makes {} contain itself",
            drafts[target].describe()
        ),
    )
    .with_help(format!(
        "the nesting is {} > <ref id=\"{id}\">; reference an object outside this chain",
        chain.join(" > ")
    ))
}

#[cfg(test)]
mod tests;
