//! Image files: decoding the images scenes reference (PNG, JPEG, OpenEXR, Radiance HDR, BMP, TGA,
//! PPM/PGM, PFM) into floating-point pixels, writing renders as OpenEXR (linear) and PNG (sRGB),
//! and the sRGB transfer curve. This module sits below everything that uses images (textures, environment
//! maps, the film) and knows nothing of them.
//!
//! Writers go through [`write_atomically`]: the file is written to `<path>.tmp` and renamed over
//! `<path>` only once complete, so an error (a full disk, say) or a reader looking at a checkpoint
//! never sees a truncated image under the final name.

pub mod bitmap;
pub mod compare;
pub mod exr;
pub mod pfm;
pub mod png;
pub mod srgb;

use std::fs::{self, File};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

pub use bitmap::{
    Bitmap, Encoding, FileFormat, MAX_PIXELS, decode_bitmap, decode_bitmap_file, read_bitmap,
};
pub use exr::{
    Attribute, ChannelImage, ExrHeader, read_exr, read_exr_with_header, write_exr, write_exr_with,
};
pub use png::{Channels, png_srgb_bytes, write_jpeg_u8, write_png_srgb, write_png_u8};

use crate::error::{Error, Result};

/// Writes a file through `write`, first to `<path>.tmp` and then renaming it over `path`; on error
/// the temporary file is removed and the error names `path`.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<()> {
    let mut temporary = path.as_os_str().to_owned();
    temporary.push(".tmp");
    let temporary = PathBuf::from(temporary);
    let result = File::create(&temporary)
        .and_then(|file| {
            let mut writer = BufWriter::new(file);
            write(&mut writer)?;
            writer.flush()
        })
        .and_then(|()| fs::rename(&temporary, path));
    result.map_err(|err| {
        // The temporary file may not exist (if creating it failed); nothing else to clean up.
        let _ = fs::remove_file(&temporary);
        Error::io(path, &err, "write")
    })
}

#[cfg(test)]
pub(crate) mod test_support {
    use std::path::PathBuf;

    /// A fresh scratch directory for one test.
    pub fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("prism-image-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }
}
