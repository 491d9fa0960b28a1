//! Any bytes given as an RGL `.bsdf` file give a measured material or an error; never a panic,
//! and never an allocation sized by a shape the file cannot back. A material that parses is
//! evaluated and sampled from a few directions.
#![no_main]

use std::sync::Arc;

use glam::{Vec2, Vec3};
use libfuzzer_sys::fuzz_target;
use prism_core::bsdf::{Bsdf, BxdfTree, Measured, MeasuredData, Scattering, ShadingPoint};
use prism_core::spectrum::{SampledWavelengths, WavelengthSampling};

fuzz_target!(|data: &[u8]| {
    let Ok(material) = MeasuredData::parse(data) else {
        return;
    };
    let bsdf = Bsdf::Measured(Measured {
        data: Arc::new(material),
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
        let _ = scattering.eval(Vec3::new(0.1, -0.2, 0.97).normalize());
        let _ = scattering.sample(0.5, Vec2::new(0.3, 0.7));
    }
});
