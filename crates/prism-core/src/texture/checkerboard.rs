//! Mitsuba's `checkerboard` texture: two textures alternating on the unit squares' quarters.
//!
//! ```xml
//! <texture type="checkerboard" name="reflectance">
//!     <rgb name="color0" value="0.4"/>   <!-- default 0.4 -->
//!     <rgb name="color1" value="0.2"/>   <!-- default 0.2 -->
//!     <transform name="to_uv"> <scale x="8" y="8"/> </transform>
//! </texture>
//! ```
//! With (u, v) = to_uv(uv), `color0` is used where frac(u) > ½ and frac(v) > ½ agree and
//! `color1` where they differ (Mitsuba 3, `src/textures/checkerboard.cpp`, `eval`; its `eval_1`
//! swaps the two, which we do not copy).

use glam::Vec2;

use super::{Texture, TexturePoint, UvTransform};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct Checkerboard {
    pub color0: Texture,
    pub color1: Texture,
    pub to_uv: UvTransform,
}

impl Checkerboard {
    /// The texture of the square that `uv` falls in.
    #[inline]
    fn select(&self, uv: Vec2) -> &Texture {
        let p = self.to_uv.apply(uv);
        let upper = |x: f32| x - x.floor() > 0.5;
        if upper(p.x) == upper(p.y) {
            &self.color0
        } else {
            &self.color1
        }
    }

    pub fn eval(&self, at: &TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.select(at.uv).eval(*at, lambda)
    }

    pub fn eval_1(&self, at: &TexturePoint) -> f32 {
        self.select(at.uv).eval_1(*at)
    }

    pub fn max_value(&self) -> f32 {
        self.color0.max_value().max(self.color1.max_value())
    }

    pub fn min_value(&self) -> f32 {
        self.color0.min_value().min(self.color1.min_value())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn squares_alternate() {
        let c = Checkerboard {
            color0: Texture::constant(0.4),
            color1: Texture::constant(0.2),
            to_uv: UvTransform::IDENTITY,
        };
        let at = |u, v| TexturePoint::from(Vec2::new(u, v));
        assert_eq!(c.eval_1(&at(0.25, 0.25)), 0.4);
        assert_eq!(c.eval_1(&at(0.75, 0.75)), 0.4);
        assert_eq!(c.eval_1(&at(0.75, 0.25)), 0.2);
        assert_eq!(c.eval_1(&at(1.25, -0.25)), 0.2);
    }
}
