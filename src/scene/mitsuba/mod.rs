//! Mitsuba 3 XML scenes: the parsed description and checked parameter access.
pub mod description;
pub mod factory;
pub mod params;

use std::path::Path;

use crate::error::Result;
pub use factory::LoadedScene;

/// Reads a Mitsuba XML scene file (with `-D name=value` overrides) and builds it.
pub fn load_scene(path: &Path, defines: &[(String, String)]) -> Result<LoadedScene> {
    let root = reader::read_scene_file(path, defines)?;
    factory::build_scene(&root)
}
