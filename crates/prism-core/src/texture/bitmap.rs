//! Mitsuba's `bitmap` texture: an image (PNG, JPEG, OpenEXR, Radiance HDR) looked up at the
//! surface's texture coordinates.
//!
//! ```xml
//! <texture type="bitmap" name="reflectance">
//!     <string name="filename" value="wood.jpg"/>
//!     <string name="filter_type" value="bilinear"/>   <!-- or nearest -->
//!     <string name="wrap_mode" value="repeat"/>       <!-- or mirror, clamp -->
//!     <boolean name="raw" value="false"/>             <!-- true: no sRGB decoding -->
//!     <transform name="to_uv"> <scale x="4" y="4"/> </transform>
//! </texture>
//! ```
//!
//! As in Mitsuba 3 (`src/textures/bitmap.cpp`): 8- and 16-bit images are decoded from sRGB to
//! linear values unless `raw` is set; (u, v) = (0, 0) is the top-left corner of the image and
//! texel centres lie at ((i + ½)/width, (j + ½)/height); bilinear filtering interpolates the
//! four nearest texels, `nearest` takes the one containing the point. Colour textures are
//! upsampled per texel (the Jakob–Hanika coefficient table, components clamped to [0, 1] like
//! Mitsuba's `srgb_model_fetch`) and the four texels' spectra are interpolated. Alpha channels
//! are ignored. A colour image read as a number gives the luminance of its linear RGB (where
//! Mitsuba 3 refuses a non-raw colour image).

use glam::{Vec2, Vec3};

use super::{TexturePoint, TextureValues, UvTransform, mean_over_cells};
use crate::image::Bitmap;
use crate::spectrum::rgb::{RgbSigmoidPolynomial, RgbToSpectrumTable};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// How texels are interpolated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilterType {
    Bilinear,
    Nearest,
}

/// How coordinates outside [0, 1] are mapped into the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WrapMode {
    Repeat,
    Mirror,
    Clamp,
}

/// What each texel holds, chosen by how the texture is used.
#[derive(Clone, Debug, PartialEq)]
pub enum Texels {
    /// One value per texel (grey images, or luminance when a number is wanted).
    Scalar(Vec<f32>),
    /// Upsampled colours (read as spectra).
    Spectral(Vec<RgbSigmoidPolynomial>),
    /// Raw RGB (normal maps).
    Rgb(Vec<[f32; 3]>),
    /// Emitted colours: each texel's spectrum is `scale` times its polynomial. As Mitsuba 3
    /// reads an emitter's bitmap, a colour is upsampled as a reflectance would be, with no D65
    /// factor (unlike an `<rgb>` radiance); where Mitsuba clamps components above 1 to 1,
    /// brighter texels keep their value here.
    Emission(Vec<EmissionTexel>),
}

/// An emitted colour: the spectrum `scale · polynomial(λ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionTexel {
    pub polynomial: RgbSigmoidPolynomial,
    pub scale: f32,
}

impl EmissionTexel {
    /// The texel of linear sRGB colour `rgb` (components at least 0): a colour within [0, 1]
    /// fitted as a reflectance; a brighter one divided by twice its largest component, which
    /// keeps the fit inside the table, and scaled back (Mitsuba's unbounded upsampling).
    fn new(table: &RgbToSpectrumTable, rgb: [f32; 3]) -> EmissionTexel {
        let max = rgb[0].max(rgb[1]).max(rgb[2]);
        if max <= 1.0 {
            return EmissionTexel {
                polynomial: table.fetch(rgb),
                scale: 1.0,
            };
        }
        let scale = 2.0 * max;
        EmissionTexel {
            polynomial: table.fetch(rgb.map(|c| c / scale)),
            scale,
        }
    }

    /// The linear sRGB colour the texel stands for.
    fn linear_srgb(&self) -> [f32; 3] {
        self.polynomial.linear_srgb().map(|c| c * self.scale)
    }
}

/// How a bitmap will be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureUse {
    Spectral,
    Scalar,
    Rgb,
    /// Emitted radiance (see [`Texels::Emission`]).
    Emission,
}

#[derive(Clone, Debug, PartialEq)]
pub struct BitmapTexture {
    pub width: usize,
    pub height: usize,
    pub texels: Texels,
    pub filter: FilterType,
    pub wrap: WrapMode,
    pub to_uv: UvTransform,
}

/// Luminance Y of linear sRGB (the middle row of the sRGB → XYZ matrix).
fn luminance(rgb: [f32; 3]) -> f32 {
    0.212_672_9 * rgb[0] + 0.715_152_2 * rgb[1] + 0.072_175 * rgb[2]
}

impl BitmapTexture {
    /// A texture from decoded pixels (already linearised when `raw` is not set).
    pub fn new(
        bitmap: &Bitmap,
        usage: TextureUse,
        filter: FilterType,
        wrap: WrapMode,
        to_uv: UvTransform,
    ) -> BitmapTexture {
        let channels = bitmap.channels;
        let pixels = bitmap.data.chunks_exact(channels);
        let rgb = |p: &[f32]| -> [f32; 3] {
            if channels >= 3 {
                [p[0], p[1], p[2]]
            } else {
                [p[0]; 3]
            }
        };
        let texels = match usage {
            TextureUse::Scalar => Texels::Scalar(
                pixels
                    .map(|p| {
                        if channels >= 3 {
                            luminance(rgb(p))
                        } else {
                            p[0]
                        }
                    })
                    .collect(),
            ),
            TextureUse::Spectral if channels < 3 => Texels::Scalar(pixels.map(|p| p[0]).collect()),
            TextureUse::Spectral => {
                let table = RgbToSpectrumTable::srgb();
                Texels::Spectral(pixels.map(|p| table.fetch(rgb(p))).collect())
            }
            TextureUse::Rgb => Texels::Rgb(pixels.map(rgb).collect()),
            TextureUse::Emission => {
                let table = RgbToSpectrumTable::srgb();
                Texels::Emission(
                    pixels
                        .map(|p| EmissionTexel::new(table, rgb(p).map(|c| c.max(0.0))))
                        .collect(),
                )
            }
        };
        BitmapTexture {
            width: bitmap.width,
            height: bitmap.height,
            texels,
            filter,
            wrap,
            to_uv,
        }
    }

    /// The texel index for the integer texel coordinate `i` along an axis of `n` texels.
    #[inline]
    fn wrap_index(&self, i: i64, n: usize) -> usize {
        let n = n as i64;
        let wrapped = match self.wrap {
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Mirror => {
                // Period 2n: 0 1 … n−1 n−1 … 1 0.
                let j = i.rem_euclid(2 * n);
                if j < n { j } else { 2 * n - 1 - j }
            }
        };
        wrapped as usize
    }

    /// The texels to blend at `uv` and their weights: four for bilinear filtering, one for
    /// nearest (with weight 1; the other three weights are 0). Also returns the fractional
    /// offsets (for the gradient).
    #[inline]
    fn footprint(&self, uv: Vec2) -> ([usize; 4], [f32; 4], Vec2) {
        let uv = self.to_uv.apply(uv);
        let (w, h) = (self.width, self.height);
        let at = |x: i64, y: i64| self.wrap_index(y, h) * w + self.wrap_index(x, w);
        match self.filter {
            FilterType::Nearest => {
                let x = (uv.x * w as f32).floor() as i64;
                let y = (uv.y * h as f32).floor() as i64;
                let i = at(x, y);
                ([i; 4], [1.0, 0.0, 0.0, 0.0], Vec2::ZERO)
            }
            FilterType::Bilinear => {
                let p = Vec2::new(uv.x * w as f32 - 0.5, uv.y * h as f32 - 0.5);
                let (x0, y0) = (p.x.floor(), p.y.floor());
                let f = p - Vec2::new(x0, y0);
                let (x, y) = (x0 as i64, y0 as i64);
                (
                    [at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)],
                    [
                        (1.0 - f.x) * (1.0 - f.y),
                        f.x * (1.0 - f.y),
                        (1.0 - f.x) * f.y,
                        f.x * f.y,
                    ],
                    f,
                )
            }
        }
    }

    /// The luminance (or value) of texel `i`.
    #[inline]
    fn texel_value(&self, i: usize) -> f32 {
        match &self.texels {
            Texels::Scalar(t) => t[i],
            Texels::Rgb(t) => luminance(t[i]),
            Texels::Spectral(t) => luminance(t[i].linear_srgb()),
            Texels::Emission(t) => luminance(t[i].linear_srgb()),
        }
    }
}

impl TextureValues for BitmapTexture {
    fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        let uv = at.into().uv;
        let (index, weight, _) = self.footprint(uv);
        match &self.texels {
            Texels::Spectral(texels) => {
                let mut result = SampledSpectrum::ZERO;
                for (i, w) in index.into_iter().zip(weight) {
                    if w != 0.0 {
                        let poly = &texels[i];
                        result += SampledSpectrum::from_fn(|k| poly.eval(lambda.lambda(k))) * w;
                    }
                }
                result
            }
            Texels::Emission(texels) => {
                let mut result = SampledSpectrum::ZERO;
                for (i, w) in index.into_iter().zip(weight) {
                    if w != 0.0 {
                        let texel = &texels[i];
                        result +=
                            SampledSpectrum::from_fn(|k| texel.polynomial.eval(lambda.lambda(k)))
                                * (w * texel.scale);
                    }
                }
                result
            }
            Texels::Scalar(_) | Texels::Rgb(_) => SampledSpectrum::splat(self.eval_1(uv)),
        }
    }

    fn eval_1(&self, at: impl Into<TexturePoint>) -> f32 {
        let uv = at.into().uv;
        let (index, weight, _) = self.footprint(uv);
        index
            .into_iter()
            .zip(weight)
            .map(|(i, w)| {
                if w != 0.0 {
                    w * self.texel_value(i)
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// ∂/∂(u, v) of [`Self::eval_1`] for bilinear filtering (Mitsuba's `eval_1_grad`): the
    /// derivative of the bilinear interpolant in texel units, times the resolution, pulled back
    /// through `to_uv`. Zero for nearest filtering.
    fn eval_1_grad(&self, at: impl Into<TexturePoint>) -> Vec2 {
        let uv = at.into().uv;
        if self.filter == FilterType::Nearest {
            return Vec2::ZERO;
        }
        let (index, _, f) = self.footprint(uv);
        let [v00, v10, v01, v11] = index.map(|i| self.texel_value(i));
        let d_texel = Vec2::new(
            (1.0 - f.y) * (v10 - v00) + f.y * (v11 - v01),
            (1.0 - f.x) * (v01 - v00) + f.x * (v11 - v10),
        );
        let d_uv = d_texel * Vec2::new(self.width as f32, self.height as f32);
        self.to_uv.pull_back_gradient(d_uv)
    }

    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        let uv = at.into().uv;
        let (index, weight, _) = self.footprint(uv);
        let mut result = Vec3::ZERO;
        for (i, w) in index.into_iter().zip(weight) {
            if w == 0.0 {
                continue;
            }
            let texel = match &self.texels {
                Texels::Rgb(t) => Vec3::from_array(t[i]),
                Texels::Scalar(t) => Vec3::splat(t[i]),
                Texels::Spectral(t) => Vec3::from_array(t[i].linear_srgb()),
                Texels::Emission(t) => Vec3::from_array(t[i].linear_srgb()),
            };
            result += texel * w;
        }
        result
    }

    fn max_value(&self) -> f32 {
        match &self.texels {
            Texels::Scalar(t) => t.iter().copied().fold(0.0, f32::max),
            Texels::Rgb(t) => t.iter().flatten().copied().fold(0.0, f32::max),
            // Upsampled reflectances never exceed 1.
            Texels::Spectral(_) => 1.0,
            // The polynomials lie in [0, 1].
            Texels::Emission(t) => t.iter().map(|t| t.scale).fold(0.0, f32::max),
        }
    }

    fn min_value(&self) -> f32 {
        match &self.texels {
            Texels::Scalar(t) => t.iter().copied().fold(f32::INFINITY, f32::min),
            Texels::Rgb(t) => t.iter().flatten().copied().fold(f32::INFINITY, f32::min),
            Texels::Spectral(_) | Texels::Emission(_) => 0.0,
        }
    }

    fn mean_value(&self) -> f32 {
        mean_over_cells(self, self.width.max(1), self.height.max(1))
    }

    fn aspect_ratio(&self) -> f64 {
        self.width as f64 / self.height as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Encoding;

    fn grey(width: usize, height: usize, data: Vec<f32>) -> Bitmap {
        Bitmap {
            width,
            height,
            channels: 1,
            data,
            encoding: Encoding::Linear,
        }
    }

    fn texture(filter: FilterType, wrap: WrapMode) -> BitmapTexture {
        // 2 × 2: top row 0, 1; bottom row 2, 3.
        BitmapTexture::new(
            &grey(2, 2, vec![0.0, 1.0, 2.0, 3.0]),
            TextureUse::Scalar,
            filter,
            wrap,
            UvTransform::IDENTITY,
        )
    }

    #[test]
    fn texel_centres_and_bilinear_interpolation() {
        let t = texture(FilterType::Bilinear, WrapMode::Clamp);
        assert_eq!(t.eval_1(Vec2::new(0.25, 0.25)), 0.0);
        assert_eq!(t.eval_1(Vec2::new(0.75, 0.25)), 1.0);
        assert_eq!(t.eval_1(Vec2::new(0.25, 0.75)), 2.0);
        assert!((t.eval_1(Vec2::new(0.5, 0.5)) - 1.5).abs() < 1e-6);
        // Clamped beyond the edge.
        assert_eq!(t.eval_1(Vec2::new(-3.0, 0.25)), 0.0);
        // The gradient of the bilinear interpolant: ∂/∂u = 1 texel per ½ in u, so 2.
        let g = t.eval_1_grad(Vec2::new(0.5, 0.5));
        assert!((g - Vec2::new(2.0, 4.0)).length() < 1e-5, "{g}");
    }

    #[test]
    fn wrap_modes() {
        let t = texture(FilterType::Nearest, WrapMode::Repeat);
        assert_eq!(t.eval_1(Vec2::new(1.25, 0.25)), 0.0);
        assert_eq!(t.eval_1(Vec2::new(-0.25, 0.25)), 1.0);
        let t = texture(FilterType::Nearest, WrapMode::Mirror);
        assert_eq!(t.eval_1(Vec2::new(1.25, 0.25)), 1.0);
        assert_eq!(t.eval_1(Vec2::new(1.75, 0.25)), 0.0);
        assert_eq!(t.eval_1(Vec2::new(-0.25, 0.25)), 0.0);
        let t = texture(FilterType::Nearest, WrapMode::Clamp);
        assert_eq!(t.eval_1(Vec2::new(5.0, 5.0)), 3.0);
    }

    #[test]
    fn colour_texels_are_upsampled_and_interpolated() {
        let bitmap = Bitmap {
            width: 2,
            height: 1,
            channels: 3,
            data: vec![0.8, 0.2, 0.1, 0.5, 0.5, 0.5],
            encoding: Encoding::Linear,
        };
        let t = BitmapTexture::new(
            &bitmap,
            TextureUse::Spectral,
            FilterType::Bilinear,
            WrapMode::Clamp,
            UvTransform::IDENTITY,
        );
        let lambda = SampledWavelengths::single(550.0);
        // The grey texel is exactly 0.5 at every wavelength.
        assert!((t.eval(Vec2::new(0.75, 0.5), &lambda)[0] - 0.5).abs() < 1e-6);
        let red = t.eval(Vec2::new(0.25, 0.5), &SampledWavelengths::single(650.0))[0];
        let green = t.eval(Vec2::new(0.25, 0.5), &SampledWavelengths::single(530.0))[0];
        assert!(red > 0.6 && green < 0.3, "{red} {green}");
    }
}
