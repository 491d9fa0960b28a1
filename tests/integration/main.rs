//! Prism's integration tests, one crate of topic modules: the renderer through its library and
//! through the `prism` program (docs/testing.md says what each topic tests).

mod bench;
mod chi2;
mod command_line;
mod common;
#[cfg(feature = "denoise")]
mod denoise;
mod depth_parity;
mod determinism;
#[cfg(feature = "embree")]
mod embree;
mod errors;
mod estimators;
mod image_formation;
mod layers;
mod leniency;
mod lights;
mod materials;
mod media;
mod output_formats;
mod pbrt;
mod polarization;
mod preview;
mod references;
mod reliability;
mod several_sensors;
mod shapes;
mod signposts;
mod transforms;
