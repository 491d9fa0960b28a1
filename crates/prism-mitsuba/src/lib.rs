//! Mitsuba scenes for Prism: the XML reader that parses a file (Mitsuba 3's format, and Mitsuba
//! 0.6's) into a described tree of plugins whose every value remembers its file, line and
//! column, the pbrt-v4 reader that translates a `.pbrt` file into the same tree, checked access
//! to plugin parameters, the factory that builds a renderable [`prism_core::scene::Scene`] from
//! the tree, and the mesh readers.

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
pub mod pbrt;
mod property_values;
pub mod reader;
pub mod reference;
pub mod registry;
mod substitution;
pub mod suggest;
mod transform_ops;

use std::path::Path;

pub use factory::LoadedScene;
use prism_core::error::{Error, Result};

/// Reads a scene file and builds it (see [`read_scene`]); the reader's warnings come first.
pub fn load_scene(path: &Path, defines: &[(String, String)]) -> Result<LoadedScene> {
    let document = read_scene(path, defines)?;
    let mut loaded = factory::build_scene(&document.root)?;
    loaded.warnings.splice(0..0, document.warnings);
    Ok(loaded)
}

/// Reads a scene file into its plugin tree: a pbrt-v4 scene when its name ends in `.pbrt` (see
/// [`pbrt`]), else a Mitsuba XML scene (with `-D name=value` overrides).
pub fn read_scene(path: &Path, defines: &[(String, String)]) -> Result<reader::SceneDocument> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pbrt"))
    {
        if let Some((name, _)) = defines.first() {
            return Err(Error::usage(format!(
                "-D {name}=...: a pbrt-v4 scene has no parameters to set"
            ))
            .with_help("-D sets the $name parameters of Mitsuba XML scenes"));
        }
        let scene = pbrt::read_pbrt_file(path)?;
        return Ok(reader::SceneDocument {
            root: scene.root,
            warnings: scene.warnings,
        });
    }
    reader::read_scene_document(path, defines)
}
