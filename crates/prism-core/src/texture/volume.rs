//! Mitsuba 3's `volume` texture (`src/textures/volume.cpp`): a volume (`constvolume` or
//! `gridvolume`, [`Volume`]) read on a surface at the point's world position, for surfaces
//! without a meaningful (u, v) map or for solid textures. The value at a surface point p is the
//! volume's value at p: a grid's trilinear interpolation in the grid's own coordinates
//! (`to_world`⁻¹ p), a constant's value.
//!
//! The texture needs the surface point's position ([`TexturePoint::p`]); the scene reader refuses
//! it where a texture is looked up by (u, v) alone (emitters).

use glam::{Vec2, Vec3};

use super::{TexturePoint, TextureValues};
use crate::medium::Volume;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, WavelengthSampling};

/// The texture: the volume it reads.
#[derive(Clone, Debug)]
pub struct VolumeTexture {
    pub volume: Volume,
}

impl TextureValues for VolumeTexture {
    #[inline]
    fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.volume.eval(at.into().p, lambda)
    }

    /// A constant's scalar value (a spectrum's mean over 360–830 nm, as Mitsuba's
    /// `constvolume`), a number grid's interpolated value; a colour grid (which the scene reader
    /// refuses to read as a number, as Mitsuba 3's spectral variants do) gives its spectrum's
    /// mean at four wavelengths at the centres of four equal parts of 360–830 nm.
    #[inline]
    fn eval_1(&self, at: impl Into<TexturePoint>) -> f32 {
        let p = at.into().p;
        match &self.volume {
            Volume::Constant(value) => value.eval_1(Vec2::ZERO),
            Volume::ConstantInBox(constant) => constant.value.eval_1(Vec2::ZERO),
            Volume::Grid(grid) => grid.eval(p),
            Volume::SpectralGrid(grid) => {
                let lambda = SampledWavelengths::sample(0.125, WavelengthSampling::Uniform);
                grid.eval(p, &lambda).average()
            }
        }
    }

    /// A volume has no (u, v) map: zero (the scene reader refuses a bump map of a volume
    /// texture, as Mitsuba does).
    fn eval_1_grad(&self, _at: impl Into<TexturePoint>) -> Vec2 {
        Vec2::ZERO
    }

    /// The scalar value in all three components.
    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        Vec3::splat(self.eval_1(at))
    }

    fn max_value(&self) -> f32 {
        self.volume.max_value()
    }

    /// A constant's smallest value, a number grid's smallest voxel; 0 for a colour grid (a
    /// bound: its voxels are not negative).
    fn min_value(&self) -> f32 {
        match &self.volume {
            Volume::Constant(value) => value.min_value(),
            Volume::ConstantInBox(constant) => constant.value.min_value(),
            Volume::Grid(grid) => grid.min_value(),
            Volume::SpectralGrid(_) => 0.0,
        }
    }

    /// No (u, v) map: its bound, as for [`super::MeshAttributeTexture`].
    fn mean_value(&self) -> f32 {
        self.max_value()
    }

    fn aspect_ratio(&self) -> f64 {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;
    use crate::medium::{ConstantInBox, GridFilter, GridVolume};
    use crate::spectrum::{RgbIntent, Spectrum};
    use glam::{DMat4, DVec3};

    fn at(p: Vec3) -> TexturePoint {
        TexturePoint {
            p,
            ..TexturePoint::from(Vec2::new(0.3, 0.7))
        }
    }

    /// A `constvolume` texture is its value at every point, inside its box or not.
    #[test]
    fn a_constant_volume_is_its_value_everywhere() {
        let lambda = SampledWavelengths::sample(0.4, WavelengthSampling::Uniform);
        let colour = Spectrum::from_rgb([0.2, 0.5, 0.7], RgbIntent::Albedo);
        let texture = VolumeTexture {
            volume: Volume::ConstantInBox(Box::new(ConstantInBox::new(
                colour.clone(),
                &Transform::IDENTITY,
            ))),
        };
        let number = VolumeTexture {
            volume: Volume::Constant(Spectrum::Constant(0.35)),
        };
        for p in [Vec3::splat(0.5), Vec3::new(-3.0, 7.0, 0.2)] {
            assert_eq!(texture.eval(at(p), &lambda), colour.sample(&lambda));
            assert_eq!(texture.eval_1(at(p)), colour.mean());
            assert_eq!(number.eval(at(p), &lambda), SampledSpectrum::splat(0.35));
            assert_eq!(number.eval_1(at(p)), 0.35);
        }
        assert_eq!(number.min_value(), 0.35);
        assert_eq!(number.max_value(), 0.35);
    }

    /// A grid of 3 × 2 × 2 voxels holding f(x, y, z) = x + 10 y + 100 z + 1000 x y z at voxel
    /// (x, y, z), over the unit cube scaled by 2 and moved to (1, 2, 3). Trilinear interpolation
    /// between voxel centres reproduces a multilinear f of the coordinates u = v r − ½ in
    /// voxel-centre units, so the values are by hand:
    /// * world (1.6, 3.2, 3.9): unit cube (0.3, 0.6, 0.45), u = (0.4, 0.7, 0.4), value
    ///   0.4 + 7 + 40 + 1000 · 0.112 = 159.4;
    /// * world (0.6, 3, 5.6): unit cube (−0.2, 0.5, 1.3), clamped to u = (0, 0.5, 1), value
    ///   0 + 5 + 100 + 0 = 105.
    #[test]
    fn a_grid_volume_is_interpolated_trilinearly_at_the_world_position() {
        let f = |x: f32, y: f32, z: f32| x + 10.0 * y + 100.0 * z + 1000.0 * x * y * z;
        let data: Vec<f32> = (0..12)
            .map(|i| f((i % 3) as f32, ((i / 3) % 2) as f32, (i / 6) as f32))
            .collect();
        let to_world = Transform::new(
            DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0))
                * DMat4::from_scale(DVec3::splat(2.0)),
        )
        .expect("an invertible transform");
        let grid = GridVolume::new([3, 2, 2], data, to_world, GridFilter::Trilinear)
            .expect("a valid grid");
        let texture = VolumeTexture {
            volume: Volume::Grid(Box::new(grid)),
        };
        let lambda = SampledWavelengths::sample(0.4, WavelengthSampling::Uniform);
        for (p, expected) in [
            (Vec3::new(1.6, 3.2, 3.9), 159.4),
            (Vec3::new(0.6, 3.0, 5.6), 105.0),
        ] {
            let value = texture.eval_1(at(p));
            assert!(
                (value - expected).abs() < 1e-3,
                "{p}: {value}, not {expected}"
            );
            assert_eq!(texture.eval(at(p), &lambda), SampledSpectrum::splat(value));
        }
        assert_eq!(texture.min_value(), 0.0);
        assert_eq!(texture.max_value(), f(2.0, 1.0, 1.0));
    }
}
