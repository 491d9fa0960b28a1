//! Scenes: the Mitsuba XML reader, mesh readers and the scene builder.
pub mod mesh;
pub mod mitsuba;
