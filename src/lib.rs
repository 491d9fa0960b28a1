//! Prism: a spectral Monte Carlo path tracer for Mitsuba 3 XML scenes.

// Comparisons are written `!(x > 0.0)` on purpose throughout: unlike `x <= 0.0` they also
// reject NaN, which is what a renderer's guards are for.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bsdf;
pub mod camera;
pub mod cli;
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
