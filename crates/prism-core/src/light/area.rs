//! Mitsuba's `area` emitter: a shape that emits radiance from the side its normal points to.
//!
//! ```xml
//! <shape type="rectangle">
//!     <emitter type="area">
//!         <rgb name="radiance" value="17, 12, 4"/>
//!     </emitter>
//! </shape>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! The radiance may also be a texture (`<texture type="bitmap" name="radiance">`, or a
//! `checkerboard`), looked up at the surface's texture coordinates; as Mitsuba 3 reads it, its
//! colours are upsampled as reflectances are, with no D65 factor (an `<rgb>` radiance has one).
//!
//! A uniform emitter is sampled by its shape ([`crate::geometry::Primitive::sample_from`]):
//! spheres by the cone of directions they subtend (uniform in solid angle, so no sample is wasted
//! on the far side; the lecture's "Direct Light Sampling"), other shapes uniformly by area,
//! triangle meshes choosing a triangle by area through an alias table. As in Mitsuba, an
//! emitting shape that names no BSDF gets a black one.
//!
//! A textured emitter is sampled, as Mitsuba's `AreaLight::sample_direction` does, by its
//! texture: (u, v) from a piecewise-constant density over [0, 1]² proportional to the
//! texture's luminance, mapped onto the shape by the inverse of its uv parametrisation
//! ([`crate::geometry::Shape::at_uv`]). A density p_uv over uv becomes one over area by the
//! Jacobian of the map, p_A = p_uv / |∂p/∂u × ∂p/∂v|, which corrects for meshes whose uv layout
//! does not preserve area, and one over solid angle by p_ω = p_A · d² / |cos θ| (pbrt-v4
//! §4.2.3). Unlike Mitsuba, this strategy is mixed with the shape's own one, taken with
//! probability [`SHAPE_STRATEGY_FRACTION`] (defensive importance sampling, Hesterberg 1995):
//! p = f · p_shape + (1 − f) · p_texture. The mixture is positive wherever the surface is, so
//! the estimate stays unbiased where the texture strategy cannot reach: surface whose texture
//! coordinates leave [0, 1]² (a repeating texture), mesh triangles hidden behind others in uv
//! space, cells of zero weight that bilinear filtering lights from a neighbour. A moving shape
//! (an instance with an animated transform) is sampled by its shape alone.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::{
    BoundingSphere, EmissionQuery, EmissionSample, Environment, LightBounds, LightQuery,
    LightSample, LightSource,
};
use crate::geometry::aggregate::AggregateElement;
use crate::geometry::shape::area_to_solid_angle;
use crate::geometry::{Primitive, Shape, ShapeGeometry, ShapeSampling, SurfaceSample};
use crate::math::Frame;
use crate::sampling::distribution::PiecewiseConstant2D;
use crate::sampling::warp::sample_cosine_hemisphere;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use crate::texture::Texture;
use crate::texture::TextureValues;

/// The probability with which a textured emitter is sampled by its shape rather than by its
/// texture (see the module's text).
pub const SHAPE_STRATEGY_FRACTION: f32 = 0.1;

/// Cells per side of the sampling density of a texture that is not an image (a checkerboard).
const PATTERN_RESOLUTION: usize = 256;
/// The most cells per side of the sampling density (an image's pixels, up to this many).
const MAX_RESOLUTION: usize = 4096;

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// Index of the emitting shape in the scene.
    pub shape: u32,
    pub radiance: Texture,
    /// For a textured radiance, the density over uv ∝ its luminance.
    texture_density: Option<Box<PiecewiseConstant2D>>,
    /// The mean luminance of the radiance over [0, 1]² (its luminance, if uniform).
    mean_luminance: f32,
    /// How the shape is sampled from a reference point.
    pub sampling: ShapeSampling,
}

/// The mean luminance of `texture` over [0, 1]², from the cells of its sampling density.
pub(super) fn mean_luminance(texture: &Texture) -> f32 {
    luminance_density(texture).1
}

/// The density over [0, 1]² in proportion to the texture's luminance at cell centres, with the
/// texture's image resolution (or [`PATTERN_RESOLUTION`]), and its mean.
fn luminance_density(texture: &Texture) -> (PiecewiseConstant2D, f32) {
    let (nx, ny) = match texture {
        Texture::Bitmap(bitmap) => (
            bitmap.width.clamp(1, MAX_RESOLUTION),
            bitmap.height.clamp(1, MAX_RESOLUTION),
        ),
        Texture::Constant(_)
        | Texture::Checkerboard(_)
        | Texture::MeshAttribute(_)
        | Texture::Scale(_)
        | Texture::Mix(_)
        | Texture::DirectionMix(_)
        | Texture::Volume(_) => (PATTERN_RESOLUTION, PATTERN_RESOLUTION),
    };
    let weights: Vec<f32> = (0..nx * ny)
        .map(|cell| {
            let uv = Vec2::new(
                ((cell % nx) as f32 + 0.5) / nx as f32,
                ((cell / nx) as f32 + 0.5) / ny as f32,
            );
            let value = texture.eval_1(uv);
            if value.is_finite() {
                value.max(0.0)
            } else {
                0.0
            }
        })
        .collect();
    let mean = (weights.iter().map(|&w| f64::from(w)).sum::<f64>() / weights.len() as f64) as f32;
    (PiecewiseConstant2D::new(&weights, nx, ny), mean)
}

impl AreaLight {
    /// The emitter on shape `shape` with radiance `radiance`; a texture other than a constant is
    /// importance sampled (see the module's text).
    pub fn new(shape: u32, radiance: Texture) -> AreaLight {
        match &radiance {
            Texture::Constant(spectrum) => AreaLight::uniform(shape, spectrum.clone()),
            texture => {
                let (density, mean_luminance) = luminance_density(texture);
                AreaLight {
                    shape,
                    texture_density: Some(Box::new(density)),
                    mean_luminance,
                    radiance,
                    sampling: ShapeSampling::default(),
                }
            }
        }
    }

    /// The emitter of uniform radiance `radiance` on shape `shape`.
    pub fn uniform(shape: u32, radiance: Spectrum) -> AreaLight {
        AreaLight {
            shape,
            mean_luminance: radiance.luminance(),
            radiance: Texture::Constant(radiance),
            texture_density: None,
            sampling: ShapeSampling::default(),
        }
    }

    /// The same emitter, its shape sampled by `sampling`.
    pub fn sampled_by(self, sampling: ShapeSampling) -> AreaLight {
        AreaLight { sampling, ..self }
    }

    /// Radiance leaving the point with texture coordinates `uv` and shading normal `n` in
    /// direction `w` (one-sided).
    #[inline]
    pub fn emitted(
        &self,
        uv: Vec2,
        n: Vec3,
        w: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if n.dot(w) > 0.0 {
            self.radiance.eval(uv, lambda)
        } else {
            SampledSpectrum::ZERO
        }
    }

    /// The texture's density and the shape it maps onto, if the texture strategy applies.
    #[inline]
    fn texture_strategy<'a>(
        &'a self,
        primitive: &'a Primitive,
    ) -> Option<(&'a PiecewiseConstant2D, &'a Shape)> {
        match (&self.texture_density, primitive) {
            (Some(density), Primitive::Shape(shape)) => Some((density, shape)),
            (None, _) | (Some(_), Primitive::Instance(_)) => None,
        }
    }

    /// The texture strategy's density per unit solid angle at `reference` for the surface
    /// point `s` (its uv, triangle, position and geometric normal): p_uv / |∂p/∂u × ∂p/∂v| ·
    /// d² / |cos θ|; zero where the uv map does not lead to that point.
    fn texture_pdf(
        density: &PiecewiseConstant2D,
        shape: &Shape,
        reference: Vec3,
        s: &SurfaceSample,
    ) -> f32 {
        let Some(jacobian) = shape.uv_jacobian_at(s.primitive, s.uv) else {
            return 0.0;
        };
        if !(jacobian > 0.0) {
            return 0.0;
        }
        area_to_solid_angle(density.pdf(s.uv) / jacobian, reference, s.p, s.n).unwrap_or(0.0)
    }

    /// A point uniformly distributed over the emitting shape at `time`, density per unit area
    /// (for tracing light from the emitter, and for connecting its points to the camera).
    pub fn sample_position(
        &self,
        shapes: &[Primitive],
        time: f32,
        u_choice: f32,
        u: Vec2,
    ) -> Option<SurfaceSample> {
        let s = shapes[self.shape as usize].sample_area(time, u_choice, u)?;
        (s.pdf > 0.0 && s.pdf.is_finite()).then_some(s)
    }

    /// Density per unit solid angle with which [`Self::sample_incident`] from `reference` at
    /// `time` finds the surface point `s` (its position, geometric normal, uv and triangle, as
    /// a ray hit reports them).
    pub fn pdf_from(
        &self,
        shapes: &[Primitive],
        reference: Vec3,
        time: f32,
        s: &SurfaceSample,
    ) -> f32 {
        let primitive = &shapes[self.shape as usize];
        let shape_pdf = primitive.pdf_from(reference, time, s.p, s.n, self.sampling);
        match self.texture_strategy(primitive) {
            None => shape_pdf,
            Some((density, shape)) => {
                SHAPE_STRATEGY_FRACTION * shape_pdf
                    + (1.0 - SHAPE_STRATEGY_FRACTION)
                        * Self::texture_pdf(density, shape, reference, s)
            }
        }
    }
}

impl LightSource for AreaLight {
    fn sample_incident(&self, query: LightQuery<'_>) -> Option<LightSample> {
        let LightQuery {
            shapes,
            reference,
            time,
            u_choice,
            u,
            lambda,
        } = query;
        let primitive = &shapes[self.shape as usize];
        let s = match self.texture_strategy(primitive) {
            None => primitive.sample_from(reference, time, u_choice, u, self.sampling)?,
            Some((density, shape)) if u_choice < SHAPE_STRATEGY_FRACTION => {
                let s = primitive.sample_from(
                    reference,
                    time,
                    u_choice / SHAPE_STRATEGY_FRACTION,
                    u,
                    self.sampling,
                )?;
                let texture_pdf = Self::texture_pdf(density, shape, reference, &s);
                SurfaceSample {
                    pdf: SHAPE_STRATEGY_FRACTION * s.pdf
                        + (1.0 - SHAPE_STRATEGY_FRACTION) * texture_pdf,
                    ..s
                }
            }
            Some((density, shape)) => {
                let uv = density.sample(u);
                let (s, jacobian) = shape.at_uv(uv)?;
                if !(jacobian > 0.0) {
                    return None;
                }
                let texture_pdf =
                    area_to_solid_angle(density.pdf(uv) / jacobian, reference, s.p, s.n)?;
                let shape_pdf = primitive.pdf_from(reference, time, s.p, s.n, self.sampling);
                SurfaceSample {
                    pdf: SHAPE_STRATEGY_FRACTION * shape_pdf
                        + (1.0 - SHAPE_STRATEGY_FRACTION) * texture_pdf,
                    ..s
                }
            }
        };
        let d = s.p - reference;
        let dist = d.length();
        if !(dist > 0.0) || !(s.pdf > 0.0) || !s.pdf.is_finite() {
            return None;
        }
        let wi = d / dist;
        let radiance = self.emitted(s.uv, s.shading_n, -wi, lambda);
        if radiance.is_black() {
            return None;
        }
        Some(LightSample {
            p: s.p,
            n: s.n,
            wi,
            radiance,
            pdf: s.pdf,
            is_delta: false,
        })
    }

    /// A point uniformly over the shape's area (density 1/A) and a cosine-distributed direction
    /// about its shading normal (density cos θ / π): weight L_e · π · A. A textured radiance
    /// is not importance sampled here; its value at the point enters the weight.
    fn sample_emission(&self, query: EmissionQuery<'_>) -> Option<EmissionSample> {
        let s = self.sample_position(query.shapes, query.time, query.u_choice, query.u_position)?;
        let local = sample_cosine_hemisphere(query.u_direction);
        if !(local.z > 0.0) {
            return None;
        }
        let d = Frame::from_normal(s.shading_n).to_world(local);
        let radiance = self.emitted(s.uv, s.shading_n, d, query.lambda);
        if radiance.is_black() {
            return None;
        }
        Some(EmissionSample {
            p: s.p,
            n: s.n,
            d,
            weight: radiance * (std::f32::consts::PI / s.pdf),
        })
    }

    /// Φ = π · A · L for a one-sided Lambertian emitter, with L the luminance of the radiance;
    /// for a texture, its mean luminance over [0, 1]² (exact when the uv map spreads [0, 1]²
    /// evenly over the surface, otherwise a weight for choosing the light).
    fn power(&self, shapes: &[Primitive]) -> f32 {
        PI * shapes[self.shape as usize].area() * self.mean_luminance
    }

    fn bounds(&self, shapes: &[Primitive]) -> Option<LightBounds> {
        let (lo, hi) = shapes[self.shape as usize].bounds();
        Some(LightBounds::around_box(lo, hi, 0.0))
    }

    fn set_scene_bounds(&mut self, _bounds: BoundingSphere) {}

    fn as_environment(&self) -> Option<Environment<'_>> {
        None
    }
}
