//! Mitsuba's `checkerboard` texture: two textures alternating on the unit squares' quarters.
//!
//! ```xml
//! <texture type="checkerboard" name="reflectance">
//!     <rgb name="color0" value="0.4"/>
//!     <rgb name="color1" value="0.2"/>
//!     <transform name="to_uv"> <scale x="8" y="8"/> </transform>
//! </texture>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! With (u, v) = to_uv(uv), a colour lookup uses `color0` where frac(u) > ½ and frac(v) > ½
//! agree and `color1` where they differ (Mitsuba 3, `src/textures/checkerboard.cpp`, `eval`).
//! Read as a number (a roughness, an opacity) the phase is the opposite one: `color0` where
//! they differ (Mitsuba 3's `eval_1` tests inequality), so the same XML gives the same image.

use glam::{Vec2, Vec3};

use super::{Texture, TexturePoint, TextureValues, UvTransform, mean_over_cells};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Checkerboard {
    pub color0: Texture,
    pub color1: Texture,
    pub to_uv: UvTransform,
}

impl Checkerboard {
    /// Whether `uv` falls in a square where frac(u) > ½ and frac(v) > ½ agree.
    #[inline]
    fn in_even_square(&self, uv: Vec2) -> bool {
        let p = self.to_uv.apply(uv);
        let upper = |x: f32| x - x.floor() > 0.5;
        upper(p.x) == upper(p.y)
    }
}

impl TextureValues for Checkerboard {
    /// The colour at `at`: `color0` on the even squares.
    fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        let at = at.into();
        let texture = if self.in_even_square(at.uv) {
            &self.color0
        } else {
            &self.color1
        };
        texture.eval(at, lambda)
    }

    /// The number at `at`: `color0` on the odd squares, Mitsuba 3's phase for `eval_1`.
    fn eval_1(&self, at: impl Into<TexturePoint>) -> f32 {
        let at = at.into();
        let texture = if self.in_even_square(at.uv) {
            &self.color1
        } else {
            &self.color0
        };
        texture.eval_1(at)
    }

    fn eval_1_grad(&self, _at: impl Into<TexturePoint>) -> Vec2 {
        Vec2::ZERO
    }

    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        Vec3::splat(self.eval_1(at))
    }

    fn max_value(&self) -> f32 {
        self.color0.max_value().max(self.color1.max_value())
    }

    fn min_value(&self) -> f32 {
        self.color0.min_value().min(self.color1.min_value())
    }

    fn mean_value(&self) -> f32 {
        mean_over_cells(self, 256, 256)
    }

    fn aspect_ratio(&self) -> f64 {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The values Mitsuba 3.9.1 (`scalar_spectral`) gives at these points: `eval` 0.4, 0.4, 0.2
    /// and `eval_1` 0.2, 0.2, 0.4 for color0 = 0.4, color1 = 0.2.
    #[test]
    fn squares_alternate_with_mitsubas_phases() {
        let c = Checkerboard {
            color0: Texture::constant(0.4),
            color1: Texture::constant(0.2),
            to_uv: UvTransform::IDENTITY,
        };
        let lambda = SampledWavelengths::single(550.0);
        let at = |u: f32, v: f32| TexturePoint::from(Vec2::new(u, v));
        let colour = |u: f32, v: f32| c.eval(at(u, v), &lambda)[0];
        assert_eq!(colour(0.25, 0.25), 0.4);
        assert_eq!(colour(0.75, 0.75), 0.4);
        assert_eq!(colour(0.75, 0.25), 0.2);
        assert_eq!(colour(1.25, -0.25), 0.2);
        assert_eq!(c.eval_1(at(0.25, 0.25)), 0.2);
        assert_eq!(c.eval_1(at(0.75, 0.75)), 0.2);
        assert_eq!(c.eval_1(at(0.75, 0.25)), 0.4);
        assert_eq!(c.eval_1(at(1.25, -0.25)), 0.4);
    }
}
