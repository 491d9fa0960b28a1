//! pbrt-v4's `directionmix` texture: two textures blended by the direction of the surface,
//!
//!   value = a · tex1 + (1 − a) · tex2,   a = |n · dir|,
//!
//! with n the geometric normal at the point and `dir` a unit vector, both in world space
//! (pbrt-v4, `src/pbrt/textures.h`, `FloatDirectionMixTexture` and
//! `SpectrumDirectionMixTexture`, which read `TextureEvalContext::n`, the surface interaction's
//! geometric normal). A surface facing `dir` (or away from it) shows `tex1`, one parallel to it
//! `tex2`.
//!
//! The texture needs the surface's normal ([`TexturePoint::n`]); the scene reader refuses it where
//! a texture is looked up by (u, v) alone (emitters).

use glam::{Vec2, Vec3};

use super::{Texture, TexturePoint, TextureValues};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct DirectionMixTexture {
    /// The texture where the normal is parallel to `dir`.
    pub tex1: Texture,
    /// The texture where the normal is perpendicular to `dir`.
    pub tex2: Texture,
    dir: Vec3,
}

impl DirectionMixTexture {
    /// The blend of `tex1` and `tex2` by the direction `dir` (world space, any length);
    /// `None` when `dir` is zero or not finite.
    pub fn new(tex1: Texture, tex2: Texture, dir: Vec3) -> Option<DirectionMixTexture> {
        let dir = dir.try_normalize()?;
        Some(DirectionMixTexture { tex1, tex2, dir })
    }

    /// The unit direction.
    pub fn dir(&self) -> Vec3 {
        self.dir
    }

    /// The weight of `tex1` at `at`, |n · dir| (at most 1: the normal is a unit vector, or zero
    /// for a point without one, which shows `tex2`).
    #[inline]
    pub fn amount(&self, at: &TexturePoint) -> f32 {
        at.n.dot(self.dir).abs().min(1.0)
    }
}

impl TextureValues for DirectionMixTexture {
    fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        let at = at.into();
        let amount = self.amount(&at);
        let mut value = SampledSpectrum::ZERO;
        if amount > 0.0 {
            value += self.tex1.eval(at, lambda) * amount;
        }
        if amount < 1.0 {
            value += self.tex2.eval(at, lambda) * (1.0 - amount);
        }
        value
    }

    fn eval_1(&self, at: impl Into<TexturePoint>) -> f32 {
        let at = at.into();
        let amount = self.amount(&at);
        let mut value = 0.0;
        if amount > 0.0 {
            value += amount * self.tex1.eval_1(at);
        }
        if amount < 1.0 {
            value += (1.0 - amount) * self.tex2.eval_1(at);
        }
        value
    }

    /// a ∇tex1 + (1 − a) ∇tex2: the normal held fixed, as pbrt-v4's bump mapping shifts only
    /// the point and its (u, v).
    fn eval_1_grad(&self, at: impl Into<TexturePoint>) -> Vec2 {
        let at = at.into();
        let amount = self.amount(&at);
        amount * self.tex1.eval_1_grad(at) + (1.0 - amount) * self.tex2.eval_1_grad(at)
    }

    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        let at = at.into();
        let amount = self.amount(&at);
        amount * self.tex1.eval_3(at) + (1.0 - amount) * self.tex2.eval_3(at)
    }

    /// The larger of the two textures' bounds: the blend is convex.
    fn max_value(&self) -> f32 {
        self.tex1.max_value().max(self.tex2.max_value())
    }

    fn min_value(&self) -> f32 {
        self.tex1.min_value().min(self.tex2.min_value())
    }

    /// The mean over normals spread evenly over the sphere, on which |n · dir| averages ½.
    fn mean_value(&self) -> f32 {
        0.5 * (self.tex1.mean_value() + self.tex2.mean_value())
    }

    fn aspect_ratio(&self) -> f64 {
        self.tex1.aspect_ratio()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Checkerboard, UvTransform};

    fn facing(n: Vec3, uv: Vec2) -> TexturePoint {
        TexturePoint {
            n,
            ..TexturePoint::from(uv)
        }
    }

    /// dir = (0, 3, 4)/5 after normalisation: a normal n gives a = |0.6 n_y + 0.8 n_z|.
    #[test]
    fn the_blend_is_the_absolute_cosine_between_the_normal_and_the_direction() {
        let mix = DirectionMixTexture::new(
            Texture::constant(0.9),
            Texture::constant(0.1),
            Vec3::new(0.0, 3.0, 4.0),
        )
        .expect("a non-zero direction");
        assert_eq!(mix.dir(), Vec3::new(0.0, 0.6, 0.8));
        let lambda = SampledWavelengths::single(550.0);
        let uv = Vec2::new(0.3, 0.7);
        let tilted = Vec3::new(0.6, 0.0, -0.8);
        for (n, amount) in [
            (Vec3::Z, 0.8),
            (-Vec3::Z, 0.8),
            (Vec3::Y, 0.6),
            (Vec3::X, 0.0),
            (tilted, 0.64),
            (Vec3::new(0.0, 0.6, 0.8), 1.0),
        ] {
            let expected = amount * 0.9 + (1.0 - amount) * 0.1;
            let close = |v: f32| (v - expected).abs() < 1e-6;
            assert!(close(mix.eval_1(facing(n, uv))), "{n}");
            assert!(close(mix.eval(facing(n, uv), &lambda)[0]), "{n}");
            assert!(close(mix.eval_3(facing(n, uv)).y), "{n}");
        }
        // Without a normal (a lookup by (u, v) alone) the blend is tex2.
        assert!((mix.eval_1(uv) - 0.1).abs() < 1e-6);
        assert_eq!(mix.max_value(), 0.9);
        assert_eq!(mix.min_value(), 0.1);
    }

    /// The operands are looked up at the same point: a checkerboard keeps its squares.
    #[test]
    fn textured_operands_keep_their_pattern_and_gradient() {
        let checks = Texture::Checkerboard(Box::new(Checkerboard {
            color0: Texture::constant(0.75),
            color1: Texture::constant(0.25),
            to_uv: UvTransform::IDENTITY,
        }));
        let mix = DirectionMixTexture::new(checks.clone(), Texture::constant(0.5), Vec3::X)
            .expect("a non-zero direction");
        let n = Vec3::new(0.5, 0.0, 0.75_f32.sqrt());
        for uv in [Vec2::new(0.25, 0.25), Vec2::new(0.75, 0.25)] {
            let expected = 0.5 * checks.eval_1(uv) + 0.5 * 0.5;
            assert!((mix.eval_1(facing(n, uv)) - expected).abs() < 1e-6);
            assert_eq!(mix.eval_1_grad(facing(n, uv)), Vec2::ZERO);
        }
    }

    #[test]
    fn a_zero_direction_is_refused() {
        let mix =
            |dir| DirectionMixTexture::new(Texture::constant(1.0), Texture::constant(0.0), dir);
        assert!(mix(Vec3::ZERO).is_none());
        assert!(mix(Vec3::new(f32::NAN, 0.0, 1.0)).is_none());
    }
}
