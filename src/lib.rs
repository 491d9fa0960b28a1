//! The `prism` program: its subcommands ([`cli`]) and the benchmark suite of `prism bench`
//! ([`bench`]). The renderer is the `prism-core` crate; Mitsuba scenes are read by
//! `prism-mitsuba`.

// As in prism-core: `!(x > 0.0)` also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bench;
pub mod cli;
