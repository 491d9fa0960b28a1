//! Prism: a spectral Monte Carlo path tracer for Mitsuba 3 XML scenes.
//!
//! # The pipeline
//! `prism render scene.xml` reads the Mitsuba XML file into a tree of plugins whose every value
//! remembers its file, line and column ([`scene::mitsuba::reader`]); the factory
//! ([`scene::mitsuba::factory`]) builds the renderable [`scene::Scene`]: shapes in a BVH, lights
//! with a power-proportional light sampler, materials, camera and film settings. The render
//! driver ([`render`]) splits the image into tiles and renders them on all cores; for each pixel
//! sample it asks the per-pixel sampler for the primary dimensions (wavelengths, filter offset),
//! builds a camera ray, and asks the integrator for the spectral radiance along it. The film
//! converts each sample to CIE XYZ and accumulates sums and squared sums per pixel; at the end
//! the image is written as EXR (linear) and PNG (sRGB).
//!
//! # Modules
//! | module | concept |
//! | --- | --- |
//! | [`cli`] | the subcommands of the `prism` program |
//! | [`math`] | vectors, frames, transforms, rays |
//! | [`spectrum`] | wavelengths and spectral values along a path, CIE tables, RGB upsampling |
//! | [`sampling`] | random numbers, warps, tabulated distributions, the per-pixel sampler |
//! | [`camera`] | pinhole camera |
//! | [`film`] | reconstruction filters and their samplers, pixel sums, image files |
//! | [`geometry`] | shapes, ray intersection, the BVH, robust ray offsets |
//! | [`bsdf`] | the BSDF interface and BSDFs, materials |
//! | [`light`] | light sources and the light sampler |
//! | [`integrator`] | the path tracer |
//! | [`render`] | tiles, threads, progress |
//! | [`scene`] | the scene, mesh readers, the Mitsuba XML reader and plugin factory |
//! | [`bench`] | the benchmark suite of `prism bench`: its scenes, rays and measurements |
//! | [`error`] | errors with source locations |

// Comparisons are written `!(x > 0.0)` on purpose throughout: unlike `x <= 0.0` they also
// reject NaN, which is what a renderer's guards are for.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bench;
pub mod bsdf;
pub mod camera;
pub mod cli;
pub mod error;
pub mod film;
pub mod geometry;
pub mod image;
pub mod integrator;
pub mod light;
pub mod math;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod spectrum;
pub mod texture;
pub mod world;
