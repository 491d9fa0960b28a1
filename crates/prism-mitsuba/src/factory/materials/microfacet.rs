//! The roughness parameters every microfacet BSDF shares: the distribution and α, isotropic or
//! along each tangent.

use crate::factory::textures::{TextureCache, float_texture};
use crate::params::Params;
use crate::registry::{Bounds, Choice, Default, ParamKind, ParamSpec, params};
use prism_core::bsdf::microfacet::{MicrofacetKind, MicrofacetRoughness};
use prism_core::error::{Error, Result};

params! {
    pub(super) DISTRIBUTION = ParamSpec::new("distribution", ParamKind::Choice(&[Choice::new("beckmann", &MicrofacetKind::Beckmann), Choice::new("ggx", &MicrofacetKind::Ggx)]), Default::Str("beckmann"), "the microfacet distribution");
    pub(super) ALPHA = ParamSpec::new("alpha", ParamKind::FloatTexture(Bounds::POSITIVE), Default::Float(0.1), "roughness α (RMS slope for Beckmann)");
    pub(super) ALPHA_U = ParamSpec::new("alpha_u", ParamKind::FloatTexture(Bounds::POSITIVE), Default::Text("`alpha`"), "roughness along ∂p/∂u (with `alpha_v`, instead of `alpha`)");
    pub(super) ALPHA_V = ParamSpec::new("alpha_v", ParamKind::FloatTexture(Bounds::POSITIVE), Default::Text("`alpha`"), "roughness along ∂p/∂v");
    pub(super) SAMPLE_VISIBLE = ParamSpec::new("sample_visible", ParamKind::Boolean, Default::Boolean(true), "accepted; visible normals are always sampled");
}

/// The microfacet distribution and its roughness along ∂p/∂u and ∂p/∂v: `alpha`, or `alpha_u`
/// and `alpha_v` (both, and not with `alpha`), numbers above 0 or textures; default 0.1.
/// `sample_visible` is accepted: visible normals are always sampled.
pub(super) fn roughness(
    params: &Params,
    textures: &mut TextureCache,
) -> Result<MicrofacetRoughness> {
    let kind = params.choice(&DISTRIBUTION)?;
    params.boolean(&SAMPLE_VISIBLE)?;
    let (has_u, has_v) = (params.has(&ALPHA_U), params.has(&ALPHA_V));
    if has_u || has_v {
        if params.has(&ALPHA) {
            return Err(Error::input(
                params.location_of(&ALPHA),
                "give either \"alpha\" or \"alpha_u\" and \"alpha_v\", not both",
            ));
        }
        if !(has_u && has_v) {
            let missing = if has_u { "alpha_v" } else { "alpha_u" };
            return Err(Error::input(
                params.location(),
                format!(
                    "{} has an anisotropic roughness without \"{missing}\"",
                    params.node().describe()
                ),
            )
            .with_help("give both alpha_u and alpha_v"));
        }
        return Ok(MicrofacetRoughness {
            kind,
            alpha_u: float_texture(params, &ALPHA_U, textures)?,
            alpha_v: float_texture(params, &ALPHA_V, textures)?,
        });
    }
    let alpha = float_texture(params, &ALPHA, textures)?;
    Ok(MicrofacetRoughness {
        kind,
        alpha_u: alpha.clone(),
        alpha_v: alpha,
    })
}
