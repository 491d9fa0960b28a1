//! pbrt-v4 scenes (`.pbrt`): a tokenizer and parser for pbrt-v4's scene format that translates
//! its directives into the plugin tree the Mitsuba XML reader produces ([`crate::description`]),
//! so that the factory builds the scene from either file alike.
//!
//! A pbrt model becomes the Prism plugin with the same model (docs/pbrt.md has the table); a
//! directive, a type or a parameter with no faithful counterpart is refused with its file, line
//! and column, never approximated silently. Where the translation keeps a small difference of
//! the kind that does not change what is rendered (a sampler, a filter's tail) it says so in a
//! [`Warning`].
//!
//! Relative file names (`Include`, `Import`, meshes, images) are looked up in the folder of the
//! main scene file, as pbrt-v4 does.

mod builder;
mod camera;
mod lights;
mod materials;
mod media;
mod parameters;
mod shapes;
mod spectra;
mod tokenizer;
mod transforms;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::description::{NestedPlugin, PluginClass, PluginNode, Property, PropertyValue, Warning};
use prism_core::error::{Error, Result, SourceLocation};

/// A pbrt-v4 scene read into a plugin tree, with the reader's warnings.
pub struct PbrtScene {
    pub root: Arc<PluginNode>,
    pub warnings: Vec<Warning>,
}

/// Reads the pbrt-v4 scene file at `path`.
pub fn read_pbrt_file(path: &Path) -> Result<PbrtScene> {
    let text = std::fs::read_to_string(path).map_err(|err| {
        if err.kind() == std::io::ErrorKind::NotFound {
            Error::usage(format!("scene file \"{}\" not found", path.display()))
                .with_help("check the path of the scene file")
        } else {
            Error::io(path, &err, "read the scene file")
        }
    })?;
    read_pbrt_str(&text, path)
}

/// Reads a pbrt-v4 scene given as text; `path` names it in messages, and relative file names
/// are found from its folder.
pub fn read_pbrt_str(text: &str, path: &Path) -> Result<PbrtScene> {
    let folder = path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."));
    let mut builder = builder::Builder::new(path, Arc::new(vec![folder]));
    builder.read_text(text, path, 0)?;
    builder.finish()
}

/// A new plugin node whose files are looked up in `search_paths`.
fn plugin(
    class: PluginClass,
    plugin_type: &str,
    location: &SourceLocation,
    search_paths: &Arc<Vec<PathBuf>>,
) -> PluginNode {
    PluginNode {
        class,
        plugin_type: plugin_type.to_string(),
        id: None,
        location: location.clone(),
        properties: Vec::new(),
        children: Vec::new(),
        search_paths: search_paths.clone(),
    }
}

/// Adds the property `name` = `value` written at `location`.
fn set(node: &mut PluginNode, name: &str, value: PropertyValue, location: &SourceLocation) {
    node.properties.push(Property {
        name: name.to_string(),
        value,
        location: location.clone(),
    });
}

/// Nests `child` in `node`, under `name` where the parent reads it by name.
fn nest(
    node: &mut PluginNode,
    name: Option<&str>,
    child: Arc<PluginNode>,
    location: &SourceLocation,
) {
    node.children.push(NestedPlugin {
        name: name.map(str::to_string),
        node: child,
        location: location.clone(),
    });
}

#[cfg(test)]
mod tests;
