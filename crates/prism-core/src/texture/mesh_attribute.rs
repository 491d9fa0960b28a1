//! Mitsuba's `mesh_attribute` texture: a colour the hit mesh carries per vertex (interpolated
//! with the hit's barycentric coordinates) or per face (`src/textures/mesh_attribute.cpp`,
//! `Mesh::eval_attribute`).
//!
//! A colour attribute holds linear RGB; as in Mitsuba 3.9's spectral variants (measured: the
//! interpolated coefficients of the upsampled corner spectra came out up to 1.5 % off its
//! renders), the RGB is interpolated and the result upsampled (Jakob & Hanika 2019) at each
//! lookup: at barycentrics b, the spectrum of Σ bᵢ rgbᵢ, times the texture's `scale`. An
//! attribute of one channel (a number v, held as the grey (v, v, v)) reads as that number, or
//! as a colour as the constant spectrum v.
//!
//! A scene reads at most [`MAX_MESH_ATTRIBUTES`] distinct attribute names. Each gets a slot; a
//! mesh fills, at each hit, the slots of the attributes it has ([`AttributeValues`], plain data
//! that the surface interaction carries), and the texture reads its slot.
//!
//! [`MAX_MESH_ATTRIBUTES`]: crate::geometry::interaction::MAX_MESH_ATTRIBUTES

use glam::{Vec2, Vec3};
use wide::f32x4;

use super::{TexturePoint, TextureValues};
use crate::geometry::interaction::AttributeValues;
use crate::spectrum::rgb::{RgbSigmoidPolynomial, RgbToSpectrumTable};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// The texture: which slot it reads and the factor it applies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshAttributeTexture {
    pub slot: u8,
    pub scale: f32,
}

impl MeshAttributeTexture {
    fn polynomial(&self, values: &AttributeValues) -> RgbSigmoidPolynomial {
        RgbToSpectrumTable::srgb().fetch(values.0[usize::from(self.slot)].to_array())
    }
}

impl TextureValues for MeshAttributeTexture {
    #[inline]
    fn eval(&self, at: impl Into<TexturePoint>, lambda: &SampledWavelengths) -> SampledSpectrum {
        let values = &at.into().attributes;
        let lambda = f32x4::from(*lambda.lambdas());
        let value = f32x4::splat(self.scale) * self.polynomial(values).eval4(lambda);
        SampledSpectrum(value.to_array())
    }

    /// A number attribute's value times the texture's `scale` (the scene reader reads only
    /// attributes of one channel as numbers, as Mitsuba does; of a colour this is its red).
    fn eval_1(&self, at: impl Into<TexturePoint>) -> f32 {
        let values = &at.into().attributes;
        self.scale * values.0[usize::from(self.slot)].x
    }

    fn eval_1_grad(&self, _at: impl Into<TexturePoint>) -> Vec2 {
        Vec2::ZERO
    }

    /// The linear sRGB colour of the spectrum.
    fn eval_3(&self, at: impl Into<TexturePoint>) -> Vec3 {
        let values = &at.into().attributes;
        Vec3::from(self.polynomial(values).linear_srgb()) * self.scale
    }

    fn max_value(&self) -> f32 {
        self.scale
    }

    fn min_value(&self) -> f32 {
        0.0
    }

    /// No (u, v) map: its bound.
    fn mean_value(&self) -> f32 {
        self.scale
    }

    fn aspect_ratio(&self) -> f64 {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::WavelengthSampling;

    #[test]
    fn a_colour_reads_back_as_its_spectrum() {
        let table = RgbToSpectrumTable::srgb();
        for rgb in [[0.2, 0.5, 0.8], [0.0; 3], [1.0; 3], [0.9, 0.1, 0.0]] {
            let polynomial = table.fetch(rgb);
            let mut values = AttributeValues::default();
            values.0[2] = Vec3::from(rgb);
            let texture = MeshAttributeTexture {
                slot: 2,
                scale: 0.5,
            };
            let lambda = SampledWavelengths::sample(0.3, WavelengthSampling::default());
            let at = TexturePoint {
                uv: glam::Vec2::ZERO,
                attributes: values,
                ..TexturePoint::default()
            };
            let value = texture.eval(at, &lambda);
            for i in 0..4 {
                let expected = 0.5 * polynomial.eval(lambda.lambda(i));
                assert!((value[i] - expected).abs() <= 1e-6, "{rgb:?}: {value:?}");
            }
        }
    }

    #[test]
    fn a_number_reads_back_as_itself_and_as_a_constant_spectrum() {
        let mut values = AttributeValues::default();
        values.0[1] = Vec3::splat(0.3);
        let texture = MeshAttributeTexture {
            slot: 1,
            scale: 0.5,
        };
        let at = TexturePoint {
            uv: glam::Vec2::ZERO,
            attributes: values,
            ..TexturePoint::default()
        };
        assert_eq!(texture.eval_1(at), 0.15);
        let lambda = SampledWavelengths::sample(0.7, WavelengthSampling::default());
        let value = texture.eval(at, &lambda);
        for i in 0..4 {
            assert!((value[i] - 0.15).abs() <= 1e-6, "{value:?}");
        }
    }
}
