//! Helpers shared by the integration tests.
//!
//! Cargo compiles this module into every test file that declares `mod common;`, and each file
//! uses only some of the helpers, so unused-item warnings here would be false alarms.
#![allow(dead_code)]

pub mod chi2;
pub mod scenes;
pub mod serialized;
