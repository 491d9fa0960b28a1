//! Any bytes given as a curve file (`linearcurve`) give control points or an error; never a
//! panic.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = prism_mitsuba::mesh::curves::parse_curves(data, Path::new("fuzz.txt"));
});
