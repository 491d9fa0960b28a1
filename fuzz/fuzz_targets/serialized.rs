//! Any bytes given as a Mitsuba serialized file give a mesh or an error; never a panic, and
//! never an allocation sized by a count the file cannot back. The first byte chooses the shape
//! index (0 to 3), so that the table of shapes at the end of the file is read too.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Some((&index, file)) = data.split_first() {
        let shape_index = u32::from(index % 4);
        let _ = prism_mitsuba::mesh::serialized::parse_serialized(
            file,
            shape_index,
            Path::new("fuzz.serialized"),
        );
    }
});
