//! Prism's renderer: spectral Monte Carlo light transport, independent of any scene format.
//!
//! # The pipeline
//! A [`scene::Scene`] holds the [`world::World`] (primitives in a BVH, what each is made of,
//! the lights), the camera and film, the sampler and the integrator. The render driver
//! ([`render`]) renders the image in passes of tiles on all cores; for each pixel sample it asks
//! the per-pixel sampler for the primary dimensions (wavelengths, time, filter offset, lens
//! position), builds a camera ray, and asks the integrator for the spectral radiance along it.
//! The film converts each sample to CIE XYZ and accumulates sums and squared sums per pixel; at
//! the end the image is written as EXR (linear) and PNG (sRGB).
//!
//! # Modules, lowest layer first
//! Each module uses only those above it in this table, the order of the `layers` block of
//! docs/architecture.md (one test checks the code against that block, another this table).
//!
//! | module | concept |
//! | --- | --- |
//! | [`error`] | errors with source locations |
//! | [`dispatch`] | how a plugin class is declared: its trait and the enum that dispatches it |
//! | [`math`] | vectors, frames, transforms, rays, special functions |
//! | [`sampling`] | random numbers, warps, tabulated distributions, the per-pixel sampler, chi-square tests of densities |
//! | [`spectrum`] | wavelengths and spectral values along a path, CIE tables, RGB upsampling |
//! | [`image`] | image files: decoding, EXR and PNG output, the sRGB curve, comparison |
//! | [`tensor_file`] | Mitsuba's tensor files: the sun-and-sky tables, measured BSDFs |
//! | [`polarization`] | Stokes vectors, Mueller matrices, the Fresnel equations for polarized light |
//! | [`geometry`] | shapes, intersection, the BVH, instances, the scene's primitives |
//! | [`medium`] | participating media and phase functions |
//! | [`texture`] | values that vary over a surface |
//! | [`bsdf`] | BSDFs, their lobes at a point, materials |
//! | [`light`] | light sources and the light sampler |
//! | [`world`] | geometry, materials, lights and media together |
//! | [`film`] | reconstruction filters, pixel sums and their error, the images written |
//! | [`camera`] | perspective, thin-lens and orthographic cameras, the radiance, irradiance and distant meters, the batch of sensors, and the shutter |
//! | [`integrator`] | the estimators: path, direct, distrib, volpath, volpathmis, moment, aov, depth, ptracer, bdpt, sppm, vcm, guided_path, the polarized path tracer and stokes |
//! | [`scene`] | the world with camera, film, sampler and integrator |
//! | [`render`] | passes, tiles, threads, progress, render states |

// Comparisons are written `!(x > 0.0)` on purpose throughout: unlike `x <= 0.0` they also
// reject NaN, which is what a renderer's guards are for.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bsdf;
pub mod camera;
pub mod dispatch;
pub mod error;
pub mod film;
pub mod geometry;
pub mod image;
pub mod integrator;
pub mod light;
pub mod math;
pub mod medium;
pub mod polarization;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod spectrum;
pub mod tensor_file;
pub mod texture;
pub mod world;
