//! `read_image` and `write_image`: image files as numpy arrays of linear values. OpenEXR files
//! keep their named channels (Mitsuba's, Prism's or any other renderer's); PNG and JPEG hold
//! 8-bit values through the sRGB curve; Radiance HDR files are read as they are.

use std::path::{Path, PathBuf};

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::error::{IntoPyResult, to_py};
use crate::image::as_input_error;
use prism_core::error::{Error, Result};
use prism_core::image::srgb::encode_u8;
use prism_core::image::{
    ChannelImage, Channels, ExrHeader, read_bitmap, read_exr, write_exr_with, write_jpeg_u8,
    write_png_u8,
};

/// The channels `read_image` takes from an EXR file when none are named: the first of these
/// sets the file has in full.
const CHANNEL_SETS: [&[&str]; 6] = [
    &["R", "G", "B", "A"],
    &["R", "G", "B"],
    &["X", "Y", "Z", "A"],
    &["X", "Y", "Z"],
    &["Y", "A"],
    &["Y"],
];

/// The lower-case extension of `path`.
fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// Values of `width` × `height` pixels, `channels` each, as an H × W array (one channel) or an
/// H × W × C one.
fn to_array(
    py: Python<'_>,
    width: usize,
    height: usize,
    channels: usize,
    values: Vec<f32>,
) -> Bound<'_, PyAny> {
    if channels == 1 {
        Array2::from_shape_vec((height, width), values)
            .expect("one value per pixel")
            .into_pyarray(py)
            .into_any()
    } else {
        Array3::from_shape_vec((height, width, channels), values)
            .expect("`channels` values per pixel")
            .into_pyarray(py)
            .into_any()
    }
}

/// The channels of an EXR image called `names`, interleaved per pixel, or the first channel
/// missing.
fn interleave(image: &ChannelImage, names: &[String]) -> std::result::Result<Vec<f32>, String> {
    let channels = names
        .iter()
        .map(|name| image.channel(name).ok_or_else(|| name.clone()))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let pixels = image.width * image.height;
    Ok((0..pixels)
        .flat_map(|i| channels.iter().map(move |c| c[i]))
        .collect())
}

/// The linear values of an image file as a float32 array, H × W × C (H × W for one channel).
/// An EXR gives the channels `channels` names, or else the first of R, G, B, A / R, G, B /
/// X, Y, Z, A / X, Y, Z / Y, A / Y that it has, or else all of its channels in the file's
/// (alphabetical) order; half floats are widened. PNG and JPEG values are decoded from the sRGB
/// curve (alpha stays as stored, in [0, 1]); a grey image with alpha gives RGBA.
#[pyfunction]
#[pyo3(signature = (path, channels = None))]
pub fn read_image<'py>(
    py: Python<'py>,
    path: PathBuf,
    channels: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyAny>> {
    if extension(&path).as_deref() == Some("exr") {
        let image = py
            .detach(|| read_exr(&path).map_err(as_input_error))
            .into_py_result(py)?;
        let names = channels.unwrap_or_else(|| default_channels(&image));
        let values = interleave(&image, &names).map_err(|missing| {
            let available: Vec<&str> = image.channels.iter().map(|(n, _)| n.as_str()).collect();
            to_py(
                py,
                &Error::usage(format!(
                    "\"{}\" has no channel \"{missing}\"",
                    path.display()
                ))
                .with_help(format!("its channels are {}", available.join(", "))),
            )
        })?;
        return Ok(to_array(py, image.width, image.height, names.len(), values));
    }
    if channels.is_some() {
        return Err(to_py(
            py,
            &Error::usage("channels can be named only when reading an OpenEXR file"),
        ));
    }
    let bitmap = py
        .detach(|| {
            read_bitmap(&path).map(|mut bitmap| {
                bitmap.linearize();
                bitmap
            })
        })
        .into_py_result(py)?;
    Ok(to_array(
        py,
        bitmap.width,
        bitmap.height,
        bitmap.channels,
        bitmap.data,
    ))
}

/// The channels `read_image` takes from an EXR file when none are named.
fn default_channels(image: &ChannelImage) -> Vec<String> {
    let has = |name: &&str| image.channel(name).is_some();
    match CHANNEL_SETS.iter().find(|set| set.iter().all(has)) {
        Some(set) => set.iter().map(|name| name.to_string()).collect(),
        None => image
            .channels
            .iter()
            .map(|(name, _)| name.clone())
            .collect(),
    }
}

/// Writes an H × W or H × W × C float32 array of linear values: `.exr` as OpenEXR channels
/// named `channels` (default Y; Y, A; R, G, B; R, G, B, A for 1 to 4 channels), all half
/// floats when `half`; `.png` (1 to 4 channels) and `.jpg`/`.jpeg` (1 or 3) as 8-bit values
/// through the sRGB curve, alpha stored linearly.
#[pyfunction]
#[pyo3(signature = (path, array, channels = None, half = false))]
pub fn write_image(
    py: Python<'_>,
    path: PathBuf,
    array: PyReadonlyArrayDyn<'_, f32>,
    channels: Option<Vec<String>>,
    half: bool,
) -> PyResult<()> {
    let (height, width, count) = match *array.shape() {
        [h, w] => (h, w, 1),
        [h, w, c] => (h, w, c),
        ref shape => {
            return Err(to_py(
                py,
                &Error::usage(format!(
                    "write_image takes an H × W or H × W × C array, not one of shape {shape:?}"
                )),
            ));
        }
    };
    let values: Vec<f32> = array.as_array().iter().copied().collect();
    let file = ImageArray {
        width,
        height,
        count,
        values,
    };
    let result = match extension(&path).as_deref() {
        Some("exr") => {
            let names = match channels {
                Some(names) => names,
                None => default_names(count)
                    .map_err(|e| to_py(py, &e))?
                    .iter()
                    .map(|name| name.to_string())
                    .collect(),
            };
            py.detach(|| file.write_exr(&path, names, half))
        }
        Some(extension @ ("png" | "jpg" | "jpeg")) => {
            if channels.is_some() || half {
                return Err(to_py(
                    py,
                    &Error::usage("channels and half apply only to OpenEXR files"),
                ));
            }
            let jpeg = extension != "png";
            py.detach(|| file.write_8_bit(&path, jpeg))
        }
        _ => Err(Error::usage(format!(
            "cannot write \"{}\": the name must end in .exr, .png, .jpg or .jpeg",
            path.display()
        ))),
    };
    result.into_py_result(py)
}

/// The EXR channel names of an array of `count` channels.
fn default_names(count: usize) -> Result<&'static [&'static str]> {
    match count {
        1 => Ok(&["Y"]),
        2 => Ok(&["Y", "A"]),
        3 => Ok(&["R", "G", "B"]),
        4 => Ok(&["R", "G", "B", "A"]),
        _ => Err(Error::usage(format!(
            "name the {count} channels of the array with channels=[...]"
        ))),
    }
}

/// An array to write: `count` values per pixel, row-major, top row first.
struct ImageArray {
    width: usize,
    height: usize,
    count: usize,
    values: Vec<f32>,
}

impl ImageArray {
    fn write_exr(&self, path: &Path, names: Vec<String>, half: bool) -> Result<()> {
        if names.len() != self.count {
            return Err(Error::usage(format!(
                "{} channel names given for an array of {} channels",
                names.len(),
                self.count
            )));
        }
        let channels = names
            .iter()
            .enumerate()
            .map(|(c, name)| {
                let values = self.values.iter().skip(c).step_by(self.count).copied();
                (name.clone(), values.collect())
            })
            .collect();
        let image = ChannelImage {
            width: self.width,
            height: self.height,
            channels,
        };
        let header = ExrHeader {
            half_channels: if half { names } else { Vec::new() },
            attributes: Vec::new(),
        };
        write_exr_with(path, &image, &header)
    }

    /// Writes the values as an 8-bit PNG or JPEG: colour through the sRGB curve, alpha (the
    /// second of two channels, the fourth of four) as it is, each clamped to [0, 1].
    fn write_8_bit(&self, path: &Path, jpeg: bool) -> Result<()> {
        let layout = match self.count {
            1 => Channels::Luminance,
            2 => Channels::LuminanceAlpha,
            3 => Channels::Rgb,
            4 => Channels::Rgba,
            count => {
                return Err(Error::usage(format!(
                    "an 8-bit image has 1 to 4 channels, not {count}"
                )));
            }
        };
        let alpha = matches!(layout, Channels::LuminanceAlpha | Channels::Rgba);
        let bytes: Vec<u8> = self
            .values
            .chunks(self.count)
            .flat_map(|pixel| {
                pixel.iter().enumerate().map(move |(c, &v)| {
                    if alpha && c == self.count - 1 {
                        (v.clamp(0.0, 1.0) * 255.0).round() as u8
                    } else {
                        encode_u8(v)
                    }
                })
            })
            .collect();
        let too_large = || Error::usage(format!("{}×{} is too large", self.width, self.height));
        let width = u32::try_from(self.width).map_err(|_| too_large())?;
        let height = u32::try_from(self.height).map_err(|_| too_large())?;
        if jpeg {
            write_jpeg_u8(path, width, height, layout, &bytes)
        } else {
            write_png_u8(path, width, height, layout, true, &bytes)
        }
    }
}
