//! Prism: a spectral Monte Carlo path tracer for Mitsuba 3 XML scenes.
pub mod bsdf;
pub mod cli;
pub mod camera;
pub mod error;
pub mod film;
pub mod geometry;
pub mod integrator;
pub mod light;
pub mod math;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod spectrum;
