//! Any bytes given as a Radiance RGBE (.hdr) image (`decode_bitmap` with `FileFormat::RadianceHdr`) give a bitmap or an
//! error; never a panic, and never an allocation for more pixels than the limit allows. A bitmap
//! that decodes holds exactly width × height × channels finite values.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_core::image::{FileFormat, decode_bitmap};

/// A lower limit than a scene's, so that a declared size the data cannot back stays within the
/// fuzzer's memory limit.
const MAX_PIXELS: u64 = 1 << 20;

fuzz_target!(|data: &[u8]| {
    if let Ok(bitmap) = decode_bitmap(data, FileFormat::RadianceHdr, MAX_PIXELS) {
        assert_eq!(
            bitmap.data.len(),
            bitmap.width * bitmap.height * bitmap.channels
        );
        assert!(bitmap.data.iter().all(|v| v.is_finite()));
    }
});
