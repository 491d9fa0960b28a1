//! Light sources and the choice among them.
//!
//! Direct lighting follows the lecture's split of the reflection integral into a sum over lights
//! ("Direct Light Sampling"): area lights are integrated over their surface (or, for spheres,
//! over the cone they subtend); point, spot and projector lights are single points and directional lights
//! single directions (Dirac deltas, reached only by light sampling); environment lights
//! (`constant`, `envmap`, `sunsky`) surround the scene at infinity and are also found by rays that leave
//! it, so they take part in multiple importance sampling like area lights.
//!
//! | Mitsuba emitter | file | sampled by |
//! | --- | --- | --- |
//! | `area` | [`area`] | the shape: spheres by visible cone, other shapes by area; a textured radiance by the texture through the uv map |
//! | `directionalarea` | [`directionalarea`] | not at all (a delta along the shape's normal, found by light traced from it only) |
//! | `point` | [`point`] | its position (delta) |
//! | `spot` | [`spot`] | its position (delta) |
//! | `projector` | [`projector`] | its position (delta) |
//! | `directional` | [`directional`] | its direction (delta) |
//! | `constant` | [`constant`] | uniform directions |
//! | `envmap` | [`envmap`] | directions ∝ luminance · sin θ in the lat-long image |
//! | `equal_area_envmap` (pbrt-v4's image `infinite`) | [`equal_area_envmap`] | directions ∝ luminance in the equal-area image |
//! | `sunsky` | [`sunsky`] | the sky's luminance over (φ, cos θ), and the sun's cone |
//!
//! For tracing light from the lights' side (the particle tracer), every light also draws rays
//! of its emission ([`LightSource::sample_emission`]): area lights a point by area and a
//! cosine-distributed direction, directional area lights a point by area and its normal, point
//! lights a uniform direction, spot lights a direction in their cone, projectors a point of
//! their image, and lights at infinity a direction as for light sampling and a point on the
//! disk of the scene's bounding sphere facing it.

pub mod area;
pub mod bounds;
pub mod constant;
pub mod directional;
pub mod directionalarea;
pub mod envmap;
pub mod equal_area_envmap;
pub mod point;
pub mod projector;
pub mod sampler;
pub mod spot;
pub mod sunsky;

use glam::{Vec2, Vec3};

use crate::dispatch::plugin_class;
use crate::geometry::Primitive;
use crate::math::Frame;
use crate::sampling::warp::sample_uniform_disk_concentric;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
pub use area::AreaLight;
pub use bounds::{LightBounds, Receiver};
pub use constant::ConstantLight;
pub use directional::DirectionalLight;
pub use directionalarea::DirectionalAreaLight;
pub use envmap::EnvironmentMap;
pub use equal_area_envmap::EqualAreaEnvmap;
pub use point::PointLight;
pub use projector::Projector;
pub use sampler::{LightSampler, LightSelection};
pub use spot::SpotLight;
pub use sunsky::{Sunsky, SunskySettings};

plugin_class! {
    /// What every light answers: how it lights a point, how much it emits, where it is, and
    /// whether rays that leave the scene see it.
    pub trait LightSource {
        /// Samples light arriving at the query's point from this light. None where the light
        /// sends nothing towards it.
        fn sample_incident(&self, query: LightQuery<'_>) -> Option<LightSample>;

        /// Draws a ray of the light's emission, a point and a direction, for tracing light from
        /// the lights' side (Mitsuba's `Emitter::sample_ray`). None where the draw finds no
        /// emission.
        fn sample_emission(&self, query: EmissionQuery<'_>) -> Option<EmissionSample>;

        /// Emitted power Φ, summarised as a luminance-weighted scalar (watts weighted by ȳ):
        /// the light sampler chooses lights in proportion to it. Lights at infinity count the
        /// flux they send into the scene's bounding sphere, so [`Self::set_scene_bounds`] must
        /// come first.
        fn power(&self, shapes: &[Primitive]) -> f32;

        /// Where the light is, for choosing it by importance ([`bounds`]): the box of its
        /// shape, or its position; None for lights at infinity. The power is left 0 (the
        /// sampler fills it in).
        fn bounds(&self, shapes: &[Primitive]) -> Option<LightBounds>;

        /// Tells a light at infinity the scene's extent (Mitsuba's `Emitter::set_scene`);
        /// lights at a finite place ignore it.
        fn set_scene_bounds(&mut self, bounds: BoundingSphere);

        /// The light as rays that leave the scene see it (Mitsuba's "environment emitter", of
        /// which a scene has at most one); None for lights that no ray can hit at infinity.
        fn as_environment(&self) -> Option<Environment<'_>>;

        /// Whether this light surrounds the scene and is seen by rays that leave it.
        fn is_environment(&self) -> bool {
            self.as_environment().is_some()
        }

        /// Radiance arriving along a ray that leaves the scene in direction `d` (unit): the
        /// environment's emission; zero for other lights.
        fn environment_radiance(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
            self.as_environment()
                .map_or(SampledSpectrum::ZERO, |e| e.radiance(d, lambda))
        }

        /// Density per unit solid angle with which [`Self::sample_incident`] picks the
        /// direction `d` (unit) of an environment light; zero for other lights.
        fn environment_pdf(&self, d: Vec3) -> f32 {
            self.as_environment().map_or(0.0, |e| e.pdf(d))
        }
    }

    /// A light source of the scene.
    #[derive(Clone, Debug)]
    pub enum Light {
        Area(AreaLight),
        DirectionalArea(DirectionalAreaLight),
        Point(PointLight),
        Spot(SpotLight),
        Projector(Projector),
        Directional(DirectionalLight),
        Constant(ConstantLight),
        Envmap(EnvironmentMap),
        EqualAreaEnvmap(EqualAreaEnvmap),
        Sunsky(Box<Sunsky>),
    }
}

/// What [`LightSource::sample_incident`] is asked, as pbrt-v4's `LightSampleContext` with the
/// random numbers: the receiving point and the instant, what the light may be made of, and the
/// numbers to draw the sample with.
#[derive(Clone, Copy, Debug)]
pub struct LightQuery<'a> {
    /// The world's primitives, which area lights are made of.
    pub shapes: &'a [Primitive],
    /// The receiving point.
    pub reference: Vec3,
    /// The instant, for shapes that move.
    pub time: f32,
    /// The random number that chooses among a light's sampling strategies or parts.
    pub u_choice: f32,
    /// The random numbers that draw the point or direction.
    pub u: Vec2,
    /// The wavelengths the radiance is sampled at.
    pub lambda: &'a SampledWavelengths,
}

/// What [`LightSource::sample_emission`] is asked: what the light may be made of, the
/// instant, the wavelengths and the random numbers.
#[derive(Clone, Copy, Debug)]
pub struct EmissionQuery<'a> {
    /// The world's primitives, which area lights are made of.
    pub shapes: &'a [Primitive],
    /// The instant, for shapes that move.
    pub time: f32,
    /// The random number that chooses among a light's parts (a mesh's triangle).
    pub u_choice: f32,
    /// The random numbers that draw the point.
    pub u_position: Vec2,
    /// The random numbers that draw the direction.
    pub u_direction: Vec2,
    /// The wavelengths the emission is sampled at.
    pub lambda: &'a SampledWavelengths,
}

/// A ray of emitted light and its weight L_e |cos θ| / (p_A · p_ω): the radiance leaving the
/// point along the ray over the densities of the point per unit area and of the direction per
/// unit solid angle (Veach 1997, §10.2). For a point source it is I / p_ω; for a light at
/// infinity, the radiance times the area of the disk the point is drawn on over p_ω.
#[derive(Clone, Copy, Debug)]
pub struct EmissionSample {
    /// Where the ray starts.
    pub p: Vec3,
    /// The geometric normal there (zero for point sources and lights at infinity).
    pub n: Vec3,
    /// The unit direction the light travels in.
    pub d: Vec3,
    pub weight: SampledSpectrum,
}

/// A light at infinity (`directional`, `constant`, `envmap`, `sunsky`): it lights every point
/// from directions alone, has no place for the light sampler to bound, and is told the scene's
/// bounding sphere (Mitsuba's `Emitter::set_scene`), beyond which its shadow rays end and
/// through which its power is counted. Its [`LightSource`] follows.
pub trait LightAtInfinity {
    /// Whether the light arrives from a single direction (a Dirac delta: `directional`).
    const IS_DELTA: bool;

    /// Draws the direction light arrives from with the random numbers `u`.
    fn sample_direction(&self, u: Vec2, lambda: &SampledWavelengths) -> Option<DirectionSample>;

    /// [`LightSource::as_environment`].
    fn environment(&self) -> Option<Environment<'_>>;

    /// [`LightSource::power`]: the flux entering the scene's bounding sphere.
    fn flux(&self) -> f32;

    /// The scene's bounding sphere, as [`LightSource::set_scene_bounds`] gave it.
    fn scene(&self) -> &BoundingSphere;

    fn scene_mut(&mut self) -> &mut BoundingSphere;
}

/// Light arriving from a direction at infinity.
#[derive(Clone, Copy, Debug)]
pub struct DirectionSample {
    /// The unit direction towards the light.
    pub wi: Vec3,
    /// The radiance along `wi` (for a delta: the irradiance).
    pub radiance: SampledSpectrum,
    /// The density per unit solid angle (1 for a delta).
    pub pdf: f32,
}

impl<L: LightAtInfinity> LightSource for L {
    #[inline]
    fn sample_incident(&self, query: LightQuery<'_>) -> Option<LightSample> {
        let s = self.sample_direction(query.u, query.lambda)?;
        Some(LightSample::from_infinity(
            self.scene(),
            query.reference,
            s.wi,
            s.radiance,
            s.pdf,
            L::IS_DELTA,
        ))
    }

    /// The direction from [`LightAtInfinity::sample_direction`], and the point uniformly on
    /// the disk of the scene's bounding sphere (radius R) facing it, outside the sphere:
    /// weight L · πR² / p_ω (for `directional`, whose "radiance" is the irradiance and p_ω 1,
    /// E · πR²), as Mitsuba's `sample_ray` of its lights at infinity.
    fn sample_emission(&self, query: EmissionQuery<'_>) -> Option<EmissionSample> {
        let s = self.sample_direction(query.u_direction, query.lambda)?;
        if !(s.pdf > 0.0) || s.radiance.is_black() {
            return None;
        }
        let scene = self.scene();
        let disk = sample_uniform_disk_concentric(query.u_position) * scene.radius;
        let frame = Frame::from_normal(s.wi);
        let p = scene.center + scene.radius * s.wi + frame.to_world(Vec3::new(disk.x, disk.y, 0.0));
        let area = std::f32::consts::PI * scene.radius * scene.radius;
        Some(EmissionSample {
            p,
            n: Vec3::ZERO,
            d: -s.wi,
            weight: s.radiance * (area / s.pdf),
        })
    }

    fn power(&self, _shapes: &[Primitive]) -> f32 {
        self.flux()
    }

    fn bounds(&self, _shapes: &[Primitive]) -> Option<LightBounds> {
        None
    }

    fn set_scene_bounds(&mut self, bounds: BoundingSphere) {
        *self.scene_mut() = bounds;
    }

    fn as_environment(&self) -> Option<Environment<'_>> {
        self.environment()
    }
}

/// A light at infinity as the rays that leave the scene see it.
#[derive(Clone, Copy, Debug)]
pub enum Environment<'a> {
    Constant(&'a ConstantLight),
    Envmap(&'a EnvironmentMap),
    EqualAreaEnvmap(&'a EqualAreaEnvmap),
    Sunsky(&'a Sunsky),
}

impl Environment<'_> {
    /// The radiance arriving along a ray that leaves the scene in direction `d` (unit).
    #[inline]
    pub fn radiance(&self, d: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Environment::Constant(light) => light.radiance(lambda),
            Environment::Envmap(light) => light.radiance(d, lambda),
            Environment::EqualAreaEnvmap(light) => light.radiance(d, lambda),
            Environment::Sunsky(light) => light.radiance(d, lambda),
        }
    }

    /// The density per unit solid angle with which the light's `sample_incident` draws `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        match self {
            Environment::Constant(light) => light.pdf(),
            Environment::Envmap(light) => light.pdf(d),
            Environment::EqualAreaEnvmap(light) => light.pdf(d),
            Environment::Sunsky(light) => light.pdf(d),
        }
    }
}

/// Incident light sampled at a point: where it comes from and how much arrives.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// The point on the light; for lights at infinity, a point beyond the scene in direction
    /// `wi`, so that a shadow ray to it crosses the whole scene.
    pub p: Vec3,
    /// Geometric normal at `p` (zero for point, spot and infinite lights), for the shadow ray's
    /// far end.
    pub n: Vec3,
    /// Unit direction from the receiving point towards `p`.
    pub wi: Vec3,
    /// Radiance arriving along `wi` (for a point light: intensity / distance²; for a
    /// directional light: its irradiance).
    pub radiance: SampledSpectrum,
    /// Density of the sample per unit solid angle, or 1 for delta lights.
    pub pdf: f32,
    /// Whether the light is a Dirac delta (a point or a direction): no other strategy can find
    /// it.
    pub is_delta: bool,
}

impl LightSample {
    /// Light from the point `p` of a point, spot or projector light, arriving along `wi`: a
    /// delta, whose shadow ray ends at `p`.
    #[inline]
    pub fn from_point(p: Vec3, wi: Vec3, radiance: SampledSpectrum) -> LightSample {
        LightSample {
            p,
            n: Vec3::ZERO,
            wi,
            radiance,
            pdf: 1.0,
            is_delta: true,
        }
    }

    /// Light from a light at infinity arriving at `reference` along `wi`: the shadow ray ends
    /// beyond the scene's bounding sphere `scene`.
    #[inline]
    pub fn from_infinity(
        scene: &BoundingSphere,
        reference: Vec3,
        wi: Vec3,
        radiance: SampledSpectrum,
        pdf: f32,
        is_delta: bool,
    ) -> LightSample {
        LightSample {
            p: scene.point_beyond(reference, wi),
            n: Vec3::ZERO,
            wi,
            radiance,
            pdf,
            is_delta,
        }
    }
}

/// The direction from `reference` towards the point `p` and the squared distance between them,
/// for lights at a point; None where they coincide.
#[inline]
pub(crate) fn towards_point(p: Vec3, reference: Vec3) -> Option<(Vec3, f32)> {
    let d = p - reference;
    let dist2 = d.length_squared();
    (dist2 > 0.0).then(|| (d / dist2.sqrt(), dist2))
}

/// The sphere that bounds the scene's geometry. Lights at infinity use it, as Mitsuba's
/// `set_scene` does, to place shadow-ray end points beyond the scene and to define their power
/// (the flux they send into it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    pub center: Vec3,
    pub radius: f32,
}

impl BoundingSphere {
    /// The sphere around an axis-aligned box (centre, half diagonal), enlarged by a relative 10⁻⁴
    /// as Mitsuba enlarges it by its ray epsilon; a tiny sphere at the origin for an empty scene.
    pub fn around_box(bounds: Option<(Vec3, Vec3)>) -> BoundingSphere {
        const EPSILON: f32 = 1e-4;
        match bounds {
            Some((min, max)) if min.is_finite() && max.is_finite() => {
                let center = 0.5 * (min + max);
                BoundingSphere {
                    center,
                    radius: ((max - center).length() * (1.0 + EPSILON)).max(EPSILON),
                }
            }
            _ => BoundingSphere {
                center: Vec3::ZERO,
                radius: EPSILON,
            },
        }
    }

    /// A point in direction `wi` from `reference` that is outside the sphere (twice the larger
    /// of the radius and the reference's distance from the centre, as Mitsuba places it).
    pub fn point_beyond(&self, reference: Vec3, wi: Vec3) -> Vec3 {
        let distance = 2.0 * self.radius.max((reference - self.center).length());
        reference + wi * distance
    }
}

impl Default for BoundingSphere {
    fn default() -> Self {
        BoundingSphere::around_box(None)
    }
}
