//! Any bytes given as a curve file (`linearcurve`, `bsplinecurve`) give control points or an
//! error; never a panic.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for min_points in [2, 4] {
        let _ = prism_mitsuba::mesh::curves::parse_curves(data, Path::new("fuzz.txt"), min_points);
    }
});
