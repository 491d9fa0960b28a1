//! Any bytes given as one of the `sunsky` emitter's tensor files give tables or an error; never
//! a panic, and never an allocation sized by a shape the file cannot back. The first byte
//! chooses which file the rest replaces (even: the datasets, odd: the sampling data; the other
//! is the embedded copy). Tables that parse are built into an emitter, which is evaluated and
//! sampled.
#![no_main]

use glam::{Vec2, Vec3};
use libfuzzer_sys::fuzz_target;
use prism_core::light::sunsky::data::{DATASETS, SAMPLING_DATA, SunskyTables};
use prism_core::tensor_file::parse_tensor_file;
use prism_core::light::{LightQuery, LightSource, Sunsky, SunskySettings};
use prism_core::math::Transform;
use prism_core::spectrum::SampledWavelengths;

fuzz_target!(|data: &[u8]| {
    let Some((&choice, bytes)) = data.split_first() else {
        return;
    };
    let _ = parse_tensor_file(bytes);
    let parsed = if choice % 2 == 0 {
        SunskyTables::parse(bytes, SAMPLING_DATA)
    } else {
        SunskyTables::parse(DATASETS, bytes)
    };
    let Ok(tables) = parsed else {
        return;
    };
    let settings = SunskySettings {
        sun: Vec3::new(0.3, 0.2, 0.8),
        turbidity: 1.0 + f32::from(choice % 10),
        albedo: [0.3; 11],
        sun_scale: 1.0,
        sky_scale: 1.0,
        sun_half_aperture: 0.01,
        complex_sun: choice & 2 != 0,
        to_world: Transform::IDENTITY,
    };
    let light = Sunsky::with_tables(&settings, &tables);
    let lambda = SampledWavelengths::single(550.0);
    for d in [
        Vec3::Z,
        Vec3::new(0.3, 0.2, 0.8).normalize(),
        Vec3::new(1.0, 0.0, 0.01).normalize(),
    ] {
        let _ = light.radiance(d, &lambda);
        let _ = light.pdf(d);
    }
    for u in [Vec2::new(0.1, 0.7), Vec2::new(0.99, 0.2)] {
        let _ = light.sample_incident(LightQuery {
            shapes: &[],
            reference: Vec3::ZERO,
            time: 0.0,
            u_choice: 0.5,
            u,
            lambda: &lambda,
        });
    }
    let _ = light.power(&[]);
});
