//! The plugin factory: turns a parsed Mitsuba scene description into a renderable
//! [`prism_core::scene::Scene`].
//!
//! Each plugin class has its registry and builders in its own module (see
//! [`crate::registry`]), each plugin's entry, parameters and builder together; a builder reads
//! its declared parameters through [`crate::params::Params`], so that unknown or misspelled
//! parameters are reported with their location. [`scene`] reads the root element section by
//! section; objects declared once and referenced many times (a BSDF with an `id`) are built
//! once.

pub mod fov;
mod inline_grid;
mod instancing;
pub mod integrators;
pub mod lights;
pub mod materials;
pub mod media;
mod scene;
pub mod sensor;
mod sensor_choice;
pub mod shapes;
pub mod spectra;
pub mod textures;

pub use scene::{KeptGeometry, LoadedScene, build_scene, build_scene_with_geometry};
pub use sensor_choice::SceneSensor;
