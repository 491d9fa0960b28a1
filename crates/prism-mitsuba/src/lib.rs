//! Mitsuba scenes for Prism: the XML reader that parses a file (Mitsuba 3's format, and Mitsuba
//! 0.6's) into a described tree of plugins whose every value remembers its file, line and
//! column, checked access to plugin parameters, the factory that builds a renderable
//! [`prism_core::scene::Scene`] from the tree, and the mesh readers.

// As in prism-core: `!(x > 0.0)` also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod description;
pub mod dict;
mod element;
pub mod factory;
pub mod file_cache;
pub mod fingerprint;
pub mod mesh;
pub mod params;
mod property_values;
pub mod reader;
pub mod reference;
pub mod registry;
mod substitution;
pub mod suggest;
mod transform_ops;

use std::path::Path;

pub use factory::LoadedScene;
use prism_core::error::Result;

/// Reads a Mitsuba XML scene file (with `-D name=value` overrides) and builds it; the reader's
/// warnings come first.
pub fn load_scene(path: &Path, defines: &[(String, String)]) -> Result<LoadedScene> {
    let document = reader::read_scene_document(path, defines)?;
    let mut loaded = factory::build_scene(&document.root)?;
    loaded.warnings.splice(0..0, document.warnings);
    Ok(loaded)
}
