//! Any text given as a scene file must be read and built into a scene, or refused with an
//! error; never a panic. Files the scene names are looked up next to a virtual scene file in
//! an empty folder, so only the XML itself is being tested.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("/nonexistent-prism-fuzz/scene.xml");
    if let Ok(root) = prism_mitsuba::reader::read_scene_str(text, path, &[]) {
        let _ = prism_mitsuba::factory::build_scene(&root);
    }
});
