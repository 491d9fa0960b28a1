//! A constant texture: a spectrum, the same everywhere on the surface.

use glam::{Vec2, Vec3};

use super::{TexturePoint, TextureValues};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

impl TextureValues for Spectrum {
    #[inline]
    fn eval(&self, _at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.sample(lambda)
    }

    #[inline]
    fn eval_1(&self, _at: impl Into<TexturePoint>) -> f32 {
        match self {
            Spectrum::Constant(v) => *v,
            spectrum => spectrum.mean(),
        }
    }

    #[inline]
    fn eval_1_grad(&self, _at: impl Into<TexturePoint>) -> Vec2 {
        Vec2::ZERO
    }

    #[inline]
    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        Vec3::splat(self.eval_1(at))
    }

    fn max_value(&self) -> f32 {
        Spectrum::max_value(self)
    }

    fn min_value(&self) -> f32 {
        Spectrum::min_value(self)
    }

    fn mean_value(&self) -> f32 {
        self.eval_1(Vec2::ZERO)
    }

    fn aspect_ratio(&self) -> f64 {
        1.0
    }
}
