//! `MakeNamedMedium`: pbrt-v4's `homogeneous` medium as Mitsuba's, σ_a and σ_s times `scale`,
//! with a Henyey-Greenstein phase function of parameter `g`. pbrt's emissive media (`Le`) and
//! its measured presets are refused.

use std::sync::Arc;

use super::builder::Builder;
use super::parameters::ParameterList;
use super::spectra;
use super::{nest, plugin, set};
use crate::description::{PluginClass, PluginNode, PropertyValue};
use prism_core::error::Result;

impl Builder {
    /// The medium of `MakeNamedMedium`'s parameters.
    pub(super) fn medium(&mut self, list: &ParameterList) -> Result<PluginNode> {
        let ty = match list.strings("type", "string")? {
            Some((_, types)) => types[0].clone(),
            None => return Err(list.directive_error("needs a \"string type\" parameter")),
        };
        if ty != "homogeneous" {
            return Err(list
                .directive_error(format!("Prism has no medium like pbrt-v4's \"{ty}\""))
                .with_help("Prism reads \"homogeneous\""));
        }
        let location = list.location.clone();
        if let Some(parameter) = list.get("preset") {
            return Err(list.error(
                parameter,
                "names pbrt's measured media, which Prism does not have",
            ));
        }
        if let Some((value, parameter)) = list.spectrum("Le", false)? {
            let is_zero = match &value {
                super::parameters::SpectrumParam::Rgb(rgb) => rgb.iter().all(|&c| c == 0.0),
                super::parameters::SpectrumParam::Samples(s) => s.iter().all(|&(_, v)| v == 0.0),
                _ => false,
            };
            if !is_zero {
                return Err(list.error(
                    parameter,
                    "makes the medium emit, which Prism's media do not",
                ));
            }
        }
        list.ignore(&["Lescale"]);
        let mut node = plugin(
            PluginClass::Medium,
            "homogeneous",
            &location,
            &self.search_paths,
        );
        for name in ["sigma_a", "sigma_s"] {
            match list.spectrum(name, false)? {
                Some((value, parameter)) => {
                    let value = spectra::spectrum(list, parameter, &value, &self.search_paths)?;
                    set(&mut node, name, value, &parameter.location);
                }
                None => set(&mut node, name, PropertyValue::Float(1.0), &location),
            }
        }
        set(
            &mut node,
            "scale",
            PropertyValue::Float(list.float("scale", 1.0)?),
            &location,
        );
        let g = list.float("g", 0.0)?;
        if g != 0.0 {
            let mut phase = plugin(PluginClass::Phase, "hg", &location, &self.search_paths);
            set(&mut phase, "g", PropertyValue::Float(g), &location);
            nest(&mut node, None, Arc::new(phase), &location);
        }
        list.finish()?;
        Ok(node)
    }
}
