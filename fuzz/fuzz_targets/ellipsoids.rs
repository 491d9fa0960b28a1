//! Any bytes given as the PLY file of the `ellipsoids` shape give ellipsoids or an error; never
//! a panic.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = prism_mitsuba::mesh::ellipsoids::parse_ellipsoids(data, Path::new("fuzz.ply"));
});
