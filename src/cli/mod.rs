//! The subcommands of the `prism` program, one per file, and what `prism render` shows while it
//! runs: the progress bar and the image sent to a display server; and the denoised image it
//! writes at the end.

pub mod bench;
pub mod compare;
pub mod converge;
pub mod denoise;
pub mod display_server;
pub mod merge;
pub mod plugins;
pub mod progress_bar;
pub mod render;
