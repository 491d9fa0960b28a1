//! Materials, and the scattering at a path vertex that both integrators use.

use glam::{Vec2, Vec3};

use super::{
    Bsdf, BsdfEval, BsdfFlags, BsdfModel, BsdfSample, BxdfTree, NodeId, ResolveContext,
    ShadingPoint,
};
use crate::geometry::SurfaceInteraction;
use crate::math::Frame;
use crate::polarization::{FrameChange, SampledMueller};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// What a surface is made of: a BSDF for the front (the side of the shading normal) and, for
/// top-level `twosided` materials, one for the back. Mitsuba's reflecting BSDFs are one-sided
/// (black from behind) unless wrapped in `twosided`; dielectrics handle both sides themselves.
#[derive(Clone, Debug)]
pub struct Material {
    pub front: Bsdf,
    pub back: Option<Bsdf>,
}

impl Material {
    /// A material with one BSDF for both sides (the BSDF decides what its back is).
    pub fn new(bsdf: impl Into<Bsdf>) -> Material {
        Material {
            front: bsdf.into(),
            back: None,
        }
    }

    /// The BSDF that applies when the outgoing direction has local z-component `cos_theta_o`,
    /// and whether the frame must be flipped to use it (back side of a two-sided material).
    /// Without a back BSDF the front one is used from both sides: it decides what its back is.
    #[inline]
    pub fn side(&self, cos_theta_o: f32) -> (&Bsdf, bool) {
        match &self.back {
            Some(back) if cos_theta_o < 0.0 => (back, true),
            _ => (&self.front, false),
        }
    }

    /// The scattering at the hit `si` towards `wo` (world space, unit): the BSDF of the side
    /// `wo` sees, in the shading frame of that side, with its textures evaluated at the hit for
    /// the wavelengths `lambda`; its lobes are written into `tree`.
    #[inline]
    pub fn scattering<'t, 'm>(
        &'m self,
        si: &SurfaceInteraction,
        wo: Vec3,
        lambda: &SampledWavelengths,
        tree: &'t mut BxdfTree<'m>,
    ) -> Scattering<'t, 'm> {
        let (bsdf, point) = self.seen_from(si, wo);
        Scattering::new(bsdf, &point, point.frame.to_local(wo), lambda, tree)
    }

    /// The albedo at the hit `si` seen from `wo` (world space, unit): the diffuse reflectance
    /// of the side `wo` sees (see [`BsdfModel::diffuse_reflectance`]).
    pub fn diffuse_reflectance(
        &self,
        si: &SurfaceInteraction,
        wo: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let (bsdf, point) = self.seen_from(si, wo);
        bsdf.diffuse_reflectance(&point, point.frame.to_local(wo), lambda)
    }

    /// The BSDF of the side of `si` that `wo` sees, and the shading point in that side's frame.
    #[inline]
    fn seen_from(&self, si: &SurfaceInteraction, wo: Vec3) -> (&Bsdf, ShadingPoint) {
        let (bsdf, flip) = self.side(si.shading.to_local(wo).z);
        let frame = if flip {
            si.shading.flipped()
        } else {
            si.shading
        };
        let point = ShadingPoint {
            uv: si.uv,
            attributes: si.attributes,
            p: si.p,
            frame,
            ng: if si.n.dot(frame.n) < 0.0 { -si.n } else { si.n },
            dp_du: si.dp_du,
            dp_dv: si.dp_dv,
        };
        (bsdf, point)
    }

    /// Whether light passes through unchanged from both sides (the `null` BSDF): an
    /// index-matched boundary, which volumetric path tracing crosses without a bounce.
    pub fn is_null(&self) -> bool {
        matches!(self.front, Bsdf::Null(_)) && matches!(self.back, None | Some(Bsdf::Null(_)))
    }

    /// Whether some lobe of either side lets light through unchanged (`null`, `mask`,
    /// `thindielectric`, and adapters around them).
    pub fn has_null_lobe(&self) -> bool {
        self.front.flags().has_null_lobe()
            || self
                .back
                .as_ref()
                .is_some_and(|back| back.flags().has_null_lobe())
    }

    /// The value of the null lobes at the hit `si` for light passing straight through towards
    /// `wo` (world space, unit) on the side `wo` sees ([`Scattering::null_transmission`]).
    pub fn null_transmission(
        &self,
        si: &SurfaceInteraction,
        wo: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let mut tree = BxdfTree::empty();
        self.scattering(si, wo, lambda, &mut tree)
            .null_transmission()
    }

    /// Whether a BSDF of either side, or one nested in it, is a polarizing element
    /// ([`BsdfFlags::POLARIZING`]).
    pub fn is_polarizing(&self) -> bool {
        let polarizing = |bsdf: &Bsdf| bsdf.flags().contains(BsdfFlags::POLARIZING);
        polarizing(&self.front) || self.back.as_ref().is_some_and(polarizing)
    }

    /// The most [`BxdfTree`] nodes either side takes.
    pub fn node_count(&self) -> usize {
        let back = self.back.as_ref().map_or(0, Bsdf::node_count);
        self.front.node_count().max(back)
    }
}

/// The scattering at one path vertex (pbrt-v4's `BSDF`): the lobes of a BSDF with its textures
/// evaluated, the shading frame they work in and the outgoing direction. Directions in and out
/// are in world space.
pub struct Scattering<'t, 'm> {
    /// The shading frame of the side the path arrived on.
    pub frame: Frame,
    /// The outgoing direction, local to `frame`.
    pub wo: Vec3,
    flags: BsdfFlags,
    dispersive: bool,
    tree: &'t BxdfTree<'m>,
    root: NodeId,
}

impl<'t, 'm> Scattering<'t, 'm> {
    /// The scattering of `bsdf` at `point` towards `wo` (local to `point.frame`), its lobes
    /// written into `tree` (whatever it held before is dropped). Tests and benchmarks query
    /// BSDFs outside a scene this way, at [`ShadingPoint::local`].
    #[inline]
    pub fn new(
        bsdf: &'m Bsdf,
        point: &ShadingPoint,
        wo: Vec3,
        lambda: &SampledWavelengths,
        tree: &'t mut BxdfTree<'m>,
    ) -> Scattering<'t, 'm> {
        tree.clear();
        let root = bsdf.resolve(&ResolveContext { point, wo, lambda }, tree);
        Scattering {
            frame: point.frame,
            wo,
            flags: bsdf.flags(),
            dispersive: bsdf.is_dispersive(),
            tree,
            root,
        }
    }

    /// The union of the BSDF's lobes' flags.
    #[inline]
    pub fn flags(&self) -> BsdfFlags {
        self.flags
    }

    /// Whether some index of refraction of the BSDF varies with wavelength (see
    /// [`BsdfSample::terminates_secondary`]).
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        self.dispersive
    }

    /// f(wo, wi)·|cos θi| of the smooth lobes and the density of sampling `wi` (world space).
    #[inline]
    pub fn eval(&self, wi: Vec3) -> BsdfEval {
        self.tree.eval(self.root, self.wo, self.frame.to_local(wi))
    }

    /// The value of the null lobes for light passing straight through towards the outgoing
    /// direction ([`super::Bxdf::null_transmission`]): what a shadow ray crossing the surface
    /// carries on.
    #[inline]
    pub fn null_transmission(&self) -> SampledSpectrum {
        self.tree.null_transmission(self.root, self.wo)
    }

    /// For polarized rendering: the Mueller matrix of the lobe `lobe` (a sample's flags, or
    /// [`BsdfFlags::NONE`] for the smooth lobes) for light arriving from `wi` (world space),
    /// from the implicit Stokes basis of the incident beam to that of the outgoing one, world
    /// directions, with M₀₀ equal to `value`, the unpolarized value that eval or sample gave
    /// (a depolarizer for BSDFs without a polarized model; see [`super::Bxdf::mueller`]).
    pub fn polarized(&self, wi: Vec3, lobe: BsdfFlags, value: SampledSpectrum) -> SampledMueller {
        let wi = self.frame.to_local(wi);
        let Some(local) = self.tree.mueller(self.root, self.wo, wi, lobe) else {
            return SampledMueller::depolarizer(value);
        };
        let change = FrameChange::local_to_world(&self.frame, -wi, self.wo);
        local.in_frames(&change).with_m00(value)
    }

    /// Draws an incident direction: `u_lobe` chooses a lobe, `u` the direction within it; the
    /// sample's `wi` is in world space.
    #[inline]
    pub fn sample(&self, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let mut s = self.tree.sample(self.root, self.wo, u_lobe, u)?;
        s.wi = self.frame.to_world(s.wi);
        Some(s)
    }
}
