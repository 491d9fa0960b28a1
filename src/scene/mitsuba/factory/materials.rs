//! BSDF plugins: `diffuse` and `twosided`.

use super::spectra::{Range, spectrum_param};
use crate::bsdf::{Bsdf, Diffuse, Material};
use crate::error::{Error, Result};
use crate::scene::mitsuba::description::{PluginClass, PluginNode};
use crate::scene::mitsuba::params::Params;

/// The BSDF types this factory knows.
pub const SUPPORTED_BSDFS: &[&str] = &["diffuse", "twosided"];

/// Mitsuba's default material for a shape without a BSDF: one-sided diffuse, reflectance 0.5.
pub fn default_material() -> Material {
    Material {
        front: Bsdf::Diffuse(Diffuse {
            reflectance: crate::spectrum::Spectrum::Constant(0.5),
        }),
        back: None,
    }
}

/// Builds the material a `<bsdf>` element describes.
pub fn build_material(node: &PluginNode) -> Result<Material> {
    if node.plugin_type == "twosided" {
        let params = Params::new(node);
        let nested = params.children(PluginClass::Bsdf);
        let (front, back) = match nested.as_slice() {
            [one] => {
                let bsdf = build_one_sided(&one.node)?;
                (bsdf.clone(), bsdf)
            }
            [front, back] => (build_one_sided(&front.node)?, build_one_sided(&back.node)?),
            _ => {
                return Err(Error::input(
                    &node.location,
                    format!(
                        "bsdf \"twosided\" needs one or two nested BSDFs, found {}",
                        nested.len()
                    ),
                )
                .with_help(
                    "nest the BSDF to use on both sides, or one for the front and one for the back",
                ));
            }
        };
        params.finish()?;
        return Ok(Material {
            front,
            back: Some(back),
        });
    }
    Ok(Material {
        front: build_one_sided(node)?,
        back: None,
    })
}

/// Builds a BSDF that is not a `twosided` wrapper.
fn build_one_sided(node: &PluginNode) -> Result<Bsdf> {
    let params = Params::new(node);
    let bsdf = match node.plugin_type.as_str() {
        "diffuse" => Bsdf::Diffuse(Diffuse {
            reflectance: spectrum_param(&params, "reflectance", 0.5, Range::Albedo)?,
        }),
        "twosided" => {
            return Err(Error::input(
                &node.location,
                "a \"twosided\" BSDF cannot be nested in another \"twosided\"",
            )
            .with_help("remove the inner twosided wrapper"));
        }
        other => return Err(unknown_type(node, other)),
    };
    params.finish()?;
    Ok(bsdf)
}

fn unknown_type(node: &PluginNode, name: &str) -> Error {
    Error::input(&node.location, format!("unknown bsdf type \"{name}\"")).with_help(format!(
        "supported bsdf types: {}",
        SUPPORTED_BSDFS.join(", ")
    ))
}
