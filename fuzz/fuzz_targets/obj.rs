//! Any bytes given as a Wavefront OBJ file give a mesh or an error; never a panic.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = prism_mitsuba::mesh::obj::parse_obj(data, Path::new("fuzz.obj"));
});
