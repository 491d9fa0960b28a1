//! Mitsuba 3 XML scenes: the reader that parses a file into a described tree of plugins, checked
//! access to plugin parameters, and the factory that builds a renderable scene from the tree.
pub mod description;
mod element;
pub mod factory;
pub mod params;
mod property_values;
pub mod reader;
mod substitution;
mod transform_ops;

use std::path::Path;

use crate::error::Result;
pub use factory::LoadedScene;

/// Reads a Mitsuba XML scene file (with `-D name=value` overrides) and builds it.
pub fn load_scene(path: &Path, defines: &[(String, String)]) -> Result<LoadedScene> {
    let root = reader::read_scene_file(path, defines)?;
    factory::build_scene(&root)
}
