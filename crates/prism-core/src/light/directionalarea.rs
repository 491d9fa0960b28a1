//! Mitsuba 3's `directionalarea` emitter: a shape that emits only along its normal.
//!
//! ```xml
//! <shape type="rectangle">
//!     <emitter type="directionalarea">
//!         <rgb name="radiance" value="1"/>
//!     </emitter>
//! </shape>
//! ```
//! Its parameters and their defaults are listed in docs/plugins.md.
//!
//! Each point x of the shape emits a beam along its shading normal n(x): the radiance is
//! L(x) δ(ω − n(x)), so `radiance` L is a flux per unit area (W m⁻²), the irradiance the beam
//! brings a surface facing it. A surface tilted by θ against the beam receives E = L cos θ, and
//! the light's power is Φ = ∫ L dA = L · A (Mitsuba's `DirectionalArea::sample_ray`, whose
//! weight is the area times the radiance).
//!
//! Being a Dirac delta in direction, the emission is found by no ray and no light sample:
//! as in Mitsuba, the shape looks black and a light sample that chooses it brings nothing.
//! Only estimators that trace light from the lights (`ptracer`) render what it lights:
//! [`LightSource::sample_emission`] draws a point uniformly by area (density 1/A) and the
//! direction n, with weight L / (1/A) = L · A.
//!
//! The radiance may be a texture, looked up at the point's texture coordinates, as for `area`.

use super::{
    BoundingSphere, EmissionQuery, EmissionSample, Environment, LightBounds, LightQuery,
    LightSample, LightSource, area,
};
use crate::geometry::Primitive;
use crate::geometry::aggregate::AggregateElement;
use crate::texture::{Texture, TextureValues};

#[derive(Clone, Debug)]
pub struct DirectionalAreaLight {
    /// Index of the emitting shape in the scene.
    pub shape: u32,
    /// The flux per unit area sent along the normal.
    pub radiance: Texture,
    /// The mean luminance of the radiance over [0, 1]² (its luminance, if uniform).
    mean_luminance: f32,
}

impl DirectionalAreaLight {
    /// The emitter on shape `shape`, sending `radiance` per unit area along the normal.
    pub fn new(shape: u32, radiance: Texture) -> DirectionalAreaLight {
        let mean_luminance = match &radiance {
            Texture::Constant(spectrum) => spectrum.luminance(),
            texture => area::mean_luminance(texture),
        };
        DirectionalAreaLight {
            shape,
            radiance,
            mean_luminance,
        }
    }
}

impl LightSource for DirectionalAreaLight {
    /// Nothing: no direction drawn towards the shape is its normal but with probability zero.
    fn sample_incident(&self, _query: LightQuery<'_>) -> Option<LightSample> {
        None
    }

    /// A point uniformly by area and its shading normal: weight L / p_A.
    fn sample_emission(&self, query: EmissionQuery<'_>) -> Option<EmissionSample> {
        let s = query.shapes[self.shape as usize].sample_area(
            query.time,
            query.u_choice,
            query.u_position,
        )?;
        if !(s.pdf > 0.0 && s.pdf.is_finite()) {
            return None;
        }
        let radiance = self.radiance.eval(s.uv, query.lambda);
        if radiance.is_black() {
            return None;
        }
        Some(EmissionSample {
            p: s.p,
            n: s.n,
            d: s.shading_n,
            weight: radiance * (1.0 / s.pdf),
        })
    }

    /// Φ = L · A, with L the luminance of the radiance (for a texture, its mean over [0, 1]²).
    fn power(&self, shapes: &[Primitive]) -> f32 {
        shapes[self.shape as usize].area() * self.mean_luminance
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
