//! Splatting: contributions that land anywhere on the film (the particle tracer's connections
//! to the camera), spread over the pixels through the reconstruction filter, and the exact sums
//! that gather them.
//!
//! A contribution V at film position u adds V · k(u_x − c_x) k(u_y − c_y) / (∫k)² to every pixel
//! whose centre c is within the filter's radius of u: the filter normalised to integrate to one,
//! so that the expected image is the filtered one, ∫ k_j(u) L(u) du, as a camera sample's
//! estimate through the same filter ([`super::filter`]; Veach 1997, §10.3.4.3). A box filter of
//! radius ½ puts each contribution in the one pixel it lands in.
//!
//! The sums are fixed point ([`super::accumulation::ExactSum`]), so that the image does not
//! depend on the order in which the contributions arrive: whatever the number of threads and the
//! way the light subpaths are split among them, it is the same to the last bit.

use glam::Vec2;

use super::accumulation::ValueSum;
use super::{CropWindow, Filter, FilterSampler, Kernel};

/// Spreads contributions over the pixels of the crop window through the filter.
#[derive(Clone, Debug)]
pub struct Splatter {
    filter: Filter,
    /// 1 / (∫k)².
    normalization: f32,
    crop: CropWindow,
}

impl Splatter {
    pub fn new(filter: Filter, crop: CropWindow) -> Splatter {
        let integral = FilterSampler::new(filter).integral_1d();
        Splatter {
            filter,
            normalization: 1.0 / (integral * integral),
            crop,
        }
    }

    /// The first and last pixel (full-film coordinates, inclusive) of the crop window whose
    /// filter covers the film position `film`: those x with |film.x − (x + ½)| ≤ r, and alike
    /// in y; None where there is none.
    #[inline]
    fn covered(&self, film: Vec2) -> Option<(Vec2, Vec2)> {
        let r = self.filter.radius();
        let lo = self.crop.offset.as_vec2();
        let hi = lo + self.crop.size.as_vec2() - Vec2::ONE;
        let first = (film - Vec2::splat(0.5 + r)).ceil().max(lo);
        let last = (film + Vec2::splat(r - 0.5)).floor().min(hi);
        (first.x <= last.x && first.y <= last.y).then_some((first, last))
    }

    /// Whether the filter of some pixel of the crop window covers the film position `film`.
    #[inline]
    pub fn reaches(&self, film: Vec2) -> bool {
        self.covered(film).is_some()
    }

    /// Calls `add(i, w)` for every pixel of the crop window whose filter covers the full-film
    /// position `film` (pixels, origin top-left): i its row-major index in the crop window, w
    /// its filter weight k(Δx) k(Δy) / (∫k)².
    #[inline]
    pub fn for_each_pixel(&self, film: Vec2, mut add: impl FnMut(usize, f32)) {
        let Some((first, last)) = self.covered(film) else {
            return;
        };
        for y in first.y as u32..=last.y as u32 {
            let wy = self.filter.eval(film.y - (y as f32 + 0.5));
            if wy == 0.0 {
                continue;
            }
            let row = (y - self.crop.offset.y) * self.crop.size.x;
            for x in first.x as u32..=last.x as u32 {
                let wx = self.filter.eval(film.x - (x as f32 + 0.5));
                if wx != 0.0 {
                    let i = (row + x - self.crop.offset.x) as usize;
                    add(i, wx * wy * self.normalization);
                }
            }
        }
    }
}

/// One contribution to a pixel: its row-major index in the crop window and its CIE XYZ.
#[derive(Clone, Copy, Debug)]
pub struct SplatValue {
    pub pixel: u32,
    pub xyz: [f64; 3],
}

/// Exact sums of splatted XYZ, one per pixel of the crop window, row-major.
#[derive(Clone, Debug, Default)]
pub struct SplatSums {
    pub xyz: Vec<[ValueSum; 3]>,
}

impl SplatSums {
    /// Zero sums for `pixels` pixels, reusing the allocation.
    pub fn clear(&mut self, pixels: usize) {
        self.xyz.clear();
        self.xyz.resize(pixels, [ValueSum::default(); 3]);
    }

    /// Adds the contributions `values`.
    pub fn add(&mut self, values: &[SplatValue]) {
        for v in values {
            let sums = &mut self.xyz[v.pixel as usize];
            for (sum, value) in sums.iter_mut().zip(v.xyz) {
                sum.add(value);
            }
        }
    }

    /// The sums of pixel `i`.
    #[inline]
    pub fn value(&self, i: usize) -> [f64; 3] {
        self.xyz[i].map(ValueSum::value)
    }
}

#[cfg(test)]
mod tests {
    use glam::UVec2;

    use super::*;
    use crate::film::{BoxFilter, GaussianFilter, TentFilter};

    fn weights(splatter: &Splatter, film: Vec2) -> Vec<(usize, f32)> {
        let mut out = Vec::new();
        splatter.for_each_pixel(film, |i, w| out.push((i, w)));
        out
    }

    fn crop(offset: (u32, u32), size: (u32, u32)) -> CropWindow {
        CropWindow {
            offset: UVec2::new(offset.0, offset.1),
            size: UVec2::new(size.0, size.1),
        }
    }

    /// The box filter of radius ½ puts a contribution in the pixel it lands in, with weight 1;
    /// positions outside the crop window add nothing.
    #[test]
    fn the_box_filter_hits_one_pixel() {
        let splatter = Splatter::new(Filter::Box(BoxFilter { radius: 0.5 }), crop((2, 1), (4, 3)));
        assert_eq!(weights(&splatter, Vec2::new(3.3, 2.7)), vec![(5, 1.0)]);
        assert!(weights(&splatter, Vec2::new(1.9, 2.5)).is_empty());
        assert!(weights(&splatter, Vec2::new(6.1, 2.5)).is_empty());
    }

    /// Away from the crop window's edges, a splat's weights average to one over the positions
    /// within a pixel (∫ Σ_j k_j(u) du over a unit cell is ∫ k(x)k(y) / (∫k)² = 1, which makes
    /// the splatted image the filtered one); the tent's sum to one at every position.
    #[test]
    fn weights_average_to_one_inside_the_window() {
        let tent = Splatter::new(
            Filter::Tent(TentFilter { radius: 1.0 }),
            crop((0, 0), (32, 32)),
        );
        for film in [Vec2::new(16.0, 16.0), Vec2::new(10.3, 20.71)] {
            let total: f32 = weights(&tent, film).iter().map(|(_, w)| w).sum();
            assert!((total - 1.0).abs() < 1e-5, "tent at {film}: {total}");
        }
        let gaussian = Splatter::new(
            Filter::Gaussian(GaussianFilter { stddev: 0.5 }),
            crop((0, 0), (32, 32)),
        );
        let n = 64;
        let mut total = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let film = Vec2::new(
                    16.0 + (i as f32 + 0.5) / n as f32,
                    16.0 + (j as f32 + 0.5) / n as f32,
                );
                total += weights(&gaussian, film)
                    .iter()
                    .map(|(_, w)| f64::from(*w))
                    .sum::<f64>();
            }
        }
        let mean = total / f64::from(n * n);
        assert!((mean - 1.0).abs() < 2e-3, "gaussian: {mean}");
    }

    /// The sums do not depend on the order of the contributions.
    #[test]
    fn sums_are_order_independent() {
        let values: Vec<SplatValue> = (0..200)
            .map(|i| SplatValue {
                pixel: (i * 7 % 5) as u32,
                xyz: [0.1 * f64::from(i), 1e-3 / f64::from(i + 1), 3.0],
            })
            .collect();
        let mut forward = SplatSums::default();
        forward.clear(5);
        forward.add(&values);
        let mut backward = SplatSums::default();
        backward.clear(5);
        let reversed: Vec<SplatValue> = values.iter().rev().copied().collect();
        backward.add(&reversed[..77]);
        backward.add(&reversed[77..]);
        assert_eq!(forward.xyz, backward.xyz);
    }
}
