//! Any bytes given as a `.pbsdf` file give a measured pBRDF or an error; never a panic, and
//! never an allocation sized by a shape the file cannot back. A table that parses is
//! evaluated, sampled and asked for its Mueller matrix from a few directions.
#![no_main]

use std::sync::Arc;

use glam::{Vec2, Vec3};
use libfuzzer_sys::fuzz_target;
use prism_core::bsdf::{
    Bsdf, BsdfFlags, BxdfTree, MeasuredPolarized, MeasuredPolarizedData, Scattering, ShadingPoint,
};
use prism_core::spectrum::{SampledSpectrum, SampledWavelengths, WavelengthSampling};

fuzz_target!(|data: &[u8]| {
    let Ok(table) = MeasuredPolarizedData::parse(data) else {
        return;
    };
    let bsdf = Bsdf::MeasuredPolarized(MeasuredPolarized {
        data: Arc::new(table),
        alpha_sample: 0.1,
        wavelength: None,
    });
    let point = ShadingPoint::local(Vec2::ZERO);
    let lambda = SampledWavelengths::sample(0.5, WavelengthSampling::CieSum);
    let mut tree = BxdfTree::empty();
    for wo in [
        Vec3::Z,
        Vec3::new(0.6, 0.0, 0.8),
        Vec3::new(-0.3, 0.9, 0.3).normalize(),
    ] {
        let scattering = Scattering::new(&bsdf, &point, wo, &lambda, &mut tree);
        let wi = Vec3::new(0.1, -0.2, 0.97).normalize();
        let _ = scattering.eval(wi);
        let _ = scattering.polarized(wi, BsdfFlags::NONE, SampledSpectrum::ONE);
        let _ = scattering.sample(0.5, Vec2::new(0.3, 0.7));
    }
});
