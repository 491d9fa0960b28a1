//! OpenEXR files of named 32-bit float channels: the renderer's images and the references it
//! compares against.

use std::io;
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, Layer,
    LayerAttributes, LineOrder, ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
};

use super::write_atomically;
use crate::error::{Error, Result};

/// An image of named f32 channels, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelImage {
    pub width: usize,
    pub height: usize,
    pub channels: Vec<(String, Vec<f32>)>,
}

impl ChannelImage {
    /// The samples of the channel called `name`, if there is one.
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        self.channels
            .iter()
            .find(|(channel, _)| channel == name)
            .map(|(_, samples)| samples.as_slice())
    }
}

/// How EXR pixel data is compressed: ZIP over blocks of 16 scanlines, which every EXR reader
/// supports. The random low mantissa bits of rendered f32 data hardly compress with any method,
/// and ZIP writes fastest of those that compress at all.
const EXR_COMPRESSION: Compression = Compression::ZIP16;

/// Writes 32-bit float channels to an OpenEXR file: one layer, scanlines in increasing y, ZIP
/// compression (see `EXR_COMPRESSION`). Channel names are stored as given; the file lists them
/// alphabetically, as the format requires.
pub fn write_exr(path: &Path, image: &ChannelImage) -> Result<()> {
    let invalid = |message: String| Error::io(path, &io::Error::other(message), "write");
    let pixels = image.width * image.height;
    if pixels == 0 || image.channels.is_empty() {
        return Err(invalid(format!(
            "an EXR image needs pixels and channels, got {}x{} with {} channels",
            image.width,
            image.height,
            image.channels.len()
        )));
    }
    let mut channels = SmallVec::new();
    for (name, samples) in &image.channels {
        if samples.len() != pixels {
            return Err(invalid(format!(
                "channel \"{name}\" has {} samples for {}x{} pixels",
                samples.len(),
                image.width,
                image.height
            )));
        }
        let text = Text::new_or_none(name)
            .ok_or_else(|| invalid(format!("channel name \"{name}\" is not Latin-1 text")))?;
        channels.push(AnyChannel::new(text, FlatSamples::F32(samples.clone())));
    }
    let encoding = Encoding {
        compression: EXR_COMPRESSION,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (image.width, image.height),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(channels),
    );
    let exr_image = Image::from_layer(layer);
    write_atomically(path, |writer| {
        exr_image.write().to_buffered(writer).map_err(exr_to_io)
    })
}

/// Reads every channel of an OpenEXR file as f32 (half and u32 channels converted), at the
/// largest resolution level, over the data window. A multi-part file whose parts share one size
/// gives channels named `part.channel`. A missing or corrupt file is an error naming the file.
pub fn read_exr(path: &Path) -> Result<ChannelImage> {
    let read_error = |err| Error::io(path, &exr_to_io(err), "read");
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(path)
        .map_err(read_error)?;

    let layers = &image.layer_data;
    let size = layers.first().map(|layer| layer.size);
    let (Some(size), true) = (size, layers.iter().all(|layer| Some(layer.size) == size)) else {
        return Err(read_error(exr::error::Error::NotSupported(
            "parts of different sizes (or no parts at all)".into(),
        )));
    };
    let mut channels = Vec::new();
    for layer in layers {
        let prefix = match &layer.attributes.layer_name {
            Some(name) if layers.len() > 1 => format!("{name}."),
            _ => String::new(),
        };
        for channel in &layer.channel_data.list {
            let samples = channel.sample_data.values_as_f32().collect();
            channels.push((format!("{prefix}{}", channel.name), samples));
        }
    }
    Ok(ChannelImage {
        width: size.width(),
        height: size.height(),
        channels,
    })
}

/// An exr error as an I/O error: file-system errors pass through, format errors become
/// `InvalidData` or `Unsupported`.
fn exr_to_io(err: exr::error::Error) -> io::Error {
    use exr::error::Error as ExrError;
    match err {
        ExrError::Io(err) => err,
        ExrError::Invalid(message) => io::Error::new(
            io::ErrorKind::InvalidData,
            format!("invalid OpenEXR data ({message})"),
        ),
        ExrError::NotSupported(message) => io::Error::new(
            io::ErrorKind::Unsupported,
            format!("unsupported OpenEXR feature ({message})"),
        ),
        ExrError::Aborted => io::Error::from(io::ErrorKind::Interrupted),
    }
}

#[cfg(test)]
mod tests {
    use std::fs;

    use super::*;
    use crate::image::test_support::scratch_dir;
    use crate::sampling::rng::Pcg32;

    /// An image of the given channels filled with random values, including awkward ones.
    fn random_image(width: usize, height: usize, names: &[&str], seed: u64) -> ChannelImage {
        let mut rng = Pcg32::seeded(seed);
        let channels = names
            .iter()
            .map(|name| {
                let mut samples: Vec<f32> = (0..width * height)
                    .map(|_| (rng.next_f32() - 0.25) * 1e3 * rng.next_f32().powi(8))
                    .collect();
                samples[0] = f32::MIN_POSITIVE / 4.0; // subnormal
                samples[1] = -0.0;
                samples[2] = f32::MAX;
                (name.to_string(), samples)
            })
            .collect();
        ChannelImage {
            width,
            height,
            channels,
        }
    }

    fn assert_bit_exact(written: &ChannelImage, read: &ChannelImage) {
        assert_eq!((read.width, read.height), (written.width, written.height));
        assert_eq!(read.channels.len(), written.channels.len());
        for (name, samples) in &written.channels {
            let back = read
                .channel(name)
                .unwrap_or_else(|| panic!("channel {name} missing"));
            let bits = |values: &[f32]| values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(back), bits(samples), "channel {name}");
        }
    }

    #[test]
    fn exr_round_trip_is_bit_exact() {
        let dir = scratch_dir("exr-round-trip");
        for names in [&["R", "G", "B"][..], &["R", "G", "B", "X", "Y", "Z"]] {
            let image = random_image(7, 5, names, names.len() as u64);
            let path = dir.join(format!("{}.exr", names.len()));
            write_exr(&path, &image).unwrap();
            assert!(!dir.join(format!("{}.exr.tmp", names.len())).exists());
            assert_bit_exact(&image, &read_exr(&path).unwrap());
        }
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn multi_part_exr_channels_are_prefixed_with_the_part_name() {
        let part = |name: &str, value: f32| {
            let y = AnyChannel::new("Y", FlatSamples::F32(vec![value; 6]));
            let channels = AnyChannels::sort(SmallVec::from_vec(vec![y]));
            Layer::new(
                (3, 2),
                LayerAttributes::named(name),
                Encoding::default(),
                channels,
            )
        };
        let attributes = exr::prelude::ImageAttributes::with_size((3, 2));
        let image = Image::from_layers(attributes, vec![part("a", 1.0), part("b", 2.0)]);
        let dir = scratch_dir("exr-multi-part");
        let path = dir.join("parts.exr");
        image.write().to_file(&path).unwrap();

        let read = read_exr(&path).unwrap();
        assert_eq!((read.width, read.height), (3, 2));
        assert_eq!(read.channel("a.Y"), Some(&[1.0; 6][..]));
        assert_eq!(read.channel("b.Y"), Some(&[2.0; 6][..]));
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn exr_write_rejects_a_short_channel() {
        let dir = scratch_dir("exr-short");
        let mut image = random_image(4, 3, &["R", "G"], 1);
        image.channels[1].1.pop();
        let path = dir.join("short.exr");
        let err = write_exr(&path, &image).unwrap_err();
        assert!(err.message.contains("short.exr"), "{err}");
        assert!(!path.exists());
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn corrupt_or_missing_exr_is_an_error_naming_the_file() {
        let dir = scratch_dir("exr-corrupt");
        let good = dir.join("good.exr");
        write_exr(&good, &random_image(16, 16, &["R", "G", "B"], 2)).unwrap();
        let bytes = fs::read(&good).unwrap();

        let truncated = dir.join("truncated.exr");
        fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
        let garbage = dir.join("garbage.exr");
        let mut scrambled = bytes.clone();
        let mut rng = Pcg32::seeded(3);
        for byte in &mut scrambled[8..] {
            *byte = rng.next_u32() as u8;
        }
        fs::write(&garbage, &scrambled).unwrap();
        let not_exr = dir.join("not-exr.exr");
        fs::write(&not_exr, b"P3 1 1 255 0 0 0").unwrap();
        let missing = dir.join("missing.exr");

        for path in [&truncated, &garbage, &not_exr, &missing] {
            let err = read_exr(path).unwrap_err();
            let file_name = path.file_name().unwrap().to_str().unwrap();
            assert!(err.to_string().contains(file_name), "{err}");
        }
        fs::remove_dir_all(dir).unwrap();
    }

    /// An EXR written by another renderer (Tungsten's reference of Bitterli's Cornell box, half
    /// floats) reads, with the channel means the OpenEXR library's Python reader gives it.
    #[test]
    fn reads_an_exr_written_by_another_renderer() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes/bitterli-cornell-box/TungstenRender.exr");
        let image = read_exr(&path).unwrap();
        let mean = |name: &str| {
            let samples = image.channel(name).unwrap();
            samples.iter().map(|&v| f64::from(v)).sum::<f64>() / samples.len() as f64
        };
        let means = [mean("R"), mean("G"), mean("B")];
        for (got, want) in means.iter().zip([0.1963, 0.1275, 0.0361]) {
            assert!((got - want).abs() < 5e-4, "{means:?}");
        }
    }
}
