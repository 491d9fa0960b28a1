//! Any bytes given as a render state (`--resume`, `prism merge`) decode or are refused; never a
//! panic, and never an allocation sized by a count the file cannot back. The CRC makes random
//! bytes fail early, so the target also tries the bytes with a correct CRC appended, which lets
//! the fuzzer reach the decoder proper. A progressive integrator's state is opaque bytes at this
//! level; its integrator reads them with size checks of its own when a render resumes or a merge
//! combines them (`render::sppm`'s tests try every truncation and a flipped bit in every byte).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use prism_core::render::state::RenderState;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.state");
    let _ = RenderState::decode(data, path);
    let mut with_checksum = data.to_vec();
    with_checksum.extend_from_slice(&crc32fast::hash(data).to_le_bytes());
    let _ = RenderState::decode(&with_checksum, path);
});
