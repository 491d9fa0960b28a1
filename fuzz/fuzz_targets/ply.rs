//! Any bytes given as a PLY file give a mesh or an error; never a panic, and never an
//! allocation sized by a count the file cannot back.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = prism_mitsuba::mesh::ply::parse_ply(data, Path::new("fuzz.ply"));
});
