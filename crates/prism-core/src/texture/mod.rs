//! Textures: values that vary over a surface with its (u, v) coordinates (or, for a `volume`
//! texture, with its position). Any BSDF parameter
//! that Mitsuba lets vary (reflectances, roughness, opacity, blend weights, η and k, bump heights,
//! normal maps) is a [`Texture`]; a constant is the common case.
//!
//! A texture is read in one of three ways, fixed when the scene is built:
//! * as a spectrum ([`Texture::eval`]): colours, upsampled from RGB by Jakob & Hanika's model;
//! * as a number ([`Texture::eval_1`]): roughness, opacity, weights, heights;
//! * as a raw RGB triple ([`Texture::eval_3`]): normal maps.
//!
//! A texture is looked up at a [`TexturePoint`]: the surface's (u, v), the mesh attributes
//! interpolated there (for `mesh_attribute`), its world position (for `volume`) and its
//! geometric normal (for `directionmix`); a bare `Vec2` is a point without attributes, position
//! or normal, as emitters look their textures up.

pub mod bitmap;
pub mod checkerboard;
pub mod constant;
pub mod direction_mix;
pub mod mesh_attribute;
pub mod mix;
pub mod scale;
pub mod volume;

use std::sync::Arc;

use glam::{DMat4, Vec2, Vec3};

pub use bitmap::{BitmapTexture, FilterType, TextureUse, WrapMode};
pub use checkerboard::Checkerboard;
pub use direction_mix::DirectionMixTexture;
pub use mesh_attribute::MeshAttributeTexture;
pub use mix::MixTexture;
pub use scale::ScaledTexture;
pub use volume::VolumeTexture;

use crate::dispatch::plugin_class;
use crate::geometry::interaction::AttributeValues;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

plugin_class! {
    /// What every texture answers: its value at a point read as a spectrum, as a number or
    /// as a raw RGB triple, and bounds of its values.
    pub trait TextureValues {
        /// The spectral value at `at` and the wavelengths `lambda`.
        fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum;

        /// The scalar value at `at` (a constant spectrum's value; a non-constant one's mean
        /// over 360–830 nm).
        fn eval_1(&self, at: impl Into<TexturePoint>) -> f32;

        /// The gradient (∂/∂u, ∂/∂v) of [`Self::eval_1`] (for bump mapping); zero where the
        /// texture is piecewise constant.
        fn eval_1_grad(&self, at: impl Into<TexturePoint>) -> Vec2;

        /// The raw RGB value at `at` (normal maps); a constant or checkerboard gives its scalar
        /// value in all three components, a mesh attribute the linear sRGB colour of its
        /// spectrum.
        fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3;

        /// An upper bound of the values (spectral or scalar) the texture takes.
        fn max_value(&self) -> f32;

        /// The smallest value the texture takes (for validating scalar parameters).
        fn min_value(&self) -> f32;

        /// The mean of [`Self::eval_1`] over [0, 1]²: at an image's texel centres, or on a
        /// grid of 256 × 256 cell centres for a pattern ([`mean_over_cells`]).
        fn mean_value(&self) -> f32;

        /// The width over the height of the texture's image, which sets the shape of what
        /// projects it (a projector's field of view); 1 for a texture without an image.
        fn aspect_ratio(&self) -> f64;
    }

    /// A texture.
    #[derive(Clone, Debug)]
    pub enum Texture {
        /// The same value everywhere.
        Constant(Spectrum),
        /// An image (shared between the materials that reference it).
        Bitmap(Arc<BitmapTexture>),
        /// Two textures in a checkerboard pattern.
        Checkerboard(Box<Checkerboard>),
        /// A colour the mesh carries per vertex or per face (Mitsuba's `mesh_attribute`).
        MeshAttribute(MeshAttributeTexture),
        /// A texture times a number-valued texture (pbrt-v4's `scale`).
        Scale(Box<ScaledTexture>),
        /// Two textures blended by a number-valued texture (pbrt-v4's `mix`).
        Mix(Box<MixTexture>),
        /// Two textures blended by the surface normal's direction (pbrt-v4's `directionmix`).
        DirectionMix(Box<DirectionMixTexture>),
        /// A volume read at the surface point's world position (Mitsuba's `volume`).
        Volume(Arc<VolumeTexture>),
    }
}

/// Where a texture is looked up.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexturePoint {
    pub uv: Vec2,
    /// The hit mesh's attributes, interpolated at the point (zero where the mesh has none).
    pub attributes: AttributeValues,
    /// The point's world position (the origin for a lookup by (u, v) alone, which the scene
    /// reader never gives a `volume` texture).
    pub p: Vec3,
    /// The surface's geometric normal (world space, unit; zero for a lookup by (u, v) alone,
    /// which the scene reader never gives a `directionmix` texture).
    pub n: Vec3,
}

impl From<Vec2> for TexturePoint {
    /// A point of a surface without mesh attributes, position or normal.
    fn from(uv: Vec2) -> TexturePoint {
        TexturePoint {
            uv,
            attributes: AttributeValues::default(),
            p: Vec3::ZERO,
            n: Vec3::ZERO,
        }
    }
}

impl Texture {
    /// The constant `v` everywhere.
    pub fn constant(v: f32) -> Texture {
        Texture::Constant(Spectrum::Constant(v))
    }

    /// Whether the texture, or one it combines, is a [`VolumeTexture`], read at the surface
    /// point's position and without a (u, v) gradient.
    pub fn reads_position(&self) -> bool {
        match self {
            Texture::Volume(_) => true,
            Texture::DirectionMix(m) => m.tex1.reads_position() || m.tex2.reads_position(),
            Texture::Constant(_) | Texture::Bitmap(_) | Texture::MeshAttribute(_) => false,
            Texture::Checkerboard(c) => c.color0.reads_position() || c.color1.reads_position(),
            Texture::Scale(s) => s.texture.reads_position() || s.scale.reads_position(),
            Texture::Mix(m) => {
                m.tex1.reads_position() || m.tex2.reads_position() || m.amount.reads_position()
            }
        }
    }
}

/// The mean of `texture`'s [`TextureValues::eval_1`] at the centres of an `nx` × `ny` grid of
/// cells over [0, 1]².
pub fn mean_over_cells(texture: &impl TextureValues, nx: usize, ny: usize) -> f32 {
    let sum: f64 = (0..nx * ny)
        .map(|cell| {
            let uv = Vec2::new(
                ((cell % nx) as f32 + 0.5) / nx as f32,
                ((cell / nx) as f32 + 0.5) / ny as f32,
            );
            f64::from(texture.eval_1(uv))
        })
        .sum();
    (sum / (nx * ny) as f64) as f32
}

/// Mitsuba's `to_uv`: an affine map of texture coordinates, (u, v) ↦ A (u, v) + b. A 4 × 4
/// `<transform>` is read as Mitsuba 3 does: rows and columns 0, 1 and 3 (x, y, translation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// Rows (a₀₀, a₀₁, b₀) and (a₁₀, a₁₁, b₁).
    pub rows: [[f32; 3]; 2],
}

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform {
        rows: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    };

    pub fn from_matrix(m: &DMat4) -> UvTransform {
        // glam matrices are column-major: m.col(j)[i] is row i, column j.
        let entry = |i: usize, j: usize| m.col(j)[i] as f32;
        UvTransform {
            rows: [
                [entry(0, 0), entry(0, 1), entry(0, 3)],
                [entry(1, 0), entry(1, 1), entry(1, 3)],
            ],
        }
    }

    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [r0, r1] = self.rows;
        Vec2::new(
            r0[0] * uv.x + r0[1] * uv.y + r0[2],
            r1[0] * uv.x + r1[1] * uv.y + r1[2],
        )
    }

    /// The gradient of f(A uv + b) with respect to uv, given the gradient `g` of f: Aᵀ g.
    #[inline]
    pub fn pull_back_gradient(&self, g: Vec2) -> Vec2 {
        let [r0, r1] = self.rows;
        Vec2::new(r0[0] * g.x + r1[0] * g.y, r0[1] * g.x + r1[1] * g.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_transform_keeps_the_translation_of_a_4x4_matrix() {
        // scale (2, 3) then translate (0.25, 0.5): u' = 2u + 0.25, v' = 3v + 0.5 (as Mitsuba 3.9
        // reads `<scale x="2" y="3"/><translate x="0.25" y="0.5"/>`).
        let m = DMat4::from_translation(glam::DVec3::new(0.25, 0.5, 0.0))
            * DMat4::from_scale(glam::DVec3::new(2.0, 3.0, 1.0));
        let t = UvTransform::from_matrix(&m);
        assert_eq!(t.apply(Vec2::new(1.0, 1.0)), Vec2::new(2.25, 3.5));
        assert_eq!(
            t.pull_back_gradient(Vec2::new(1.0, 1.0)),
            Vec2::new(2.0, 3.0)
        );
    }
}
