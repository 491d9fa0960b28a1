//! Any bytes given as a Mitsuba `.vol` grid give a grid or an error; never a panic, and never
//! an allocation sized by a resolution the file cannot back. A grid of one channel (numbers) or
//! three (colours, upsampled to spectra) that parses is also built and looked up with every
//! filter and wrap mode, inside and outside its box.
#![no_main]

use glam::Vec3;
use libfuzzer_sys::fuzz_target;
use prism_core::math::Transform;
use prism_core::medium::volume::parse_vol;
use prism_core::medium::{GridFilter, GridVolume, GridWrap, SpectralGridVolume};
use prism_core::spectrum::{SampledWavelengths, WavelengthSampling};

fuzz_target!(|data: &[u8]| {
    let Ok(file) = parse_vol(data) else {
        return;
    };
    let points = [Vec3::splat(0.5), Vec3::ZERO, Vec3::ONE, Vec3::new(-3.0, 0.2, 7.0)];
    let lambda = SampledWavelengths::sample(0.5, WavelengthSampling::Uniform);
    for filter in [GridFilter::Trilinear, GridFilter::Nearest] {
        for wrap in [GridWrap::Clamp, GridWrap::Repeat, GridWrap::Mirror] {
            match file.channels {
                1 => {
                    if let Some(grid) = GridVolume::new(
                        file.resolution,
                        file.data.clone(),
                        Transform::IDENTITY,
                        filter,
                    ) {
                        let grid = grid.with_wrap(wrap);
                        for p in points {
                            let _ = grid.eval(p);
                        }
                    }
                }
                3 => {
                    if let Some(grid) = SpectralGridVolume::new(
                        file.resolution,
                        &file.data,
                        Transform::IDENTITY,
                        filter,
                    ) {
                        let grid = grid.with_wrap(wrap);
                        for p in points {
                            let _ = grid.eval(p, &lambda);
                        }
                    }
                }
                _ => {}
            }
        }
    }
});
