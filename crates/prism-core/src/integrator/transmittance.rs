//! What a ray crosses between two points of a scene with participating media: the media it
//! travels in (they change where it crosses a shape that bounds one), and the transmittance of
//! a shadow ray through them and through the surfaces with null lobes, the hook that the
//! volumetric path tracers give to light sampling ([`super::mis::sample_light`]).

use glam::Vec3;

use crate::bsdf::Material;
use crate::geometry::SurfaceInteraction;
use crate::geometry::interaction::SHADOW_EPSILON;
use crate::geometry::offset::offset_ray_origin;
use crate::integrator::SampleContext;
use crate::light::LightSample;
use crate::math::Ray;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

/// The medium a ray leaving `si` in direction `d` travels in, when it was in `current`: the
/// medium on the side it leaves to where the shape names an `interior` or `exterior` medium,
/// `current` where it names none.
#[inline]
pub fn medium_after(
    world: &World,
    si: &SurfaceInteraction,
    d: Vec3,
    current: Option<u32>,
) -> Option<u32> {
    let interface = world.medium_interface(si.shape);
    if interface.is_transition() {
        interface.target(si.n, d)
    } else {
        current
    }
}

/// The transmittance of a shadow ray in its two factors: that of the media it crosses, and the
/// product of the null transmissions of the surfaces it passes (Mitsuba 3's
/// `eval_null_transmission`: 1 for `null`, 1 − R' for `thindielectric`, 1 − α(1 − t_nested)
/// for `mask`). A path crosses the media by free flights, whose densities `volpathmis` weighs
/// by MIS, and the surfaces by choosing a null lobe, which is no scattering vertex.
#[derive(Clone, Copy, Debug)]
pub struct ShadowTransmittance {
    pub media: SampledSpectrum,
    pub surfaces: SampledSpectrum,
}

impl ShadowTransmittance {
    /// Nothing in the way (vacuum).
    pub const ONE: ShadowTransmittance = ShadowTransmittance {
        media: SampledSpectrum::ONE,
        surfaces: SampledSpectrum::ONE,
    };

    /// Blocked.
    pub const ZERO: ShadowTransmittance = ShadowTransmittance {
        media: SampledSpectrum::ZERO,
        surfaces: SampledSpectrum::ZERO,
    };

    /// The whole transmittance: media times surfaces.
    #[inline]
    pub fn total(&self) -> SampledSpectrum {
        self.media * self.surfaces
    }

    /// Whether no light passes.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.media.is_black() || self.surfaces.is_black()
    }
}

/// The transmittance from `origin` to `end` at `time` for a ray starting in `medium`: the
/// product of the transmittances of the media crossed (closed form in homogeneous media, ratio
/// tracking in heterogeneous ones) and of the null transmissions of the surfaces crossed; zero
/// when a surface without a null lobe is in the way.
#[inline]
pub fn shadow_transmittance(
    ctx: &mut SampleContext,
    origin: Vec3,
    end: Vec3,
    time: f32,
    medium: Option<u32>,
    lambda: &SampledWavelengths,
) -> ShadowTransmittance {
    shadow_transmittance_crossing(ctx, origin, end, time, medium, lambda, |material, si, d| {
        material.null_transmission(si, -d, lambda)
    })
}

/// [`shadow_transmittance`] with `cross` giving the null transmission of each surface with a
/// null lobe that the ray (unit direction d) crosses, at its hit: the hook by which a
/// polarized path also follows what those surfaces do to the light's polarization.
pub fn shadow_transmittance_crossing(
    ctx: &mut SampleContext,
    origin: Vec3,
    end: Vec3,
    time: f32,
    mut medium: Option<u32>,
    lambda: &SampledWavelengths,
    mut cross: impl FnMut(&Material, &SurfaceInteraction, Vec3) -> SampledSpectrum,
) -> ShadowTransmittance {
    let world = ctx.world();
    let d = (end - origin).normalize();
    let mut o = origin;
    let mut transmittance = ShadowTransmittance::ONE;
    loop {
        let remaining = (end - o).dot(d);
        if !(remaining > 0.0) {
            return transmittance;
        }
        let segment = Ray::new(o, d, remaining, time);
        let hit = ctx.intersect(&segment);
        if let Some(m) = medium {
            let t = hit.map_or(remaining, |si| si.t);
            transmittance.media *=
                world.media[m as usize]
                    .transmittance(&segment, t, lambda, || ctx.sampler.next_1d());
            if transmittance.media.is_black() {
                return transmittance;
            }
        }
        let Some(si) = hit else {
            return transmittance;
        };
        let material = world.material(&si);
        if !material.is_null() {
            if !material.has_null_lobe() {
                return ShadowTransmittance::ZERO;
            }
            transmittance.surfaces *= cross(material, &si, d);
            if transmittance.surfaces.is_black() {
                return transmittance;
            }
        }
        medium = medium_after(world, &si, d, medium);
        o = si.spawn_ray(d).o;
    }
}

/// Where a shadow ray from `origin` (a point in a medium) towards the light sample `ls` ends:
/// just off the light's surface, short of it by the shadow epsilon.
#[inline]
pub fn shadow_end(origin: Vec3, ls: &LightSample) -> Vec3 {
    let target = if ls.n == Vec3::ZERO {
        ls.p
    } else {
        let m = if (ls.p - origin).dot(ls.n) <= 0.0 {
            ls.n
        } else {
            -ls.n
        };
        offset_ray_origin(ls.p, m)
    };
    origin + (target - origin) * (1.0 - SHADOW_EPSILON)
}
