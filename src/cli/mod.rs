//! The subcommands of the `prism` program, one per file, and the Embree comparison backend.

pub mod accel;
pub mod bench;
pub mod compare;
pub mod converge;
#[cfg(feature = "embree")]
pub mod embree;
pub mod merge;
pub mod plugins;
pub mod render;
