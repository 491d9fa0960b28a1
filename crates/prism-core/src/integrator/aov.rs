//! Mitsuba 3's `aov` integrator: arbitrary output variables of the surface the camera ray sees
//! first (what a denoiser needs: albedo and normals; also depth, position, parametrisation and
//! indices), written as extra film channels beside the images of nested integrators.
//!
//! ```xml
//! <integrator type="aov">
//!     <string name="aovs" value="dd.y:depth,nn:sh_normal,alb:albedo"/>
//!     <integrator type="path" name="my_image"/>
//! </integrator>
//! ```
//!
//! Channels, in order: for each nested integrator `n`, its linear sRGB estimate as `n.R`, `n.G`,
//! `n.B` and its coverage `n.A`; then each nested integrator's own channels as `n.<channel>`;
//! then each variable of `aovs`, named `name` with the suffixes of its type:
//!
//! | type | channels | value |
//! | --- | --- | --- |
//! | `albedo` | R, G, B | the BSDF's diffuse reflectance ([`crate::bsdf::BsdfModel::diffuse_reflectance`]), linear sRGB |
//! | `depth` | T | the distance along the ray from where it leaves the camera (on the near clip plane, as in Mitsuba) to the hit |
//! | `position` | X, Y, Z | the hit point (world space) |
//! | `uv` | U, V | the surface parametrisation |
//! | `geo_normal` | X, Y, Z | the unit geometric normal |
//! | `sh_normal` | X, Y, Z | the unit shading normal |
//! | `dp_du`, `dp_dv` | X, Y, Z | the tangents ∂p/∂u, ∂p/∂v |
//! | `prim_index` | I | the primitive (triangle) within its shape, 0 for analytic shapes |
//! | `shape_index` | I | the shape's position among the scene's shapes, from 0 |
//!
//! A camera ray that hits nothing gives 0 in every variable. A pixel's value is the filtered
//! mean over its samples, as the image's, so at silhouettes it mixes surfaces (and indices come
//! out fractional). The image is the first nested integrator's, black without one. The nested
//! integrators run first, drawing their random numbers as they would alone; the variables need
//! none.

use crate::geometry::SurfaceInteraction;
use crate::integrator::{Integrator, SampleContext};
use crate::math::Ray;
use crate::spectrum::cie::xyz_to_linear_srgb;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::world::World;

/// The kind of an output variable (`name:type` in `aovs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AovKind {
    Albedo,
    Depth,
    Position,
    Uv,
    GeometricNormal,
    ShadingNormal,
    DpDu,
    DpDv,
    PrimitiveIndex,
    ShapeIndex,
}

impl AovKind {
    /// Every kind with its name in `aovs`.
    pub const ALL: [(&'static str, AovKind); 10] = [
        ("albedo", AovKind::Albedo),
        ("depth", AovKind::Depth),
        ("position", AovKind::Position),
        ("uv", AovKind::Uv),
        ("geo_normal", AovKind::GeometricNormal),
        ("sh_normal", AovKind::ShadingNormal),
        ("dp_du", AovKind::DpDu),
        ("dp_dv", AovKind::DpDv),
        ("prim_index", AovKind::PrimitiveIndex),
        ("shape_index", AovKind::ShapeIndex),
    ];

    /// The suffixes of its channels, as Mitsuba names them.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            AovKind::Albedo => &["R", "G", "B"],
            AovKind::Depth => &["T"],
            AovKind::Uv => &["U", "V"],
            AovKind::Position
            | AovKind::GeometricNormal
            | AovKind::ShadingNormal
            | AovKind::DpDu
            | AovKind::DpDv => &["X", "Y", "Z"],
            AovKind::PrimitiveIndex | AovKind::ShapeIndex => &["I"],
        }
    }
}

/// One output variable: its name (the channels' prefix) and kind.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Aov {
    pub name: String,
    pub kind: AovKind,
}

#[derive(Clone, Debug)]
pub struct AovIntegrator {
    /// The variables, in the order `aovs` lists them.
    pub aovs: Vec<Aov>,
    /// The nested integrators with the names their channels carry, in the scene's order.
    pub integrators: Vec<(String, Integrator)>,
}

impl AovIntegrator {
    pub fn aov_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for (name, _) in &self.integrators {
            names.extend(["R", "G", "B", "A"].map(|c| format!("{name}.{c}")));
        }
        for (name, integrator) in &self.integrators {
            names.extend(integrator.aov_names().iter().map(|a| format!("{name}.{a}")));
        }
        for aov in &self.aovs {
            names.extend(
                aov.kind
                    .channels()
                    .iter()
                    .map(|c| format!("{}.{c}", aov.name)),
            );
        }
        names
    }

    /// The first nested integrator's radiance; the nested images and the variables go to `aovs`.
    pub(super) fn radiance(
        &self,
        ctx: &mut SampleContext,
        ray: Ray,
        lambda: &SampledWavelengths,
        aovs: &mut [f32],
    ) -> SampledSpectrum {
        let prepared = ctx.prepared;
        let world = ctx.world();
        let (images, rest) = aovs.split_at_mut(4 * prepared.nested.len());
        let mut image = SampledSpectrum::ZERO;
        let mut offset = 0;
        for (i, (nested, rgba)) in prepared
            .nested
            .iter()
            .zip(images.chunks_exact_mut(4))
            .enumerate()
        {
            let k = nested.aov_count();
            let radiance = nested.radiance(
                ray,
                lambda,
                ctx.sampler,
                ctx.count,
                &mut rest[offset..offset + k],
            );
            offset += k;
            rgba[..3].copy_from_slice(&xyz_to_linear_srgb(lambda.to_xyz(&radiance)));
            if i == 0 {
                image = radiance;
            }
        }
        let hit = ctx.intersect(&ray);
        // Coverage: the ray finds a surface, or an environment the integrator shows.
        for (rgba, (_, integrator)) in images.chunks_exact_mut(4).zip(&self.integrators) {
            let environment_seen = world.environment.is_some() && !integrator.hides_emitters();
            rgba[3] = if hit.is_some() || environment_seen {
                1.0
            } else {
                0.0
            };
        }
        let Some(si) = hit else {
            return image;
        };
        let mut values = rest[offset..].iter_mut();
        for aov in &self.aovs {
            let value = variable(world, &ray, &si, aov.kind, lambda);
            // The variable's channels first, so that zip stops without taking one more output.
            for (v, out) in value[..aov.kind.channels().len()]
                .iter()
                .zip(values.by_ref())
            {
                *out = *v;
            }
        }
        image
    }
}

/// The value of a variable of kind `kind` at the camera ray's hit `si` (the channels it has).
fn variable(
    world: &World,
    ray: &Ray,
    si: &SurfaceInteraction,
    kind: AovKind,
    lambda: &SampledWavelengths,
) -> [f32; 3] {
    let v = |v: glam::Vec3| v.to_array();
    match kind {
        AovKind::Albedo => {
            let albedo = world
                .material(si)
                .diffuse_reflectance(si, -ray.d.normalize(), lambda);
            xyz_to_linear_srgb(lambda.to_xyz(&albedo))
        }
        AovKind::Depth => [si.t * ray.d.length(), 0.0, 0.0],
        AovKind::Position => v(si.p),
        AovKind::Uv => [si.uv.x, si.uv.y, 0.0],
        AovKind::GeometricNormal => v(si.n),
        AovKind::ShadingNormal => v(si.shading.n),
        AovKind::DpDu => v(si.dp_du),
        AovKind::DpDv => v(si.dp_dv),
        AovKind::PrimitiveIndex => [si.primitive as f32, 0.0, 0.0],
        AovKind::ShapeIndex => [si.shape as f32, 0.0, 0.0],
    }
}
