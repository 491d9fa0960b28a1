//! pbrt-v4's `scale` texture: a texture times a number-valued texture, tex · scale (pbrt-v4,
//! `src/pbrt/textures.h`, `FloatScaledTexture` and `SpectrumScaledTexture`).

use glam::{Vec2, Vec3};

use super::{Texture, TexturePoint, TextureValues, mean_over_cells};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct ScaledTexture {
    pub texture: Texture,
    /// Read as a number.
    pub scale: Texture,
}

impl TextureValues for ScaledTexture {
    fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        let at = at.into();
        self.texture.eval(at, lambda) * self.scale.eval_1(at)
    }

    fn eval_1(&self, at: impl Into<TexturePoint>) -> f32 {
        let at = at.into();
        self.texture.eval_1(at) * self.scale.eval_1(at)
    }

    /// ∇(t s) = s ∇t + t ∇s.
    fn eval_1_grad(&self, at: impl Into<TexturePoint>) -> Vec2 {
        let at = at.into();
        self.scale.eval_1(at) * self.texture.eval_1_grad(at)
            + self.texture.eval_1(at) * self.scale.eval_1_grad(at)
    }

    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        let at = at.into();
        self.texture.eval_3(at) * self.scale.eval_1(at)
    }

    /// The largest product of the two textures' bounds (a product over a box of values is
    /// extreme at a corner).
    fn max_value(&self) -> f32 {
        self.corner_products().into_iter().fold(f32::MIN, f32::max)
    }

    fn min_value(&self) -> f32 {
        self.corner_products().into_iter().fold(f32::MAX, f32::min)
    }

    fn mean_value(&self) -> f32 {
        mean_over_cells(self, 256, 256)
    }

    fn aspect_ratio(&self) -> f64 {
        self.texture.aspect_ratio()
    }
}

impl ScaledTexture {
    fn corner_products(&self) -> [f32; 4] {
        let (t0, t1) = (self.texture.min_value(), self.texture.max_value());
        let (s0, s1) = (self.scale.min_value(), self.scale.max_value());
        [t0 * s0, t0 * s1, t1 * s0, t1 * s1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Checkerboard, UvTransform};

    #[test]
    fn a_texture_is_scaled_by_a_textured_number() {
        // scale: 3 on the odd squares, 0.5 on the even ones when read as a number.
        let scale = Texture::Checkerboard(Box::new(Checkerboard {
            color0: Texture::constant(3.0),
            color1: Texture::constant(0.5),
            to_uv: UvTransform::IDENTITY,
        }));
        let scaled = ScaledTexture {
            texture: Texture::constant(0.2),
            scale,
        };
        let lambda = SampledWavelengths::single(550.0);
        let even = Vec2::new(0.25, 0.25);
        let odd = Vec2::new(0.75, 0.25);
        assert_eq!(scaled.eval(even, &lambda)[0], 0.2 * 0.5);
        assert_eq!(scaled.eval(odd, &lambda)[0], 0.2 * 3.0);
        assert_eq!(scaled.eval_1(odd), 0.2 * 3.0);
        assert_eq!(scaled.eval_3(even), Vec3::splat(0.2 * 0.5));
        assert_eq!(scaled.max_value(), 0.2 * 3.0);
        assert_eq!(scaled.min_value(), 0.2 * 0.5);
        assert!((scaled.mean_value() - 0.2 * 1.75).abs() < 1e-6);
    }
}
