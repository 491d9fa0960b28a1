//! Prism: a spectral Monte Carlo path tracer for Mitsuba 3 XML scenes.
pub mod error;
pub mod film;
pub mod sampling;
pub mod scene;
