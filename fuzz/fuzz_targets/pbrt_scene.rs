//! Any text given as a pbrt-v4 scene must be read and built into a scene, or refused with an
//! error; never a panic. Files the scene names (`Include`, meshes, images) are looked up next to
//! a virtual scene file in an empty folder, so only the pbrt text itself is being tested.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("/nonexistent-prism-fuzz/scene.pbrt");
    if let Ok(scene) = prism_mitsuba::pbrt::read_pbrt_str(text, path) {
        let _ = prism_mitsuba::factory::build_scene(&scene.root);
    }
});
