//! Bad input: each malformed scene, file or flag gives one clear message naming the file, line
//! and column, and exit status 2 — never a panic.

mod bad_input;
mod cli;
mod lights;
