//! The subcommands of the `prism` program, one per file.

pub mod bench;
pub mod compare;
pub mod converge;
pub mod merge;
pub mod plugins;
pub mod progress_bar;
pub mod render;
