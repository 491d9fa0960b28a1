//! Chi-square tests of sampling routines against the densities they claim
//! ([`prism_core::sampling::chi2`]; docs/testing.md, chi-square tests). Each module is one
//! suite: its tests share Šidák's correction, over a count derived from the module's own cases.

mod bsdfs;
mod image_formation;
mod layered;
mod lights;
mod media;
mod sampling;
