//! Scattering at surfaces: the BSDF interface, Mitsuba's BSDFs, and materials that choose a BSDF
//! for each side of a surface.
//!
//! # Two forms of a BSDF
//! A scene describes a BSDF by its parameters, any of which may vary over the surface
//! ([`Bsdf`], whose variants implement [`BsdfModel`]). At a path vertex the material evaluates
//! those textures once, at the hit and for the path's wavelengths, and gets the lobes there: a
//! small tree of [`Bxdf`]s in fixed storage ([`BxdfTree`]; adapters such as `mask` and
//! `blendbsdf` are inner nodes). [`Scattering`] holds that tree with its shading frame and the
//! outgoing direction; both integrators evaluate and sample only through it (pbrt-v4's
//! `GetBSDF`, Pharr et al. 2023, §10.5).
//!
//! # Conventions
//! BSDFs work in the local shading frame (normal = +z). Following pbrt's naming, `wo` points
//! towards where the light goes (the camera side of the path) and `wi` towards where it comes
//! from; both point away from the surface. `eval` returns f(wo, wi)·|cos θi| (the cosine is part
//! of the BSDF's value, as in Mitsuba 3) together with the density of sampling `wi`, and
//! `sample` returns the value divided by its pdf.
//!
//! The lecture's "Importance Sampling of the Reflection Integral" splits a BRDF into diffuse,
//! glossy and mirror parts and adapts the sampling to each: every BSDF here is a sum of lobes
//! with [`BsdfFlags`] saying which kind each is. `sample` first picks a lobe with a probability
//! proportional to an estimate of that lobe's albedo for the given `wo` (the `u_lobe` number),
//! then a direction within it. Smooth lobes (diffuse, glossy) have a density and can be
//! evaluated, so they take part in light sampling and multiple importance sampling; delta lobes
//! (specular mirror and refraction, and the "null" pass-through of `mask` and `thindielectric`)
//! can only be sampled, and their `pdf` is the probability of choosing them. For a sample of a
//! smooth lobe the returned pdf and weight are those of the whole BSDF (all smooth lobes'
//! densities summed), so that MIS sees the density the direction was really drawn with.
//!
//! # Adding a BSDF
//! Write one file with the description and its lobes (implementing [`Bxdf`]). A description
//! that nests no other BSDF implements [`LeafBsdf`], one built around nested BSDFs [`Adapter`];
//! [`BsdfModel`] follows from either. Add its two types to the `bsdfs!` lists below, and
//! register its plugin and parameters with the scene reader (docs/architecture.md).
//!
//! | plugin | file | lobes |
//! | --- | --- | --- |
//! | `diffuse` | [`diffuse`] | diffuse reflection |
//! | `roughdiffuse` | [`roughdiffuse`] | diffuse reflection (Oren–Nayar) |
//! | `conductor` | [`conductor`] | specular reflection |
//! | `roughconductor` | [`roughconductor`] | glossy reflection |
//! | `dielectric` | [`dielectric`] | specular reflection and transmission |
//! | `roughdielectric` | [`roughdielectric`] | glossy reflection and transmission |
//! | `thindielectric` | [`thindielectric`] | specular reflection, null transmission |
//! | `plastic` | [`plastic`] | specular and diffuse reflection |
//! | `roughplastic` | [`roughplastic`] | glossy and diffuse reflection |
//! | `phong` | [`phong`] | glossy and diffuse reflection |
//! | `pplastic` | [`pplastic`] | glossy and diffuse reflection |
//! | `ward` | [`ward`] | glossy and diffuse reflection |
//! | `principled` | [`principled`] | diffuse, glossy reflection (two), glossy transmission |
//! | `principledthin` | [`principledthin`] | diffuse and glossy reflection and transmission |
//! | `diffusetransmission` | [`diffusetransmission`] | diffuse reflection and transmission (pbrt-v4's) |
//! | `coateddiffuse`, `coatedconductor` | [`layered`] | reflection by a random walk through a coating (pbrt-v4's) |
//! | `hair` | [`hair`] | glossy scattering around a fibre (reflection and transmission) |
//! | `measured` | [`measured`] | glossy reflection, tabulated (RGL database) |
//! | `measured_polarized` | [`measured_polarized`] | glossy reflection, a tabulated Mueller matrix (KAIST pBRDF database) |
//! | `polarizer` | [`polarizer`] | null transmission through a linear polarizer |
//! | `retarder` | [`retarder`] | null transmission through a linear retarder (a wave plate) |
//! | `circular` | [`circular`] | null transmission through a circular polarizer |
//! | `twosided` | [`twosided`] | those of the nested BSDFs, on both sides |
//! | `mask` | [`mask`] | the nested BSDF's, and null transmission |
//! | `null` | [`null`] | null transmission only (a medium's boundary) |
//! | `blendbsdf` | [`blend`] | both nested BSDFs' |
//! | `bumpmap`, `normalmap` | [`bumpmap`], [`normalmap`] | the nested BSDF's, in a perturbed frame |

pub mod blend;
pub mod bumpmap;
pub mod burley;
pub mod circular;
pub mod conductor;
pub mod dielectric;
pub mod diffuse;
pub mod diffusetransmission;
pub mod fresnel;
pub mod glossydiffuse;
pub mod hair;
pub mod layer_interface;
pub mod layered;
pub mod mask;
pub mod material;
pub mod measured;
pub mod measured_polarized;
pub mod microfacet;
pub mod normalmap;
pub mod null;
pub mod perturbed;
pub mod phong;
pub mod plastic;
pub mod polarizer;
pub mod polarizing_sheet;
pub mod pplastic;
pub mod principled;
pub mod principledthin;
pub mod retarder;
pub mod roughconductor;
pub mod roughdielectric;
pub mod roughdiffuse;
pub mod roughplastic;
pub mod thindielectric;
pub mod twosided;
pub mod ward;

use arrayvec::ArrayVec;
use glam::{Vec2, Vec3};

pub use blend::Blend;
pub use bumpmap::BumpMap;
pub use circular::Circular;
pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use diffusetransmission::DiffuseTransmission;
pub use hair::{Hair, HairAbsorption, HairLobeShapes};
pub use layered::{CoatedConductor, CoatedDiffuse, Coating};
pub use mask::Mask;
pub use material::{Material, Scattering};
pub use measured::{Measured, MeasuredData};
pub use measured_polarized::{MeasuredPolarized, MeasuredPolarizedData};
pub use normalmap::NormalMap;
pub use null::Null;
pub use phong::Phong;
pub use plastic::Plastic;
pub use polarizer::Polarizer;
pub use pplastic::PolarizedPlastic;
pub use principled::Principled;
pub use principledthin::PrincipledThin;
pub use retarder::Retarder;
pub use roughconductor::RoughConductor;
pub use roughdielectric::RoughDielectric;
pub use roughdiffuse::RoughDiffuse;
pub use roughplastic::RoughPlastic;
pub use thindielectric::ThinDielectric;
pub use twosided::TwoSided;
pub use ward::{Ward, WardVariant};

use crate::geometry::interaction::AttributeValues;
use crate::math::Frame;
use crate::polarization::SampledMueller;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::TexturePoint;

/// Which kind of lobe a sample or BSDF has (the lecture's split into diffuse, glossy and mirror
/// parts) and whether it reflects or transmits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    /// No lobe.
    pub const NONE: BsdfFlags = BsdfFlags(0);
    pub const DIFFUSE: BsdfFlags = BsdfFlags(1);
    pub const GLOSSY: BsdfFlags = BsdfFlags(2);
    /// A Dirac delta lobe (mirror or clear glass): cannot be evaluated, only sampled.
    pub const SPECULAR: BsdfFlags = BsdfFlags(4);
    /// Light passing straight through, unchanged in direction (Mitsuba's `Null`: the `null`
    /// BSDF, the transparent part of `mask`, the transmission of `thindielectric`); a delta lobe
    /// too.
    pub const NULL: BsdfFlags = BsdfFlags(32);
    /// The BSDF changes the polarization of light in a way an unpolarized render cannot show
    /// (`polarizer`, `retarder`, `circular`): a scene with one renders polarized.
    pub const POLARIZING: BsdfFlags = BsdfFlags(64);
    pub const REFLECTION: BsdfFlags = BsdfFlags(8);
    pub const TRANSMISSION: BsdfFlags = BsdfFlags(16);

    pub const fn union(self, other: BsdfFlags) -> BsdfFlags {
        BsdfFlags(self.0 | other.0)
    }

    pub const fn contains(self, other: BsdfFlags) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether some lobe can be evaluated (is not a delta), so light sampling can help.
    pub const fn has_smooth_lobe(self) -> bool {
        self.0 & (BsdfFlags::DIFFUSE.0 | BsdfFlags::GLOSSY.0) != 0
    }

    /// Whether some lobe lets light through unchanged (a null lobe).
    pub const fn has_null_lobe(self) -> bool {
        self.0 & BsdfFlags::NULL.0 != 0
    }

    /// Whether this is (or includes) a delta lobe: specular or null.
    pub const fn is_delta(self) -> bool {
        self.0 & (BsdfFlags::SPECULAR.0 | BsdfFlags::NULL.0) != 0
    }
}

/// A direction drawn by a BSDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled direction: in the local frame when a [`Bxdf`] returns it, in world space when
    /// [`Scattering::sample`] does.
    pub wi: Vec3,
    /// f(wo, wi)·|cos θi| / pdf.
    pub weight: SampledSpectrum,
    /// Density per unit solid angle (for a delta lobe: the probability of choosing it).
    pub pdf: f32,
    /// The lobe that produced the sample.
    pub flags: BsdfFlags,
    /// Relative index of refraction along the path (η_t/η_i when refracting, 1 otherwise), for
    /// Russian roulette (Mitsuba's `bs.eta`).
    pub eta: f32,
    /// Whether the direction is right for the hero wavelength only (refraction through a
    /// dispersive interface): the path must then drop its other wavelengths.
    pub terminates_secondary: bool,
}

impl BsdfSample {
    /// A sample with η = 1 that does not disperse.
    #[inline]
    pub fn new(wi: Vec3, weight: SampledSpectrum, pdf: f32, flags: BsdfFlags) -> BsdfSample {
        BsdfSample {
            wi,
            weight,
            pdf,
            flags,
            eta: 1.0,
            terminates_secondary: false,
        }
    }
}

/// The value of a BSDF for a pair of directions, f(wo, wi)·|cos θi| over its smooth lobes, and
/// the density with which sampling from `wo` returns `wi`: what light sampling and multiple
/// importance sampling need, computed together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfEval {
    pub value: SampledSpectrum,
    pub pdf: f32,
}

impl BsdfEval {
    /// No light and no density: the value of every delta lobe, and of directions a BSDF does not
    /// scatter into.
    pub const ZERO: BsdfEval = BsdfEval {
        value: SampledSpectrum::ZERO,
        pdf: 0.0,
    };
}

/// The probability of choosing a lobe in proportion to an estimate of its albedo, `lobe`,
/// against the estimate for the other lobes, `rest`: 1 where both are zero.
#[inline]
pub(crate) fn choice_probability(lobe: f32, rest: f32) -> f32 {
    if lobe + rest > 0.0 {
        lobe / (lobe + rest)
    } else {
        1.0
    }
}

/// For a BSDF that is a mixture of lobes: the sample of one smooth lobe turned into a sample of
/// the whole mixture, whose density at `wi` is `pdf` and whose value there is `value`.
#[inline]
pub(crate) fn mixture_sample(
    wi: Vec3,
    value: SampledSpectrum,
    pdf: f32,
    flags: BsdfFlags,
) -> Option<BsdfSample> {
    if !(pdf > 0.0) || !pdf.is_finite() {
        return None;
    }
    Some(BsdfSample::new(wi, value * (1.0 / pdf), pdf, flags))
}

/// The surface point a BSDF's textures are evaluated at: texture coordinates, and the local
/// geometry for the BSDFs that perturb the shading frame (bump and normal maps).
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    pub uv: Vec2,
    /// The hit mesh's attributes at the point (for `mesh_attribute` textures).
    pub attributes: AttributeValues,
    /// The point's world position (for `volume` textures).
    pub p: Vec3,
    /// The shading frame that the local directions refer to (world space).
    pub frame: Frame,
    /// The geometric normal, on the side of `frame.n` (also for `directionmix` textures).
    pub ng: Vec3,
    /// ∂p/∂u and ∂p/∂v (world space, not normalised).
    pub dp_du: Vec3,
    pub dp_dv: Vec3,
}

impl ShadingPoint {
    /// Where the point's textures are looked up.
    #[inline]
    pub fn at(&self) -> TexturePoint {
        TexturePoint {
            uv: self.uv,
            attributes: self.attributes,
            p: self.p,
            n: self.ng,
        }
    }

    /// A point whose shading frame is the world frame (for tests and BSDF queries out of scene
    /// context).
    pub fn local(uv: Vec2) -> ShadingPoint {
        ShadingPoint {
            uv,
            attributes: AttributeValues::default(),
            p: Vec3::ZERO,
            frame: Frame {
                s: Vec3::X,
                t: Vec3::Y,
                n: Vec3::Z,
            },
            ng: Vec3::Z,
            dp_du: Vec3::X,
            dp_dv: Vec3::Y,
        }
    }
}

/// A BSDF as a scene describes it: parameters that may be textures.
pub trait BsdfModel {
    /// The union of the lobes' flags.
    fn flags(&self) -> BsdfFlags;
    /// Whether some index of refraction varies with wavelength, so that refracted directions
    /// depend on it (see [`BsdfSample::terminates_secondary`]).
    fn is_dispersive(&self) -> bool;
    /// The nodes its lobes take in a [`BxdfTree`] (1 for a BSDF that nests none).
    fn node_count(&self) -> usize;
    /// The albedo a denoiser wants (Mitsuba's `eval_diffuse_reflectance`): the reflectance of
    /// the diffuse part at `point` for the wavelengths `lambda`, seen from `wo` (local), which
    /// `twosided` needs to choose a side; zero for BSDFs without a diffuse part.
    fn diffuse_reflectance(
        &self,
        point: &ShadingPoint,
        wo: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum;
    /// Evaluates the textures at the context's point for its wavelengths and adds the lobes
    /// there to `tree`. Returns the index of the node added last, its root.
    fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId;
}

/// Where a BSDF's lobes are resolved: the point, the outgoing direction `wo` (local to the
/// point's frame), which adapters need to choose a side or tilt a frame, and the path's
/// wavelengths `lambda`.
#[derive(Clone, Copy, Debug)]
pub struct ResolveContext<'p> {
    pub point: &'p ShadingPoint,
    pub wo: Vec3,
    pub lambda: &'p SampledWavelengths,
}

/// A BSDF that nests no other: its lobes take one node of a [`BxdfTree`] and depend on the
/// textures' point and the wavelengths only. Its [`BsdfModel`] follows: one node, which
/// `resolve` adds.
pub trait LeafBsdf {
    /// The lobes at a point.
    type Lobes<'a>: Into<Node<'a>>
    where
        Self: 'a;

    /// The union of the lobes' flags; for a BSDF whose lobes depend on its parameters, the
    /// flags of those it always has.
    const FLAGS: BsdfFlags;

    /// [`BsdfModel::flags`]: [`Self::FLAGS`], to which `principled` adds its transmission where
    /// it has one.
    fn flags(&self) -> BsdfFlags {
        Self::FLAGS
    }

    /// [`BsdfModel::is_dispersive`]. Only a BSDF that refracts through an index of refraction
    /// that may vary with wavelength answers otherwise than this `false`.
    fn is_dispersive(&self) -> bool {
        false
    }

    /// [`BsdfModel::diffuse_reflectance`], the reflectance of the diffuse part at `at`, which
    /// for a leaf does not depend on `wo`. Only a BSDF with a diffuse part answers otherwise
    /// than this zero.
    fn albedo(&self, at: TexturePoint, lambda: &SampledWavelengths) -> SampledSpectrum {
        let _ = (at, lambda);
        SampledSpectrum::ZERO
    }

    /// Evaluates the textures at `at` for the wavelengths `lambda`: the lobes there.
    fn lobes<'a>(&'a self, at: TexturePoint, lambda: &SampledWavelengths) -> Self::Lobes<'a>;
}

/// A BSDF built around nested ones (`twosided`, `mask`, `blendbsdf`, `bumpmap`, `normalmap`).
/// Its [`BsdfModel`] follows from theirs: its flags are theirs and its own, it is dispersive
/// where one of them is, and its lobes take one node beside theirs.
pub trait Adapter {
    /// The flags of the lobes the adapter adds to the nested ones' (`mask`'s null lobe).
    const OWN_FLAGS: BsdfFlags;

    /// The nested BSDFs.
    fn nested(&self) -> &[Box<Bsdf>];

    /// The most nodes the nested BSDFs' lobes take at a point: the sum of their counts, as all
    /// of them are resolved. `twosided`, which resolves one side, answers the larger count.
    fn nested_node_count(&self) -> usize {
        self.nested().iter().map(|b| b.node_count()).sum()
    }

    /// [`BsdfModel::diffuse_reflectance`]: the nested BSDF's, for an adapter that nests one;
    /// `blendbsdf` blends its two, `twosided` takes the side `wo` sees.
    fn diffuse_reflectance(&self, context: &ResolveContext) -> SampledSpectrum {
        let ResolveContext { point, wo, lambda } = *context;
        self.nested()[0].diffuse_reflectance(point, wo, lambda)
    }

    /// [`BsdfModel::resolve`]: the nested BSDFs' lobes, then the adapter's node.
    fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId;
}

/// A BSDF's lobes at one point for one path's wavelengths, in the local frame. Adapters reach
/// the lobes they nest through `tree`; other BSDFs ignore it.
pub trait Bxdf {
    /// f(wo, wi)·|cos θi| of the smooth lobes and the density of sampling `wi`. A BSDF made only
    /// of delta lobes keeps this default: nothing to evaluate.
    fn eval(&self, tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
        let _ = (tree, wo, wi);
        BsdfEval::ZERO
    }
    /// Draws `wi` given `wo`: `u_lobe` chooses a lobe, `u` the direction within it.
    fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample>;
    /// The value of the null lobes for light passing straight through from −wo to wo (Mitsuba
    /// 3's `eval_null_transmission`): the probability of sampling them times their weight, so
    /// that a shadow ray through the surface carries what the path that crosses it by sampling
    /// would carry on average. A BSDF without null lobes keeps this default: none passes.
    fn null_transmission(&self, tree: &BxdfTree, wo: Vec3) -> SampledSpectrum {
        let _ = (tree, wo);
        SampledSpectrum::ZERO
    }
    /// For polarized rendering: the Mueller matrix of f(wo, wi)·|cos θi| of the lobe `lobe`
    /// (a sample's flags, or [`BsdfFlags::NONE`] for the smooth lobes that light sampling
    /// evaluates), up to a positive factor per wavelength, from the implicit Stokes basis of the
    /// incident beam (travelling along −wi) to that of the outgoing one (along wo), local
    /// directions, as Mitsuba 3's polarized BSDFs return it; the integrator scales its M₀₀ to
    /// the unpolarized value. A BSDF without a polarized model keeps this default, None: it
    /// depolarizes, as Mitsuba's do.
    fn mueller(
        &self,
        tree: &BxdfTree,
        wo: Vec3,
        wi: Vec3,
        lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        let _ = (tree, wo, wi, lobe);
        None
    }
}

/// Index of a node in a [`BxdfTree`].
pub type NodeId = u8;

/// The most nodes a BSDF's lobes may take (a BSDF and the adapters around it); the scene reader
/// refuses BSDFs nested deeper.
pub const MAX_NODES: usize = 16;

/// The lobes of one vertex: the nodes of a tree in fixed storage, children before parents, so
/// that a vertex allocates nothing. An integrator keeps one per vertex it holds at once (the
/// path tracer one per path, reused at every bounce; the distribution ray tracer one per level
/// of its recursion), so the lobes are written where they are used and never copied.
pub struct BxdfTree<'a> {
    nodes: ArrayVec<Node<'a>, MAX_NODES>,
}

impl<'a> BxdfTree<'a> {
    /// A tree without nodes, to be filled by [`BsdfModel::resolve`].
    #[inline]
    pub fn empty() -> BxdfTree<'a> {
        BxdfTree {
            nodes: ArrayVec::new(),
        }
    }

    /// Removes every node.
    #[inline]
    pub fn clear(&mut self) {
        self.nodes.clear();
    }

    /// Adds a node; its index. The scene reader keeps BSDFs within [`MAX_NODES`].
    #[inline]
    pub fn push(&mut self, node: impl Into<Node<'a>>) -> NodeId {
        self.nodes.push(node.into());
        (self.nodes.len() - 1) as NodeId
    }

    /// [`Bxdf::eval`] of node `id`.
    #[inline]
    pub fn eval(&self, id: NodeId, wo: Vec3, wi: Vec3) -> BsdfEval {
        self.nodes[id as usize].eval(self, wo, wi)
    }

    /// [`Bxdf::sample`] of node `id`.
    #[inline]
    pub fn sample(&self, id: NodeId, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        self.nodes[id as usize].sample(self, wo, u_lobe, u)
    }

    /// [`Bxdf::null_transmission`] of node `id`.
    #[inline]
    pub fn null_transmission(&self, id: NodeId, wo: Vec3) -> SampledSpectrum {
        self.nodes[id as usize].null_transmission(self, wo)
    }

    /// [`Bxdf::mueller`] of node `id`.
    #[inline]
    pub fn mueller(
        &self,
        id: NodeId,
        wo: Vec3,
        wi: Vec3,
        lobe: BsdfFlags,
    ) -> Option<SampledMueller> {
        self.nodes[id as usize].mueller(self, wo, wi, lobe)
    }
}

/// Declares the BSDFs: the description enum [`Bsdf`], one variant per plugin, and the lobe enum
/// [`Node`], one variant per kind of lobes (bump and normal maps share theirs), dispatched to
/// [`BsdfModel`] and [`Bxdf`] by `match` (no dynamic dispatch in the hot path: docs/architecture.md,
/// Conventions). The descriptions are listed as leaves and adapters; the [`BsdfModel`] of each
/// follows from its [`LeafBsdf`] or [`Adapter`].
macro_rules! bsdfs {
    (
        leaves { $($leaf:ident($leaf_model:ty),)+ }
        adapters { $($adapter:ident($adapter_model:ty),)+ }
        lobes { $($node:ident($lobes:ty),)+ }
    ) => {
        bsdfs!(@descriptions $($leaf($leaf_model),)+ $($adapter($adapter_model),)+);

        $(impl BsdfModel for $leaf_model {
            #[inline]
            fn flags(&self) -> BsdfFlags {
                LeafBsdf::flags(self)
            }

            #[inline]
            fn is_dispersive(&self) -> bool {
                LeafBsdf::is_dispersive(self)
            }

            fn node_count(&self) -> usize {
                1
            }

            fn diffuse_reflectance(
                &self,
                point: &ShadingPoint,
                _wo: Vec3,
                lambda: &SampledWavelengths,
            ) -> SampledSpectrum {
                self.albedo(point.at(), lambda)
            }

            #[inline]
            fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
                tree.push(self.lobes(context.point.at(), context.lambda))
            }
        })+

        $(impl BsdfModel for $adapter_model {
            #[inline]
            fn flags(&self) -> BsdfFlags {
                self.nested()
                    .iter()
                    .fold(Self::OWN_FLAGS, |flags, b| flags.union(b.flags()))
            }

            #[inline]
            fn is_dispersive(&self) -> bool {
                self.nested().iter().any(|b| b.is_dispersive())
            }

            fn node_count(&self) -> usize {
                1 + self.nested_node_count()
            }

            fn diffuse_reflectance(
                &self,
                point: &ShadingPoint,
                wo: Vec3,
                lambda: &SampledWavelengths,
            ) -> SampledSpectrum {
                Adapter::diffuse_reflectance(self, &ResolveContext { point, wo, lambda })
            }

            #[inline]
            fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
                Adapter::resolve(self, context, tree)
            }
        })+

        /// One node of a [`BxdfTree`]: a BSDF's lobes with their textures evaluated.
        #[derive(Clone, Copy, Debug)]
        pub enum Node<'a> {
            $($node($lobes),)+
        }

        impl Bxdf for Node<'_> {
            #[inline]
            fn eval(&self, tree: &BxdfTree, wo: Vec3, wi: Vec3) -> BsdfEval {
                match self {
                    $(Node::$node(b) => b.eval(tree, wo, wi),)+
                }
            }

            #[inline]
            fn sample(&self, tree: &BxdfTree, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
                match self {
                    $(Node::$node(b) => b.sample(tree, wo, u_lobe, u),)+
                }
            }

            #[inline]
            fn null_transmission(&self, tree: &BxdfTree, wo: Vec3) -> SampledSpectrum {
                match self {
                    $(Node::$node(b) => b.null_transmission(tree, wo),)+
                }
            }

            #[inline]
            fn mueller(&self, tree: &BxdfTree, wo: Vec3, wi: Vec3, lobe: BsdfFlags) -> Option<SampledMueller> {
                match self {
                    $(Node::$node(b) => b.mueller(tree, wo, wi, lobe),)+
                }
            }
        }

        $(impl<'a> From<$lobes> for Node<'a> {
            fn from(lobes: $lobes) -> Node<'a> {
                Node::$node(lobes)
            }
        })+
    };

    (@descriptions $($variant:ident($model:ty),)+) => {
        /// A BSDF as the scene describes it (one side of a surface, unless it is two-sided by
        /// nature, as dielectrics are).
        #[derive(Clone, Debug)]
        pub enum Bsdf {
            $($variant($model),)+
        }

        impl BsdfModel for Bsdf {
            #[inline]
            fn flags(&self) -> BsdfFlags {
                match self {
                    $(Bsdf::$variant(b) => BsdfModel::flags(b),)+
                }
            }

            #[inline]
            fn is_dispersive(&self) -> bool {
                match self {
                    $(Bsdf::$variant(b) => BsdfModel::is_dispersive(b),)+
                }
            }

            fn node_count(&self) -> usize {
                match self {
                    $(Bsdf::$variant(b) => b.node_count(),)+
                }
            }

            fn diffuse_reflectance(
                &self,
                point: &ShadingPoint,
                wo: Vec3,
                lambda: &SampledWavelengths,
            ) -> SampledSpectrum {
                match self {
                    $(Bsdf::$variant(b) => BsdfModel::diffuse_reflectance(b, point, wo, lambda),)+
                }
            }

            #[inline]
            fn resolve<'a>(&'a self, context: &ResolveContext, tree: &mut BxdfTree<'a>) -> NodeId {
                match self {
                    $(Bsdf::$variant(b) => BsdfModel::resolve(b, context, tree),)+
                }
            }
        }

        $(impl From<$model> for Bsdf {
            fn from(bsdf: $model) -> Bsdf {
                Bsdf::$variant(bsdf)
            }
        })+
    };
}

bsdfs! {
    leaves {
        Diffuse(Diffuse),
        RoughDiffuse(RoughDiffuse),
        Conductor(Conductor),
        RoughConductor(RoughConductor),
        Dielectric(Dielectric),
        RoughDielectric(RoughDielectric),
        ThinDielectric(ThinDielectric),
        Plastic(Plastic),
        RoughPlastic(RoughPlastic),
        Phong(Phong),
        PolarizedPlastic(PolarizedPlastic),
        Ward(Ward),
        Principled(Principled),
        PrincipledThin(PrincipledThin),
        DiffuseTransmission(DiffuseTransmission),
        CoatedDiffuse(CoatedDiffuse),
        CoatedConductor(CoatedConductor),
        Null(Null),
        Hair(Hair),
        Measured(Measured),
        MeasuredPolarized(MeasuredPolarized),
        Polarizer(Polarizer),
        Retarder(Retarder),
        Circular(Circular),
    }
    adapters {
        TwoSided(TwoSided),
        Mask(Mask),
        Blend(Blend),
        BumpMap(BumpMap),
        NormalMap(NormalMap),
    }
    lobes {
        Diffuse(diffuse::DiffuseLobes),
        RoughDiffuse(roughdiffuse::RoughDiffuseLobes),
        Conductor(conductor::ConductorLobes),
        RoughConductor(roughconductor::RoughConductorLobes),
        Dielectric(dielectric::DielectricLobes),
        RoughDielectric(roughdielectric::RoughDielectricLobes),
        ThinDielectric(thindielectric::ThinDielectricLobes),
        Plastic(plastic::PlasticLobes<'a>),
        RoughPlastic(roughplastic::RoughPlasticLobes<'a>),
        Phong(phong::PhongLobes),
        PolarizedPlastic(pplastic::PolarizedPlasticLobes),
        Ward(ward::WardLobes),
        Principled(principled::PrincipledLobes),
        PrincipledThin(principledthin::PrincipledThinLobes),
        DiffuseTransmission(diffusetransmission::DiffuseTransmissionLobes),
        Layered(layered::LayeredLobes),
        BackSide(twosided::BackSideLobes),
        Mask(mask::MaskLobes),
        Blend(blend::BlendLobes),
        Perturbed(perturbed::PerturbedLobes),
        Null(null::NullLobes),
        Hair(hair::HairLobes<'a>),
        Measured(measured::MeasuredLobes<'a>),
        MeasuredPolarized(measured_polarized::MeasuredPolarizedLobes<'a>),
        Polarizer(polarizer::PolarizerLobes),
        Retarder(retarder::RetarderLobes),
        Circular(circular::CircularLobes),
    }
}
