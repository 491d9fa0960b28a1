//! OpenEXR files of named float channels: the renderer's images and the references it compares
//! against. Each channel is stored as a 32-bit float or, where asked, as a 16-bit half float;
//! the header may carry attributes of its own (the render's samples per pixel, seed, ...).

use std::io;
use std::path::Path;

use exr::meta::attribute::AttributeValue;
use exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, Layer,
    LayerAttributes, LineOrder, ReadChannels, ReadLayers, SmallVec, Text, WritableImage, f16,
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

/// An attribute of an EXR header, of the kinds Prism writes and reads.
#[derive(Clone, Debug, PartialEq)]
pub enum Attribute {
    Int(i32),
    Double(f64),
    Text(String),
}

/// What an EXR file holds beside its channels' values: which channels are stored as half
/// floats, and the header's own attributes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExrHeader {
    /// Channels stored as IEEE 754 binary16 (11 significant bits, largest finite value 65504,
    /// smallest normal 6.1·10⁻⁵; larger values become infinite); the others are 32-bit floats.
    pub half_channels: Vec<String>,
    /// Attributes by name, beside the ones every EXR file has.
    pub attributes: Vec<(String, Attribute)>,
}

impl ExrHeader {
    /// The attribute called `name`, if there is one.
    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.attributes
            .iter()
            .find(|(attribute, _)| attribute == name)
            .map(|(_, value)| value)
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
    write_exr_with(path, image, &ExrHeader::default())
}

/// As [`write_exr`], with the channels `header` names stored as half floats (rounded to the
/// nearest) and its attributes in the file's header.
pub fn write_exr_with(path: &Path, image: &ChannelImage, header: &ExrHeader) -> Result<()> {
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
        let samples = if header.half_channels.contains(name) {
            FlatSamples::F16(samples.iter().map(|&v| f16::from_f32(v)).collect())
        } else {
            FlatSamples::F32(samples.clone())
        };
        channels.push(AnyChannel::new(text, samples));
    }
    let mut attributes = LayerAttributes::default();
    for (name, value) in &header.attributes {
        let text = |value: &str| {
            Text::new_or_none(value)
                .ok_or_else(|| invalid(format!("attribute \"{value}\" is not Latin-1 text")))
        };
        let value = match value {
            Attribute::Int(v) => AttributeValue::I32(*v),
            Attribute::Double(v) => AttributeValue::F64(*v),
            Attribute::Text(v) => AttributeValue::Text(text(v)?),
        };
        attributes.other.insert(text(name)?, value);
    }
    let encoding = Encoding {
        compression: EXR_COMPRESSION,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (image.width, image.height),
        attributes,
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
    read_exr_with_header(path).map(|(image, _)| image)
}

/// As [`read_exr`], with the half channels and the integer, floating-point and text attributes
/// of the header (of every part).
pub fn read_exr_with_header(path: &Path) -> Result<(ChannelImage, ExrHeader)> {
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
    let mut header = ExrHeader::default();
    let shared = image.attributes.other.iter();
    for (name, value) in shared.chain(layers.iter().flat_map(|l| l.attributes.other.iter())) {
        let value = match value {
            AttributeValue::I32(v) => Attribute::Int(*v),
            AttributeValue::F32(v) => Attribute::Double(f64::from(*v)),
            AttributeValue::F64(v) => Attribute::Double(*v),
            AttributeValue::Text(v) => Attribute::Text(v.to_string()),
            _ => continue,
        };
        header.attributes.push((name.to_string(), value));
    }
    for layer in layers {
        let prefix = match &layer.attributes.layer_name {
            Some(name) if layers.len() > 1 => format!("{name}."),
            _ => String::new(),
        };
        for channel in &layer.channel_data.list {
            let name = format!("{prefix}{}", channel.name);
            if matches!(channel.sample_data, FlatSamples::F16(_)) {
                header.half_channels.push(name.clone());
            }
            let samples = channel.sample_data.values_as_f32().collect();
            channels.push((name, samples));
        }
    }
    let image = ChannelImage {
        width: size.width(),
        height: size.height(),
        channels,
    };
    Ok((image, header))
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

    /// Half channels hold the nearest binary16 value of each sample (exactly those of values
    /// that have one); the attributes come back as written.
    #[test]
    fn half_channels_and_attributes_round_trip() {
        let dir = scratch_dir("exr-half");
        let mut image = random_image(6, 4, &["R", "G", "variance.Y"], 4);
        image.channels[0].1[3] = 0.1;
        image.channels[1].1[3] = 1.5;
        let header = ExrHeader {
            half_channels: vec!["G".into(), "R".into()],
            attributes: vec![
                ("prism.seconds".into(), Attribute::Double(1.25)),
                ("prism.spp".into(), Attribute::Int(64)),
                ("prism.version".into(), Attribute::Text("1.2.3".into())),
            ],
        };
        let path = dir.join("half.exr");
        write_exr_with(&path, &image, &header).unwrap();
        let (read, read_header) = read_exr_with_header(&path).unwrap();

        let mut half_channels = read_header.half_channels.clone();
        half_channels.sort();
        assert_eq!(half_channels, header.half_channels);
        let mut attributes = read_header.attributes.clone();
        attributes.sort_by(|a, b| a.0.cmp(&b.0));
        assert_eq!(attributes, header.attributes);
        assert_eq!(
            read_header.attribute("prism.spp"),
            Some(&Attribute::Int(64))
        );

        for (name, samples) in &image.channels {
            let back = read.channel(name).unwrap();
            let half = name != "variance.Y";
            for (&v, &b) in samples.iter().zip(back) {
                let expected = if half { f16::from_f32(v).to_f32() } else { v };
                assert_eq!(b.to_bits(), expected.to_bits(), "{name}: {v}");
            }
        }
        assert_eq!(read.channel("G").unwrap()[3], 1.5);
        assert_eq!(read.channel("R").unwrap()[3], 0.099975586);
        assert_eq!(read.channel("R").unwrap()[2], f32::INFINITY);
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
