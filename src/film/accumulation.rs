//! The film: per-pixel sums of the CIE XYZ estimates and of their squares.

use glam::UVec2;

use crate::spectrum::cie::xyz_to_linear_srgb;

/// The rectangle of the full film that is rendered (Mitsuba's crop window).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CropWindow {
    pub offset: UVec2,
    pub size: UVec2,
}

/// Running sums for one pixel. With N samples of (filter-weighted) XYZ values vᵢ, the pixel is
/// Σvᵢ/N; Σvᵢ² gives the variance of that mean.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelSums {
    pub xyz: [f64; 3],
    pub xyz_squared: [f64; 3],
    pub samples: u64,
    /// Samples whose value was NaN or infinite, dropped from the sums.
    pub rejected: u64,
}

impl PixelSums {
    /// Adds one sample; a non-finite value is counted and dropped.
    #[inline]
    pub fn add(&mut self, xyz: [f32; 3]) {
        self.samples += 1;
        if !xyz.iter().all(|v| v.is_finite()) {
            self.rejected += 1;
            return;
        }
        for ((sum, squares), v) in self.xyz.iter_mut().zip(&mut self.xyz_squared).zip(xyz) {
            let v = f64::from(v);
            *sum += v;
            *squares += v * v;
        }
    }

    /// The pixel's estimate of XYZ: the mean over all samples taken (a rejected sample counts as
    /// zero, which keeps the estimate unbiased for integrands that are finite almost everywhere).
    pub fn mean(&self) -> [f64; 3] {
        if self.samples == 0 {
            return [0.0; 3];
        }
        self.xyz.map(|v| v / self.samples as f64)
    }
}

/// The image being rendered.
#[derive(Clone, Debug)]
pub struct Film {
    /// Size of the full film in pixels.
    pub size: UVec2,
    pub crop: CropWindow,
    /// Pixels of the crop window, row-major, top row first.
    pub pixels: Vec<PixelSums>,
}

impl Film {
    pub fn new(size: UVec2, crop: CropWindow) -> Film {
        Film {
            size,
            crop,
            pixels: vec![PixelSums::default(); (crop.size.x * crop.size.y) as usize],
        }
    }

    /// Index in `pixels` of a pixel given relative to the crop window.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (y * self.crop.size.x + x) as usize
    }

    /// XYZ of every pixel, row-major.
    pub fn xyz(&self) -> Vec<[f32; 3]> {
        self.pixels
            .iter()
            .map(|p| p.mean().map(|v| v as f32))
            .collect()
    }

    /// Linear sRGB of every pixel.
    pub fn linear_srgb(&self) -> Vec<[f32; 3]> {
        self.xyz().into_iter().map(xyz_to_linear_srgb).collect()
    }

    /// Total samples taken and samples rejected as non-finite.
    pub fn sample_counts(&self) -> (u64, u64) {
        self.pixels
            .iter()
            .fold((0, 0), |(s, r), p| (s + p.samples, r + p.rejected))
    }
}
