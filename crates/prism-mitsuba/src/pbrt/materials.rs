//! `Material`, `MakeNamedMaterial` and `Texture`: pbrt-v4's materials and textures as Mitsuba's
//! BSDFs and textures.
//!
//! pbrt's BSDFs reflect from both sides of a surface, so the reflecting ones (`diffuse`,
//! `conductor`) are wrapped in `twosided`. Roughness becomes α = √roughness unless
//! `remaproughness` is false (pbrt's `RoughnessToAlpha`); below α = 10⁻³ the surface is smooth,
//! as pbrt's `EffectivelySmooth`. pbrt's `mix` picks one material per hit with probability
//! `amount` for the second: in expectation `blendbsdf`'s (1 − w) f₀ + w f₁. `interface` is
//! `null`. pbrt's image textures look up (s, 1 − t) with the image's first row at the top, so
//! the texture's `to_uv` flips v. The textures `scale` and `mix` are Prism's of the same names,
//! which implement pbrt-v4's.

use std::sync::Arc;

use glam::{DMat4, DVec3};

use super::builder::Builder;
use super::parameters::{FloatParam, ParameterList, SpectrumParam};
use super::spectra;
use super::tokenizer::Token;
use super::{nest, plugin, set};
use crate::description::{PluginClass, PluginNode, PropertyValue};
use crate::element::quote;
use prism_core::error::{Error, Result};
use prism_core::spectrum::conductors::conductor_preset;

impl Builder {
    /// The material `ty` with the parameters `list`.
    pub(super) fn material(&mut self, ty: &str, list: &ParameterList) -> Result<Arc<PluginNode>> {
        let location = list.location.clone();
        let node = match ty {
            "diffuse" => {
                let mut node = plugin(PluginClass::Bsdf, "diffuse", &location, &self.search_paths);
                self.spectrum_property(
                    &mut node,
                    list,
                    "reflectance",
                    "reflectance",
                    Some(PropertyValue::Float(0.5)),
                )?;
                twosided(node, self)
            }
            "conductor" => {
                let node = self.conductor(list)?;
                twosided(node, self)
            }
            "dielectric" | "thindielectric" => self.dielectric(ty, list)?,
            "mix" => self.mix(list)?,
            "interface" | "" | "none" => {
                plugin(PluginClass::Bsdf, "null", &location, &self.search_paths)
            }
            "coateddiffuse" => {
                let mut node = self.coating(ty, list, "eta", "")?;
                self.spectrum_property(
                    &mut node,
                    list,
                    "reflectance",
                    "reflectance",
                    Some(PropertyValue::Float(0.5)),
                )?;
                node
            }
            "coatedconductor" => {
                let mut node = self.coating(ty, list, "interface.eta", "interface.")?;
                self.conductor_index(&mut node, list, "conductor.eta", "conductor.k")?;
                let (u, v) = self.roughness_values(list, "conductor.")?;
                set_alpha(&mut node, list, "conductor_alpha", (u, v));
                node
            }
            "diffusetransmission" => {
                let mut node = plugin(
                    PluginClass::Bsdf,
                    "diffusetransmission",
                    &location,
                    &self.search_paths,
                );
                for name in ["reflectance", "transmittance"] {
                    self.spectrum_property(
                        &mut node,
                        list,
                        name,
                        name,
                        Some(PropertyValue::Float(0.25)),
                    )?;
                }
                if list.float("scale", 1.0)? != 1.0 {
                    let parameter = list.get("scale").expect("given");
                    return Err(list.error(
                        parameter,
                        "is not read by Prism: scale the reflectance and transmittance instead",
                    ));
                }
                node
            }
            _ => {
                return Err(list
                    .directive_error("Prism has no material with this pbrt-v4 model")
                    .with_help("Prism reads diffuse, conductor, dielectric, thindielectric, coateddiffuse, coatedconductor, diffusetransmission, mix and interface"));
            }
        };
        list.finish()?;
        Ok(Arc::new(node))
    }

    /// Sets `prism_name` from the spectrum or spectrum texture `pbrt_name`, or to `default`.
    fn spectrum_property(
        &self,
        node: &mut PluginNode,
        list: &ParameterList,
        pbrt_name: &str,
        prism_name: &str,
        default: Option<PropertyValue>,
    ) -> Result<()> {
        match list.spectrum(pbrt_name, true)? {
            Some((SpectrumParam::Texture(name), parameter)) => {
                let texture = self.spectrum_textures.get(&name).cloned().ok_or_else(|| {
                    list.error(
                        parameter,
                        format!("names the unknown spectrum texture \"{}\"", quote(&name)),
                    )
                    .with_help("declare it with Texture \"name\" \"spectrum\" ... first")
                })?;
                nest(node, Some(prism_name), texture, &parameter.location);
            }
            Some((value, parameter)) => {
                let value = spectra::spectrum(list, parameter, &value, &self.search_paths)?;
                set(node, prism_name, value, &parameter.location);
            }
            None => {
                if let Some(value) = default {
                    set(node, prism_name, value, &list.location);
                }
            }
        }
        Ok(())
    }

    /// Sets `prism_name` from the float or float texture `pbrt_name`, or to `default`.
    fn float_property(
        &self,
        node: &mut PluginNode,
        list: &ParameterList,
        pbrt_name: &str,
        prism_name: &str,
        default: f64,
    ) -> Result<()> {
        match list.float_or_texture(pbrt_name)? {
            Some((FloatParam::Texture(name), parameter)) => {
                let texture = self.float_textures.get(&name).cloned().ok_or_else(|| {
                    list.error(
                        parameter,
                        format!("names the unknown float texture \"{}\"", quote(&name)),
                    )
                    .with_help("declare it with Texture \"name\" \"float\" ... first")
                })?;
                nest(node, Some(prism_name), texture, &parameter.location);
            }
            Some((FloatParam::Value(value), parameter)) => {
                set(
                    node,
                    prism_name,
                    PropertyValue::Float(value),
                    &parameter.location,
                );
            }
            None => set(
                node,
                prism_name,
                PropertyValue::Float(default),
                &list.location,
            ),
        }
        Ok(())
    }

    /// pbrt's roughness as (αu, αv), or `None` for a smooth surface.
    fn roughness(&mut self, list: &ParameterList) -> Result<Option<(f64, f64)>> {
        let (u, v) = self.roughness_values(list, "")?;
        if u.max(v) < 1e-3 {
            return Ok(None);
        }
        self.warn(
            &list.location,
            "pbrt-v4's rough surfaces (Trowbridge-Reitz with height-correlated masking) are \
             rendered with Prism's GGX (Mitsuba's, with separable masking)",
        );
        Ok(Some((u, v)))
    }

    /// pbrt's `{prefix}roughness`, `{prefix}uroughness` and `{prefix}vroughness` as (αu, αv):
    /// √roughness unless `remaproughness` is false (pbrt's `RoughnessToAlpha`).
    fn roughness_values(&self, list: &ParameterList, prefix: &str) -> Result<(f64, f64)> {
        let value = |name: &str, default: f64| -> Result<f64> {
            match list.float_or_texture(name)? {
                Some((FloatParam::Value(v), _)) => Ok(v),
                Some((FloatParam::Texture(_), parameter)) => Err(list.error(
                    parameter,
                    "is a texture; Prism's pbrt reader reads constant roughness only",
                )),
                None => Ok(default),
            }
        };
        let roughness = value(&format!("{prefix}roughness"), 0.0)?;
        let u = value(&format!("{prefix}uroughness"), roughness)?;
        let v = value(&format!("{prefix}vroughness"), roughness)?;
        Ok(if list.boolean("remaproughness", true)? {
            (u.max(0.0).sqrt(), v.max(0.0).sqrt())
        } else {
            (u.max(0.0), v.max(0.0))
        })
    }

    fn set_roughness(node: &mut PluginNode, list: &ParameterList, (u, v): (f64, f64)) {
        let location = &list.location;
        set(
            node,
            "distribution",
            PropertyValue::String("ggx".into()),
            location,
        );
        if u == v {
            set(node, "alpha", PropertyValue::Float(u), location);
        } else {
            set(node, "alpha_u", PropertyValue::Float(u), location);
            set(node, "alpha_v", PropertyValue::Float(v), location);
        }
    }

    fn conductor(&mut self, list: &ParameterList) -> Result<PluginNode> {
        if let Some(parameter) = list.get("reflectance") {
            return Err(list
                .error(
                    parameter,
                    "asks for pbrt's conductor by reflectance, which Prism does not have",
                )
                .with_help("give \"spectrum eta\" and \"spectrum k\""));
        }
        let rough = self.roughness(list)?;
        let plugin_type = if rough.is_some() {
            "roughconductor"
        } else {
            "conductor"
        };
        let mut node = plugin(
            PluginClass::Bsdf,
            plugin_type,
            &list.location,
            &self.search_paths,
        );
        self.conductor_index(&mut node, list, "eta", "k")?;
        if let Some(alpha) = rough {
            Self::set_roughness(&mut node, list, alpha);
        }
        Ok(node)
    }

    /// A conductor's index from the spectra `eta_name` and `k_name` (pbrt's default: copper):
    /// the `material` of a metal Prism's table has, or both as spectra.
    fn conductor_index(
        &self,
        node: &mut PluginNode,
        list: &ParameterList,
        eta_name: &str,
        k_name: &str,
    ) -> Result<()> {
        let eta = list.spectrum(eta_name, false)?;
        let k = list.spectrum(k_name, false)?;
        let metal = |value: &Option<(SpectrumParam, &super::parameters::Parameter)>, part: &str| {
            match value {
                None => Some("Cu".to_string()),
                Some((SpectrumParam::Named(name), _)) => name
                    .strip_prefix("metal-")
                    .and_then(|rest| rest.strip_suffix(part))
                    .map(str::to_string),
                Some(_) => None,
            }
        };
        match (metal(&eta, "-eta"), metal(&k, "-k")) {
            (Some(a), Some(b)) if a == b && conductor_preset(&a).is_some() => {
                set(node, "material", PropertyValue::String(a), &list.location);
            }
            _ => {
                for (value, name) in [(&eta, "eta"), (&k, "k")] {
                    let Some((value, parameter)) = value else {
                        return Err(list.directive_error(format!(
                            "needs {eta_name} and {k_name} of the same metal (metal-*-eta and \
                             metal-*-k of a metal Prism knows), or both as spectra"
                        )));
                    };
                    match spectra::spectrum(list, parameter, value, &self.search_paths)? {
                        spectrum @ PropertyValue::Spectrum(_) => {
                            set(node, name, spectrum, &parameter.location)
                        }
                        _ => {
                            return Err(list.error(
                                parameter,
                                "must be a spectrum (samples or a file), or the metal-*-eta / \
                                 metal-*-k pair of a metal Prism knows; Prism reads RGB indices \
                                 otherwise than pbrt",
                            ));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// pbrt's coating and slab (`coateddiffuse`, `coatedconductor`): the index `eta_name`, the
    /// roughness `{prefix}roughness`, and `thickness`, `albedo`, `g`, `maxdepth`, `nsamples`.
    fn coating(
        &self,
        ty: &str,
        list: &ParameterList,
        eta_name: &str,
        prefix: &str,
    ) -> Result<PluginNode> {
        let location = &list.location;
        let mut node = plugin(PluginClass::Bsdf, ty, location, &self.search_paths);
        let eta = match list.get(eta_name) {
            None => 1.5,
            Some(parameter) if parameter.is("float") => list.float(eta_name, 1.5)?,
            Some(parameter) => {
                return Err(list.error(
                    parameter,
                    "must be a number: Prism's coatings have a constant index (pbrt lets a \
                     spectrum disperse)",
                ));
            }
        };
        let eta_prism = if ty == "coateddiffuse" {
            "eta"
        } else {
            "interface_eta"
        };
        let alpha_prism = if ty == "coateddiffuse" {
            "alpha"
        } else {
            "interface_alpha"
        };
        set(&mut node, eta_prism, PropertyValue::Float(eta), location);
        let (u, v) = self.roughness_values(list, prefix)?;
        set_alpha(&mut node, list, alpha_prism, (u, v));
        for (name, default) in [("thickness", 0.01), ("g", 0.0)] {
            let value = match list.float_or_texture(name)? {
                Some((FloatParam::Value(v), _)) => v,
                Some((FloatParam::Texture(_), parameter)) => {
                    return Err(list.error(
                        parameter,
                        "is a texture; Prism's pbrt reader reads a constant",
                    ));
                }
                None => default,
            };
            let value = if name == "g" {
                value.clamp(-1.0, 1.0)
            } else {
                value.max(0.0)
            };
            set(&mut node, name, PropertyValue::Float(value), location);
        }
        self.spectrum_property(
            &mut node,
            list,
            "albedo",
            "albedo",
            Some(PropertyValue::Float(0.0)),
        )?;
        for (pbrt, prism, default) in [("maxdepth", "max_depth", 10), ("nsamples", "samples", 1)] {
            let value = list.integer(pbrt, default)?;
            if !(1..=65536).contains(&value) {
                let parameter = list.get(pbrt).expect("given");
                return Err(list.error(parameter, "must be between 1 and 65536"));
            }
            set(&mut node, prism, PropertyValue::Integer(value), location);
        }
        Ok(node)
    }

    fn dielectric(&mut self, ty: &str, list: &ParameterList) -> Result<PluginNode> {
        let rough = if ty == "dielectric" {
            self.roughness(list)?
        } else {
            None
        };
        let plugin_type = match (ty, rough) {
            ("thindielectric", _) => "thindielectric",
            (_, Some(_)) => "roughdielectric",
            (_, None) => "dielectric",
        };
        let mut node = plugin(
            PluginClass::Bsdf,
            plugin_type,
            &list.location,
            &self.search_paths,
        );
        let eta = match list.get("eta") {
            Some(parameter) if parameter.is("float") => {
                PropertyValue::Float(list.float("eta", 1.5)?)
            }
            Some(_) => match list.spectrum("eta", false)? {
                Some((value, parameter)) => {
                    spectra::spectrum(list, parameter, &value, &self.search_paths)?
                }
                None => unreachable!("given"),
            },
            None => PropertyValue::Float(1.5),
        };
        set(&mut node, "int_ior", eta, &list.location);
        set(
            &mut node,
            "ext_ior",
            PropertyValue::Float(1.0),
            &list.location,
        );
        if let Some(alpha) = rough {
            Self::set_roughness(&mut node, list, alpha);
        }
        Ok(node)
    }

    fn mix(&mut self, list: &ParameterList) -> Result<PluginNode> {
        let Some((parameter, names)) = list.strings("materials", "string")? else {
            return Err(list.directive_error("needs \"string materials\" [ \"a\" \"b\" ]"));
        };
        if names.len() != 2 {
            return Err(list.error(parameter, "must name two materials"));
        }
        let mut node = plugin(
            PluginClass::Bsdf,
            "blendbsdf",
            &list.location,
            &self.search_paths,
        );
        self.float_property(&mut node, list, "amount", "weight", 0.5)?;
        for name in names {
            let material = self.named_material(name, &parameter.location)?;
            nest(&mut node, None, material, &parameter.location);
        }
        Ok(node)
    }

    /// `Texture "name" "spectrum"|"float" "class" ...`, defined where `ctm` places it.
    pub(super) fn add_texture(
        &mut self,
        name: &Token,
        kind: &Token,
        class: &str,
        list: &ParameterList,
        ctm: DMat4,
    ) -> Result<()> {
        let float = match kind.text.as_str() {
            "float" => true,
            "spectrum" => false,
            other => {
                return Err(Error::input(
                    &kind.location,
                    format!("unknown texture kind \"{}\"", quote(other)),
                )
                .with_help("write \"spectrum\" or \"float\""));
            }
        };
        let location = list.location.clone();
        let mapping = self.uv_mapping(list)?;
        let node = match class {
            "imagemap" => {
                let Some((parameter, files)) = list.strings("filename", "string")? else {
                    return Err(list.directive_error("needs \"string filename\""));
                };
                let filename = files[0].clone();
                let mut node = plugin(
                    PluginClass::Texture,
                    "bitmap",
                    &location,
                    &self.search_paths,
                );
                set(
                    &mut node,
                    "filename",
                    PropertyValue::String(filename.clone()),
                    &parameter.location,
                );
                let filter = match list.string("filter", "bilinear")? {
                    "point" => "nearest",
                    "bilinear" => "bilinear",
                    other => {
                        let parameter = list.get("filter").expect("given");
                        return Err(list.error(parameter, format!("asks for the filter \"{other}\"; Prism reads \"point\" and \"bilinear\"")));
                    }
                };
                set(
                    &mut node,
                    "filter_type",
                    PropertyValue::String(filter.into()),
                    &location,
                );
                let wrap = match list.string("wrap", "repeat")? {
                    "repeat" => "repeat",
                    "clamp" => "clamp",
                    other => {
                        let parameter = list.get("wrap").expect("given");
                        return Err(list.error(parameter, format!("asks for the wrap mode \"{other}\"; Prism reads \"repeat\" and \"clamp\"")));
                    }
                };
                set(
                    &mut node,
                    "wrap_mode",
                    PropertyValue::String(wrap.into()),
                    &location,
                );
                let png = filename.to_ascii_lowercase().ends_with(".png");
                let raw = match list.string("encoding", if png { "sRGB" } else { "linear" })? {
                    "sRGB" => false,
                    "linear" => true,
                    _ => {
                        let parameter = list.get("encoding").expect("given");
                        return Err(list.error(
                            parameter,
                            "Prism reads the encodings \"sRGB\" and \"linear\"",
                        ));
                    }
                };
                set(&mut node, "raw", PropertyValue::Boolean(raw), &location);
                for (name, neutral) in [("scale", 1.0)] {
                    if list.float(name, neutral)? != neutral {
                        let parameter = list.get(name).expect("given");
                        return Err(list.error(parameter, "is not read by Prism"));
                    }
                }
                if list.boolean("invert", false)? {
                    let parameter = list.get("invert").expect("given");
                    return Err(list.error(parameter, "is not read by Prism"));
                }
                if float {
                    self.warn(
                        &location,
                        "a float image texture of a colour image is read as its luminance (pbrt: the channels' average)",
                    );
                }
                // (s, t) → (s, 1 − t): pbrt's first image row is at t = 1.
                let flip = DMat4::from_translation(DVec3::new(0.0, 1.0, 0.0))
                    * DMat4::from_scale(DVec3::new(1.0, -1.0, 1.0));
                set(
                    &mut node,
                    "to_uv",
                    PropertyValue::Transform(flip * mapping),
                    &location,
                );
                node
            }
            "checkerboard" => {
                if list.integer("dimension", 2)? != 2 {
                    let parameter = list.get("dimension").expect("given");
                    return Err(list.error(
                        parameter,
                        "asks for a 3D checkerboard, which Prism does not have",
                    ));
                }
                let mut node = plugin(
                    PluginClass::Texture,
                    "checkerboard",
                    &location,
                    &self.search_paths,
                );
                // Prism's checkerboard has squares of ½ and, read as a number, the other phase.
                let (first, second) = if float {
                    ("color1", "color0")
                } else {
                    ("color0", "color1")
                };
                if float {
                    self.float_property(&mut node, list, "tex1", first, 1.0)?;
                    self.float_property(&mut node, list, "tex2", second, 0.0)?;
                } else {
                    self.spectrum_property(
                        &mut node,
                        list,
                        "tex1",
                        first,
                        Some(PropertyValue::Float(1.0)),
                    )?;
                    self.spectrum_property(
                        &mut node,
                        list,
                        "tex2",
                        second,
                        Some(PropertyValue::Float(0.0)),
                    )?;
                }
                self.warn(
                    &location,
                    "pbrt-v4 filters the checkerboard over each pixel's footprint; Prism samples it at the hit",
                );
                let half = DMat4::from_scale(DVec3::new(0.5, 0.5, 1.0));
                set(
                    &mut node,
                    "to_uv",
                    PropertyValue::Transform(half * mapping),
                    &location,
                );
                node
            }
            "scale" => {
                let mut node = plugin(PluginClass::Texture, "scale", &location, &self.search_paths);
                self.texture_operand(&mut node, list, float, "tex", 1.0)?;
                self.float_property(&mut node, list, "scale", "scale", 1.0)?;
                node
            }
            "mix" => {
                let mut node = plugin(PluginClass::Texture, "mix", &location, &self.search_paths);
                self.texture_operand(&mut node, list, float, "tex1", 0.0)?;
                self.texture_operand(&mut node, list, float, "tex2", 1.0)?;
                self.float_property(&mut node, list, "amount", "amount", 0.5)?;
                node
            }
            "directionmix" => {
                let mut node = plugin(
                    PluginClass::Texture,
                    "directionmix",
                    &location,
                    &self.search_paths,
                );
                self.texture_operand(&mut node, list, float, "tex1", 0.0)?;
                self.texture_operand(&mut node, list, float, "tex2", 1.0)?;
                // pbrt-v4 takes `dir` to render space by the transformation current here.
                let dir = ctm.transform_vector3(list.vector3("dir", DVec3::Y)?);
                if !(dir.length() > 0.0 && dir.is_finite()) {
                    let problem =
                        "has no direction (it is zero, or the transformation makes it zero)";
                    return Err(match list.get("dir") {
                        Some(parameter) => list.error(parameter, problem),
                        None => list.directive_error(format!("\"dir\" (0, 1, 0) {problem}")),
                    });
                }
                set(&mut node, "dir", PropertyValue::Vector(dir), &location);
                node
            }
            _ => {
                return Err(list
                    .directive_error("Prism has no texture with this pbrt-v4 model")
                    .with_help("Prism reads imagemap, checkerboard, scale, mix and directionmix"));
            }
        };
        list.finish()?;
        let textures = if float {
            &mut self.float_textures
        } else {
            &mut self.spectrum_textures
        };
        textures.insert(name.text.clone(), Arc::new(node));
        Ok(())
    }

    /// The operand `name` of a `scale`, `mix` or `directionmix` texture: a number or float texture in a float
    /// texture, a spectrum or spectrum texture in a spectrum texture; `default` when absent.
    fn texture_operand(
        &self,
        node: &mut PluginNode,
        list: &ParameterList,
        float: bool,
        name: &str,
        default: f64,
    ) -> Result<()> {
        if float {
            self.float_property(node, list, name, name, default)
        } else {
            self.spectrum_property(node, list, name, name, Some(PropertyValue::Float(default)))
        }
    }

    /// pbrt's `uv` mapping: (s, t) = (su·u + du, sv·v + dv).
    fn uv_mapping(&self, list: &ParameterList) -> Result<DMat4> {
        let mapping = list.string("mapping", "uv")?;
        if mapping != "uv" {
            let parameter = list.get("mapping").expect("given");
            return Err(list.error(
                parameter,
                format!("asks for the mapping \"{mapping}\"; Prism reads \"uv\""),
            ));
        }
        let su = list.float("uscale", 1.0)?;
        let sv = list.float("vscale", 1.0)?;
        let du = list.float("udelta", 0.0)?;
        let dv = list.float("vdelta", 0.0)?;
        Ok(DMat4::from_translation(DVec3::new(du, dv, 0.0))
            * DMat4::from_scale(DVec3::new(su, sv, 1.0)))
    }
}

/// Sets the roughness `name` (or `{name}_u` and `{name}_v` where they differ).
fn set_alpha(node: &mut PluginNode, list: &ParameterList, name: &str, (u, v): (f64, f64)) {
    let location = &list.location;
    if u == v {
        set(node, name, PropertyValue::Float(u), location);
    } else {
        set(
            node,
            &format!("{name}_u"),
            PropertyValue::Float(u),
            location,
        );
        set(
            node,
            &format!("{name}_v"),
            PropertyValue::Float(v),
            location,
        );
    }
}

/// A reflecting BSDF on both sides, as pbrt's BSDFs are.
fn twosided(node: PluginNode, builder: &Builder) -> PluginNode {
    let location = node.location.clone();
    let mut wrapper = plugin(
        PluginClass::Bsdf,
        "twosided",
        &location,
        &builder.search_paths,
    );
    nest(&mut wrapper, None, Arc::new(node), &location);
    wrapper
}
