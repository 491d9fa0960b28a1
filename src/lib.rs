//! The `prism` program: its subcommands ([`cli`]), the benchmark suite of `prism bench`
//! ([`bench`]), the choice of ray-tracing structure with the Embree comparison backend
//! ([`accel`], [`embree`]) and the Open Image Denoise filter of `prism render --denoise`
//! ([`denoise`]). The renderer is the `prism-core` crate; Mitsuba scenes are read by
//! `prism-mitsuba`.

// As in prism-core: `!(x > 0.0)` also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod bench;
pub mod cli;
pub mod denoise;
#[cfg(feature = "embree")]
pub mod embree;
