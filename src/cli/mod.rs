//! The subcommands of the `prism` program, one per file.

pub mod render;
