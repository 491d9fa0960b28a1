//! Any bytes given as a Mitsuba `.vol` grid give a grid or an error; never a panic, and never
//! an allocation sized by a resolution the file cannot back. A single-channel grid that parses
//! is also built and looked up, inside and outside its box.
#![no_main]

use glam::Vec3;
use libfuzzer_sys::fuzz_target;
use prism_core::math::Transform;
use prism_core::medium::volume::parse_vol;
use prism_core::medium::{GridFilter, GridVolume};

fuzz_target!(|data: &[u8]| {
    let Ok(file) = parse_vol(data) else {
        return;
    };
    if file.channels != 1 {
        return;
    }
    for filter in [GridFilter::Trilinear, GridFilter::Nearest] {
        if let Some(grid) =
            GridVolume::new(file.resolution, file.data.clone(), Transform::IDENTITY, filter)
        {
            for p in [Vec3::splat(0.5), Vec3::ZERO, Vec3::ONE, Vec3::new(-3.0, 0.2, 7.0)] {
                let _ = grid.eval(p);
            }
        }
    }
});
