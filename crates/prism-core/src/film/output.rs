//! The film written out: its linear RGB and CIE XYZ values and each pixel's estimated error as
//! interleaved arrays ([`FilmImages`]), an OpenEXR image of them and an 8-bit image beside it
//! ([`super::ldr`]).
//!
//! The EXR holds the colour channels the film's `pixel_format` asks for ([`PixelFormat`]) and
//! always the statistics of the estimate: its CIE XYZ (only Y for luminance), the variance of
//! each of their means and the relative error of Y, which `prism compare`'s z-test reads. With
//! `component_format` `float16` ([`ComponentFormat`]) the colour channels and the extra channels
//! are stored as half floats; the statistics stay 32-bit, since half floats flush variances
//! below 6·10⁻⁸ to zero. The header records the render ([`RenderMetadata`]).

use std::path::Path;

use super::Film;
use super::ldr::LdrOutput;
use super::stats::{pixel_relative_error, variance_of_mean};
use crate::error::Result;
use crate::image::{
    Attribute, ChannelImage, ExrHeader, png_srgb_bytes, write_exr, write_exr_with, write_png_srgb,
};

/// The EXR channels of the image (see [`FilmImages::channels`]), which the integrator's extra
/// channels may not reuse.
pub const IMAGE_CHANNELS: [&str; 10] = [
    "R",
    "G",
    "B",
    "X",
    "Y",
    "Z",
    "variance.X",
    "variance.Y",
    "variance.Z",
    "relative_error.Y",
];

/// The name of the coverage alpha channel, which the film records as an extra channel where
/// the pixel format has one.
pub const ALPHA_CHANNEL: &str = "A";

/// The colour channels of the EXR, as Mitsuba's `hdrfilm` names them in its `pixel_format`;
/// X, Y, Z (Y alone for the luminance formats) with their statistics are always written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelFormat {
    /// R, G, B (linear sRGB) beside X, Y, Z.
    #[default]
    Rgb,
    /// R, G, B and the coverage alpha A beside X, Y, Z.
    Rgba,
    /// X, Y, Z only.
    Xyz,
    /// X, Y, Z and A.
    Xyza,
    /// Y only.
    Luminance,
    /// Y and A.
    LuminanceAlpha,
}

impl PixelFormat {
    /// Whether the film records each pixel's coverage alpha (the channel `A`).
    pub fn has_alpha(self) -> bool {
        matches!(
            self,
            PixelFormat::Rgba | PixelFormat::Xyza | PixelFormat::LuminanceAlpha
        )
    }

    /// Which of [`IMAGE_CHANNELS`] the EXR holds.
    fn keeps(self, channel: &str) -> bool {
        match self {
            PixelFormat::Rgb | PixelFormat::Rgba => true,
            PixelFormat::Xyz | PixelFormat::Xyza => !matches!(channel, "R" | "G" | "B"),
            PixelFormat::Luminance | PixelFormat::LuminanceAlpha => {
                matches!(channel, "Y" | "variance.Y" | "relative_error.Y")
            }
        }
    }
}

/// How the EXR stores its values, as Mitsuba's `component_format` names it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ComponentFormat {
    /// Half floats for the colour and extra channels, 32-bit floats for the statistics.
    Float16,
    #[default]
    Float32,
}

/// The film's EXR: which channels it holds and how it stores them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExrOutput {
    pub pixel_format: PixelFormat,
    pub component_format: ComponentFormat,
}

/// The channels that stay 32-bit in a half-float EXR: the estimate's statistics.
const STATISTICS_CHANNELS: [&str; 4] =
    ["variance.X", "variance.Y", "variance.Z", "relative_error.Y"];

/// What the EXR's header records of a render: attributes `prism.spp` (int), `prism.seed`
/// (text, since EXR has no 64-bit integers), `prism.seconds` (double; absent for a merge of
/// renders) and `prism.version` (text, the renderer's version).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderMetadata {
    pub spp: u32,
    pub seed: u64,
    pub seconds: Option<f64>,
}

impl RenderMetadata {
    /// The header attributes.
    pub fn attributes(&self) -> Vec<(String, Attribute)> {
        let spp = i32::try_from(self.spp).unwrap_or(i32::MAX);
        let mut attributes = vec![
            ("prism.spp".into(), Attribute::Int(spp)),
            ("prism.seed".into(), Attribute::Text(self.seed.to_string())),
            (
                "prism.version".into(),
                Attribute::Text(env!("CARGO_PKG_VERSION").into()),
            ),
        ];
        if let Some(seconds) = self.seconds {
            attributes.push(("prism.seconds".into(), Attribute::Double(seconds)));
        }
        attributes
    }

    /// The metadata an EXR's header records, where it has the samples and the seed.
    pub fn of(header: &ExrHeader) -> Option<RenderMetadata> {
        let spp = match header.attribute("prism.spp")? {
            Attribute::Int(spp) => u32::try_from(*spp).ok()?,
            _ => return None,
        };
        let seed = match header.attribute("prism.seed")? {
            Attribute::Text(seed) => seed.parse().ok()?,
            _ => return None,
        };
        let seconds = match header.attribute("prism.seconds") {
            Some(Attribute::Double(seconds)) => Some(*seconds),
            _ => None,
        };
        Some(RenderMetadata { spp, seed, seconds })
    }
}

/// A film's values, row-major with the top row first, each array interleaved per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmImages {
    pub width: usize,
    pub height: usize,
    /// Linear sRGB (D65 white), three values per pixel.
    pub rgb: Vec<f32>,
    /// CIE 1931 XYZ, three values per pixel.
    pub xyz: Vec<f32>,
    /// The estimated variance of each pixel's mean of X, Y and Z (see [`super::stats`]), three
    /// values per pixel.
    pub variance: Vec<f32>,
    /// The relative standard error of each pixel's luminance, one value per pixel.
    pub relative_error: Vec<f32>,
}

impl FilmImages {
    /// The images of a film's crop window.
    pub fn of(film: &Film) -> FilmImages {
        let xyz = film.xyz();
        let rgb = film.linear_srgb();
        FilmImages {
            width: film.crop.size.x as usize,
            height: film.crop.size.y as usize,
            rgb: rgb.iter().flatten().copied().collect(),
            xyz: xyz.iter().flatten().copied().collect(),
            variance: film
                .pixels
                .iter()
                .flat_map(|p| [0, 1, 2].map(|c| variance_of_mean(p, c) as f32))
                .collect(),
            relative_error: film
                .pixels
                .iter()
                .map(|p| pixel_relative_error(p) as f32)
                .collect(),
        }
    }

    /// The images as named channels: `R`, `G`, `B` (linear sRGB), `X`, `Y`, `Z` (CIE 1931),
    /// `variance.X`, `variance.Y`, `variance.Z` and `relative_error.Y`.
    pub fn channels(&self) -> ChannelImage {
        let channel =
            |values: &[f32], c: usize| values.iter().skip(c).step_by(3).copied().collect();
        let values = [
            channel(&self.rgb, 0),
            channel(&self.rgb, 1),
            channel(&self.rgb, 2),
            channel(&self.xyz, 0),
            channel(&self.xyz, 1),
            channel(&self.xyz, 2),
            channel(&self.variance, 0),
            channel(&self.variance, 1),
            channel(&self.variance, 2),
            self.relative_error.clone(),
        ];
        ChannelImage {
            width: self.width,
            height: self.height,
            channels: IMAGE_CHANNELS
                .iter()
                .map(|name| name.to_string())
                .zip(values)
                .collect(),
        }
    }

    /// The images of channels named as [`FilmImages::channels`] names them (an EXR that Prism
    /// wrote); the error is the name of the first channel missing.
    pub fn from_channels(image: &ChannelImage) -> std::result::Result<FilmImages, &'static str> {
        let channel = |name: &'static str| image.channel(name).ok_or(name);
        let interleave = |names: [&'static str; 3]| -> std::result::Result<Vec<f32>, &'static str> {
            let [a, b, c] = [channel(names[0])?, channel(names[1])?, channel(names[2])?];
            Ok((0..a.len()).flat_map(|i| [a[i], b[i], c[i]]).collect())
        };
        Ok(FilmImages {
            width: image.width,
            height: image.height,
            rgb: interleave(["R", "G", "B"])?,
            xyz: interleave(["X", "Y", "Z"])?,
            variance: interleave(["variance.X", "variance.Y", "variance.Z"])?,
            relative_error: channel("relative_error.Y")?.to_vec(),
        })
    }

    /// Writes the OpenEXR image of [`FilmImages::channels`].
    pub fn write_exr(&self, path: &Path) -> Result<()> {
        write_exr(path, &self.channels())
    }

    /// The EXR image of [`FilmImages::channels`] and the extra channels `aovs` (name, one value
    /// per pixel) as `output` asks, with `metadata` in its header.
    pub fn exr(
        &self,
        aovs: Vec<(String, Vec<f32>)>,
        output: &ExrOutput,
        metadata: Option<&RenderMetadata>,
    ) -> (ChannelImage, ExrHeader) {
        let mut image = self.channels();
        image
            .channels
            .retain(|(name, _)| output.pixel_format.keeps(name));
        image.channels.extend(aovs);
        let half_channels = match output.component_format {
            ComponentFormat::Float32 => Vec::new(),
            ComponentFormat::Float16 => (image.channels.iter())
                .map(|(name, _)| name.clone())
                .filter(|name| !STATISTICS_CHANNELS.contains(&name.as_str()))
                .collect(),
        };
        let header = ExrHeader {
            half_channels,
            attributes: metadata.map(RenderMetadata::attributes).unwrap_or_default(),
        };
        (image, header)
    }

    /// Writes the RGB image as an 8-bit sRGB PNG.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        write_png_srgb(path, self.width, self.height, &self.rgb)
    }

    /// The bytes of the PNG file [`FilmImages::write_png`] writes.
    pub fn png_bytes(&self) -> std::io::Result<Vec<u8>> {
        png_srgb_bytes(self.width, self.height, &self.rgb)
    }
}

/// Writes the film as an EXR and as an sRGB PNG (see [`FilmImages`]); the EXR also holds the
/// integrator's extra channels under their own names.
pub fn write_images(film: &Film, exr_path: &Path, png_path: &Path) -> Result<()> {
    let output = ImageOutput {
        exr: ExrOutput::default(),
        ldr: LdrOutput::default(),
        metadata: None,
    };
    write_images_with(film, exr_path, png_path, &output)
}

/// How a render's images are written: the EXR as the film asks, the 8-bit image, and what the
/// EXR's header records.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageOutput {
    pub exr: ExrOutput,
    pub ldr: LdrOutput,
    pub metadata: Option<RenderMetadata>,
}

/// As [`write_images`], with the EXR and the 8-bit image (to `ldr_path`) as `output` says.
pub fn write_images_with(
    film: &Film,
    exr_path: &Path,
    ldr_path: &Path,
    output: &ImageOutput,
) -> Result<()> {
    let aovs = (film.aov_names.iter().cloned())
        .enumerate()
        .map(|(c, name)| (name, film.aov(c)))
        .collect();
    let (image, header) = FilmImages::of(film).exr(aovs, &output.exr, output.metadata.as_ref());
    write_exr_with(exr_path, &image, &header)?;
    let alpha = (film.aov_names.iter())
        .position(|name| name == ALPHA_CHANNEL)
        .map(|c| film.aov(c));
    output.ldr.write(
        ldr_path,
        film.crop.size.x,
        film.crop.size.y,
        &film.linear_srgb(),
        alpha.as_deref(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::CropWindow;
    use glam::UVec2;

    #[test]
    fn channels_read_back_as_the_same_images() {
        let size = UVec2::new(3, 2);
        let mut film = Film::new(
            size,
            CropWindow {
                offset: UVec2::ZERO,
                size,
            },
        );
        for (i, pixel) in film.pixels.iter_mut().enumerate() {
            let v = i as f32;
            pixel.add([v, 2.0 * v, 0.5]);
            pixel.add([v + 1.0, v, 0.25]);
        }
        let images = FilmImages::of(&film);
        assert_eq!(images.rgb.len(), 18);
        assert_eq!(images.relative_error.len(), 6);
        assert_eq!(
            FilmImages::from_channels(&images.channels()),
            Ok(images.clone())
        );
        let mut without_variance = images.channels();
        without_variance
            .channels
            .retain(|(name, _)| name != "variance.Y");
        assert_eq!(
            FilmImages::from_channels(&without_variance),
            Err("variance.Y")
        );
    }

    fn small_images() -> FilmImages {
        let size = UVec2::new(2, 2);
        let mut film = Film::new(
            size,
            CropWindow {
                offset: UVec2::ZERO,
                size,
            },
        );
        for (i, pixel) in film.pixels.iter_mut().enumerate() {
            pixel.add([i as f32, 1.0, 0.5]);
            pixel.add([0.25, i as f32, 0.5]);
        }
        FilmImages::of(&film)
    }

    fn names(image: &ChannelImage) -> Vec<&str> {
        let mut names: Vec<&str> = image.channels.iter().map(|(n, _)| n.as_str()).collect();
        names.sort();
        names
    }

    /// Each pixel format keeps its colour channels and the statistics; the extra channels
    /// (the alpha among them) follow whatever the format.
    #[test]
    fn pixel_formats_choose_the_channels() {
        let images = small_images();
        let alpha = || vec![("A".to_string(), vec![1.0; 4])];
        let exr = |pixel_format, aovs| {
            let output = ExrOutput {
                pixel_format,
                component_format: ComponentFormat::Float32,
            };
            images.exr(aovs, &output, None).0
        };
        let statistics = ["variance.X", "variance.Y", "variance.Z", "relative_error.Y"];
        let mut rgba = vec!["A", "B", "G", "R", "X", "Y", "Z"];
        rgba.extend(statistics);
        rgba.sort();
        assert_eq!(names(&exr(PixelFormat::Rgba, alpha())), rgba);
        let mut xyz = vec!["X", "Y", "Z"];
        xyz.extend(statistics);
        xyz.sort();
        assert_eq!(names(&exr(PixelFormat::Xyz, Vec::new())), xyz);
        assert_eq!(
            names(&exr(PixelFormat::LuminanceAlpha, alpha())),
            ["A", "Y", "relative_error.Y", "variance.Y"]
        );
        let rgb = exr(PixelFormat::Rgb, Vec::new());
        assert_eq!(rgb, images.channels());
    }

    /// Half floats hold the colour and extra channels, never the statistics; the metadata
    /// reads back from the header.
    #[test]
    fn half_floats_leave_the_statistics_at_32_bits() {
        let output = ExrOutput {
            pixel_format: PixelFormat::Rgb,
            component_format: ComponentFormat::Float16,
        };
        let metadata = RenderMetadata {
            spp: 16,
            seed: u64::MAX,
            seconds: Some(2.5),
        };
        let aovs = vec![("albedo.R".to_string(), vec![0.5; 4])];
        let (image, header) = small_images().exr(aovs, &output, Some(&metadata));
        let mut half = header.half_channels.clone();
        half.sort();
        assert_eq!(half, ["B", "G", "R", "X", "Y", "Z", "albedo.R"]);
        assert_eq!(image.channels.len(), 11);
        assert_eq!(RenderMetadata::of(&header), Some(metadata));
        let version = header.attribute("prism.version");
        assert_eq!(
            version,
            Some(&Attribute::Text(env!("CARGO_PKG_VERSION").into()))
        );
    }
}
