//! pbrt-v4's `mix` texture: two textures blended by a number-valued texture,
//! (1 − amount) · tex1 + amount · tex2 (pbrt-v4, `src/pbrt/textures.h`, `MixTexture`).

use glam::{Vec2, Vec3};

use super::{Texture, TexturePoint, TextureValues, mean_over_cells};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct MixTexture {
    pub tex1: Texture,
    pub tex2: Texture,
    /// The weight of `tex2`, read as a number.
    pub amount: Texture,
}

impl TextureValues for MixTexture {
    fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        let at = at.into();
        let amount = self.amount.eval_1(at);
        self.tex1.eval(at, lambda) * (1.0 - amount) + self.tex2.eval(at, lambda) * amount
    }

    fn eval_1(&self, at: impl Into<TexturePoint>) -> f32 {
        let at = at.into();
        let amount = self.amount.eval_1(at);
        (1.0 - amount) * self.tex1.eval_1(at) + amount * self.tex2.eval_1(at)
    }

    /// ∇((1 − a) t₁ + a t₂) = (1 − a) ∇t₁ + a ∇t₂ + (t₂ − t₁) ∇a.
    fn eval_1_grad(&self, at: impl Into<TexturePoint>) -> Vec2 {
        let at = at.into();
        let amount = self.amount.eval_1(at);
        (1.0 - amount) * self.tex1.eval_1_grad(at)
            + amount * self.tex2.eval_1_grad(at)
            + (self.tex2.eval_1(at) - self.tex1.eval_1(at)) * self.amount.eval_1_grad(at)
    }

    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        let at = at.into();
        let amount = self.amount.eval_1(at);
        (1.0 - amount) * self.tex1.eval_3(at) + amount * self.tex2.eval_3(at)
    }

    /// The largest value at a corner of the box of the three textures' bounds: the blend is
    /// linear in each of them.
    fn max_value(&self) -> f32 {
        self.corner_values().into_iter().fold(f32::MIN, f32::max)
    }

    fn min_value(&self) -> f32 {
        self.corner_values().into_iter().fold(f32::MAX, f32::min)
    }

    fn mean_value(&self) -> f32 {
        mean_over_cells(self, 256, 256)
    }

    fn aspect_ratio(&self) -> f64 {
        self.tex1.aspect_ratio()
    }
}

impl MixTexture {
    fn corner_values(&self) -> [f32; 8] {
        let t1 = [self.tex1.min_value(), self.tex1.max_value()];
        let t2 = [self.tex2.min_value(), self.tex2.max_value()];
        let a = [self.amount.min_value(), self.amount.max_value()];
        std::array::from_fn(|i| {
            let (t1, t2, a) = (t1[i & 1], t2[(i >> 1) & 1], a[i >> 2]);
            (1.0 - a) * t1 + a * t2
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Checkerboard, UvTransform};

    #[test]
    fn two_textures_are_blended_by_a_textured_amount() {
        // amount: 0.75 on the odd squares, 0.25 on the even ones when read as a number.
        let amount = Texture::Checkerboard(Box::new(Checkerboard {
            color0: Texture::constant(0.75),
            color1: Texture::constant(0.25),
            to_uv: UvTransform::IDENTITY,
        }));
        let mix = MixTexture {
            tex1: Texture::constant(0.2),
            tex2: Texture::constant(0.6),
            amount,
        };
        let lambda = SampledWavelengths::single(550.0);
        let even = Vec2::new(0.25, 0.25);
        let odd = Vec2::new(0.75, 0.25);
        let close = |a: f32, b: f32| (a - b).abs() < 1e-6;
        assert!(close(mix.eval(even, &lambda)[0], 0.75 * 0.2 + 0.25 * 0.6));
        assert!(close(mix.eval(odd, &lambda)[0], 0.25 * 0.2 + 0.75 * 0.6));
        assert!(close(mix.eval_1(odd), 0.5));
        assert!(close(mix.eval_3(even).x, 0.3));
        assert!(close(mix.max_value(), 0.5));
        assert!(close(mix.min_value(), 0.3));
        assert_eq!(mix.eval_1_grad(even), Vec2::ZERO);
    }
}
