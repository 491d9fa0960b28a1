//! Mitsuba's `bumpmap` adapter: the nested BSDF seen in a shading frame tilted by the gradient
//! of a height texture (Blinn 1978, "Simulation of Wrinkled Surfaces").
//!
//! ```xml
//! <bsdf type="bumpmap">
//!     <texture type="bitmap" name="height">
//!         <boolean name="raw" value="true"/> <string name="filename" value="bumps.png"/>
//!     </texture>
//!     <float name="scale" value="1"/>                        <!-- height scale, default 1 -->
//!     <boolean name="flip_invalid_normals" value="true"/>
//!     <boolean name="use_shadowing_function" value="true"/>
//!     <bsdf type="roughplastic"/>
//! </bsdf>
//! ```
//! As Mitsuba 3.9 (`bumpmap.cpp`, `perturbed_bsdf.h`): with the height gradient (h_u, h_v) the
//! tangents become ∂p/∂u + n (h_u − n·∂p/∂u) and ∂p/∂v + n (h_v − n·∂p/∂v); the perturbed normal
//! is their cross product, turned to the side of the geometric normal. The rest is shared with
//! `normalmap` ([`Perturbation`]).

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfFlags, BsdfSample, ShadingPoint, Texture};
use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

#[derive(Clone, Debug)]
pub struct BumpMap {
    pub height: Texture,
    pub scale: f32,
    pub nested: Box<Bsdf>,
    pub flip_invalid_normals: bool,
    pub use_shadowing_function: bool,
}

impl BumpMap {
    pub fn flags(&self) -> BsdfFlags {
        self.nested.flags()
    }

    /// The bump-mapped normal in the local shading frame (not normalised).
    #[inline]
    fn perturbed_normal(&self, sp: &ShadingPoint) -> Vec3 {
        let gradient = self.height.eval_1_grad(sp.uv) * self.scale;
        let n = sp.frame.n;
        let dp_du = sp.dp_du + n * (gradient.x - n.dot(sp.dp_du));
        let dp_dv = sp.dp_dv + n * (gradient.y - n.dot(sp.dp_dv));
        let normal = dp_du.cross(dp_dv);
        let normal = if normal.dot(sp.ng) < 0.0 {
            -normal
        } else {
            normal
        };
        sp.frame.to_local(normal)
    }

    #[inline]
    fn perturbation(&self, sp: &ShadingPoint, wo: Vec3) -> Perturbation {
        Perturbation::new(
            sp,
            self.perturbed_normal(sp),
            wo,
            self.flip_invalid_normals,
            self.use_shadowing_function,
        )
    }

    pub fn eval(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        self.perturbation(sp, wo).eval(&self.nested, wo, wi, lambda)
    }

    pub fn pdf(&self, sp: &ShadingPoint, wo: Vec3, wi: Vec3, lambda: &SampledWavelengths) -> f32 {
        self.perturbation(sp, wo).pdf(&self.nested, wo, wi, lambda)
    }

    pub fn sample(
        &self,
        sp: &ShadingPoint,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        self.perturbation(sp, wo)
            .sample(&self.nested, wo, u_lobe, u, lambda)
    }
}

/// A shading frame tilted to a new normal, as Mitsuba 3.9's `PerturbedBSDF` builds it for bump
/// and normal maps:
/// * with `flip_invalid_normals`, a normal that wo sees from behind is mirrored about the
///   shading normal, (x, y, z) ↦ (−x, −y, z), so that it faces wo (Schüssler et al. 2017,
///   "Microfacet-based Normal Mapping for Robust Monte Carlo Path Tracing");
/// * the first tangent is the local x axis (the direction of ∂p/∂u) made orthogonal to it;
/// * directions on different sides of the two frames get no light;
/// * with `use_shadowing_function`, values are attenuated by the shadowing term of Conty
///   Estevez et al. 2019 ("A Microfacet-Based Shadowing Function to Solve the Bump Terminator
///   Problem", Ray Tracing Gems ch. 12): G = 2 / (1 + √(1 + α² tan²θi)) with
///   α² = min(tan²θ_n / 8, 1), θ_n the tilt of the normal and θi the light direction's angle.
pub(crate) struct Perturbation {
    /// The tilted frame in the local coordinates of the original one.
    local: Frame,
    /// The shading point with the tilted frame, for the nested BSDF.
    point: ShadingPoint,
    shadowing: bool,
}

impl Perturbation {
    pub(crate) fn new(
        sp: &ShadingPoint,
        normal: Vec3,
        wo: Vec3,
        flip_invalid_normals: bool,
        shadowing: bool,
    ) -> Perturbation {
        let mut n = normal;
        if flip_invalid_normals && wo.z * wo.dot(n) <= 0.0 {
            n = Vec3::new(-n.x, -n.y, n.z);
        }
        let n = n.try_normalize().unwrap_or(Vec3::Z);
        let s = (Vec3::X - n * n.x).try_normalize().unwrap_or(Vec3::Y);
        let local = Frame {
            s,
            t: n.cross(s),
            n,
        };
        let point = ShadingPoint {
            frame: Frame {
                s: sp.frame.to_world(local.s),
                t: sp.frame.to_world(local.t),
                n: sp.frame.to_world(local.n),
            },
            ..*sp
        };
        Perturbation {
            local,
            point,
            shadowing,
        }
    }

    /// The shadowing term for the light direction `wi` (1 when disabled).
    #[inline]
    fn shadowing(&self, wi: Vec3) -> f32 {
        if !self.shadowing {
            return 1.0;
        }
        let tan2 = |v: Vec3| (1.0 - v.z * v.z).max(0.0) / (v.z * v.z);
        let alpha2 = (0.125 * tan2(self.local.n)).min(1.0);
        let g = 2.0 / (1.0 + (1.0 + alpha2 * tan2(wi)).sqrt());
        if g.is_finite() { g } else { 0.0 }
    }

    pub(crate) fn eval(
        &self,
        nested: &Bsdf,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let wi_p = self.local.to_local(wi);
        if !(wi.z * wi_p.z > 0.0) {
            return SampledSpectrum::ZERO;
        }
        nested.eval(&self.point, self.local.to_local(wo), wi_p, lambda) * self.shadowing(wi)
    }

    pub(crate) fn pdf(
        &self,
        nested: &Bsdf,
        wo: Vec3,
        wi: Vec3,
        lambda: &SampledWavelengths,
    ) -> f32 {
        let wi_p = self.local.to_local(wi);
        if !(wi.z * wi_p.z > 0.0) {
            return 0.0;
        }
        nested.pdf(&self.point, self.local.to_local(wo), wi_p, lambda)
    }

    pub(crate) fn sample(
        &self,
        nested: &Bsdf,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<BsdfSample> {
        let mut s = nested.sample(&self.point, self.local.to_local(wo), u_lobe, u, lambda)?;
        let wi = self.local.to_world(s.wi);
        if !(wi.z * s.wi.z > 0.0) {
            return None;
        }
        s.wi = wi;
        s.weight *= self.shadowing(wi);
        Some(s)
    }
}
