//! BSDF plugins, with Mitsuba 3's parameters and defaults (Mitsuba 0.6's for `roughdiffuse` and
//! `phong`, which Mitsuba 3 dropped). The checks follow Mitsuba's and add the ones it leaves to
//! chance (non-positive roughness or index, opacity outside [0, 1]).
//!
//! One module per family of BSDFs holds each plugin's entry, its parameters and its builder;
//! `microfacet` and `ior` hold the parameters several families share.

/// The parameters of a microfacet BSDF: its own, then the roughness every one of them takes
/// (`distribution`; `alpha`, or `alpha_u` and `alpha_v`; `sample_visible`).
macro_rules! microfacet_params {
    [$($own:expr),* $(,)?] => {
        &[
            $($own,)*
            $crate::factory::materials::microfacet::DISTRIBUTION,
            $crate::factory::materials::microfacet::ALPHA,
            $crate::factory::materials::microfacet::ALPHA_U,
            $crate::factory::materials::microfacet::ALPHA_V,
            $crate::factory::materials::microfacet::SAMPLE_VISIBLE,
        ]
    };
}

mod adapters;
mod conductor;
mod dielectric;
mod diffuse;
mod glossy;
mod hair;
mod ior;
mod layered;
mod measured;
mod microfacet;
mod plastic;
mod polarizing;
mod principled;

use crate::description::{PluginClass, PluginNode};
use crate::factory::textures::TextureCache;
use crate::params::Params;
use crate::registry::{Default, ParamKind, ParamSpec, Range, Registry, params};
use adapters::{ALLOW_TRANSMISSION, TWOSIDED_BSDFS, twosided_pair};
use prism_core::bsdf::{Bsdf, Diffuse, MAX_NODES, Material};
use prism_core::error::{Error, Result};
use prism_core::texture::Texture;

type Build = fn(&Params, &mut TextureCache) -> Result<Bsdf>;

/// Every BSDF, each declared in the module of its family.
pub static BSDFS: Registry<Build> = Registry {
    class: PluginClass::Bsdf,
    plugins: &[
        diffuse::DIFFUSE,
        diffuse::ROUGHDIFFUSE,
        diffuse::DIFFUSETRANSMISSION,
        conductor::CONDUCTOR,
        conductor::ROUGHCONDUCTOR,
        dielectric::DIELECTRIC,
        dielectric::ROUGHDIELECTRIC,
        dielectric::THINDIELECTRIC,
        plastic::PLASTIC,
        plastic::ROUGHPLASTIC,
        glossy::PHONG,
        plastic::PPLASTIC,
        glossy::WARD,
        principled::PRINCIPLED,
        principled::PRINCIPLEDTHIN,
        layered::COATEDDIFFUSE,
        layered::COATEDCONDUCTOR,
        hair::HAIR,
        measured::MEASURED,
        measured::MEASURED_POLARIZED,
        polarizing::POLARIZER,
        polarizing::RETARDER,
        polarizing::CIRCULAR,
        adapters::TWOSIDED,
        adapters::MASK,
        adapters::NULL,
        adapters::BLENDBSDF,
        adapters::BUMPMAP,
        adapters::NORMALMAP,
    ],
};

/// A colour parameter valued in `range` (or a texture), with a constant default.
const fn colour(name: &'static str, range: Range, default: f64, doc: &'static str) -> ParamSpec {
    ParamSpec::new(
        name,
        ParamKind::Spectrum {
            range,
            textured: true,
        },
        Default::Float(default),
        doc,
    )
}

params! {
    /// The factor on the specular reflection of dielectrics and coatings.
    SPECULAR_REFLECTANCE = colour("specular_reflectance", Range::Albedo, 1.0, "a factor on the reflected light");
    /// The reflectance of a diffuse base under a coating or a glossy lobe.
    DIFFUSE_REFLECTANCE = colour("diffuse_reflectance", Range::Albedo, 0.5, "reflectance of the diffuse base");
}

/// Mitsuba's default material for a shape without a BSDF: one-sided diffuse, reflectance 0.5.
pub fn default_material() -> Material {
    Material::new(Diffuse {
        reflectance: Texture::constant(0.5),
    })
}

/// Builds the material a `<bsdf>` element describes: a top-level `twosided` gives the front
/// and back BSDFs, anything else the front one.
pub fn build_material(node: &PluginNode, textures: &mut TextureCache) -> Result<Material> {
    let material = if node.plugin_type == "twosided" {
        let params = Params::new(node, &[TWOSIDED_BSDFS, ALLOW_TRANSMISSION]);
        let (front, back) = twosided_pair(&params, textures)?;
        params.finish()?;
        Material {
            front,
            back: Some(back),
        }
    } else {
        Material::new(build_bsdf(node, textures)?)
    };
    if material.node_count() > MAX_NODES {
        return Err(Error::input(
            &node.location,
            format!(
                "{} nests {} BSDFs and adapters, more than the {MAX_NODES} Prism supports",
                node.describe(),
                material.node_count()
            ),
        )
        .with_help("flatten the nesting: blend fewer BSDFs, or wrap fewer adapters around them"));
    }
    Ok(material)
}

/// Builds a BSDF (a `twosided` here is one nested in another adapter).
pub fn build_bsdf(node: &PluginNode, textures: &mut TextureCache) -> Result<Bsdf> {
    let plugin = BSDFS.find(node)?;
    let params = Params::new(node, plugin.params);
    let bsdf = (plugin.build)(&params, textures)?;
    params.finish()?;
    Ok(bsdf)
}
