//! `LightSource` and `AreaLightSource`: pbrt-v4's lights as Mitsuba's emitters, their spectra
//! scaled as pbrt-v4 scales them ([`super::spectra::illuminant`]).
//!
//! `point` → `point`, `spot` → `spot` (pbrt-v4's falloff is a smoothstep in cos θ, Mitsuba's
//! linear in θ: a warning says so), `distant` → `directional`, `infinite` with a uniform `L` →
//! `constant` and with an image (`filename`, pbrt's equal-area octahedral map) →
//! `equal_area_envmap`; the area light `diffuse` → `area`. A uniform infinite light's
//! `illuminance` scales it as pbrt-v4 does; `power`, an image's `illuminance`, portals and
//! two-sided area lights are refused.

use glam::{DMat4, DVec3};

use super::builder::Builder;
use super::parameters::{Parameter, ParameterList};
use super::spectra;
use super::{plugin, set};
use crate::description::{PluginClass, PluginNode, PropertyValue};
use prism_core::error::Result;

impl Builder {
    /// The spectrum `name` (default: the colour space's illuminant) times `scale`.
    fn emission(&self, list: &ParameterList, name: &str) -> Result<PropertyValue> {
        if let Some(parameter) = list.get("illuminance") {
            return Err(list
                .error(parameter, "sets the light by a photometric quantity, which Prism's pbrt reader does not read")
                .with_help("give \"scale\" instead"));
        }
        self.scaled_emission(list, name, 1.0)
    }

    /// The spectrum `name` (default: the colour space's illuminant) times `scale` and `factor`.
    fn scaled_emission(
        &self,
        list: &ParameterList,
        name: &str,
        factor: f64,
    ) -> Result<PropertyValue> {
        if let Some(parameter) = list.get("power") {
            return Err(list
                .error(parameter, "sets the light by a photometric quantity, which Prism's pbrt reader does not read")
                .with_help("give \"scale\" instead"));
        }
        let scale = list.float("scale", 1.0)? * factor;
        let value = list.spectrum(name, false)?;
        spectra::illuminant(
            list,
            value.as_ref().map(|v| v.1),
            value.as_ref().map(|v| &v.0),
            scale,
            &self.search_paths,
        )
    }

    /// The light `ty`, placed by `ctm`.
    pub(super) fn light(
        &mut self,
        ty: &str,
        list: &ParameterList,
        ctm: DMat4,
    ) -> Result<PluginNode> {
        let location = list.location.clone();
        let mut node = match ty {
            "point" => {
                let intensity = self.emission(list, "I")?;
                let from = list.point3("from", DVec3::ZERO)?;
                let mut node = plugin(PluginClass::Emitter, "point", &location, &self.search_paths);
                set(&mut node, "intensity", intensity, &location);
                set(
                    &mut node,
                    "to_world",
                    PropertyValue::Transform(ctm * DMat4::from_translation(from)),
                    &location,
                );
                node
            }
            "spot" => {
                let intensity = self.emission(list, "I")?;
                let from = list.point3("from", DVec3::ZERO)?;
                let to = list.point3("to", DVec3::Z)?;
                let cone = list.float("coneangle", 30.0)?;
                let delta = list.float("conedeltaangle", 5.0)?;
                let Some(frame) = frame_towards(from, to) else {
                    return Err(list.directive_error("\"from\" and \"to\" are the same point"));
                };
                self.warn(
                    &location,
                    "pbrt-v4's spot light falls off as a smoothstep in cos θ, Prism's (Mitsuba's) linearly in θ",
                );
                let mut node = plugin(PluginClass::Emitter, "spot", &location, &self.search_paths);
                set(&mut node, "intensity", intensity, &location);
                set(
                    &mut node,
                    "cutoff_angle",
                    PropertyValue::Float(cone),
                    &location,
                );
                set(
                    &mut node,
                    "beam_width",
                    PropertyValue::Float((cone - delta).max(0.0)),
                    &location,
                );
                set(
                    &mut node,
                    "to_world",
                    PropertyValue::Transform(ctm * frame),
                    &location,
                );
                node
            }
            "distant" => {
                let irradiance = self.emission(list, "L")?;
                let from = list.point3("from", DVec3::ZERO)?;
                let to = list.point3("to", DVec3::Z)?;
                let direction = ctm.transform_vector3(to - from);
                if direction.length() == 0.0 {
                    return Err(list.directive_error("\"from\" and \"to\" give no direction"));
                }
                let mut node = plugin(
                    PluginClass::Emitter,
                    "directional",
                    &location,
                    &self.search_paths,
                );
                set(&mut node, "irradiance", irradiance, &location);
                set(
                    &mut node,
                    "direction",
                    PropertyValue::Vector(direction),
                    &location,
                );
                node
            }
            "infinite" => {
                if let Some(parameter) = list.get("portal") {
                    return Err(list.error(parameter, "is not read by Prism"));
                }
                if let Some((parameter, files)) = list.strings("filename", "string")? {
                    return self.image_infinite_light(list, parameter, &files[0], ctm);
                }
                // pbrt-v4 scales a uniform light of `illuminance` E (if positive) by E / π, the
                // illuminance of unit radiance on a surface facing the whole hemisphere.
                let factor = match list.float_opt("illuminance")? {
                    Some(illuminance) if illuminance > 0.0 => illuminance / std::f64::consts::PI,
                    _ => 1.0,
                };
                let radiance = self.scaled_emission(list, "L", factor)?;
                let mut node = plugin(
                    PluginClass::Emitter,
                    "constant",
                    &location,
                    &self.search_paths,
                );
                set(&mut node, "radiance", radiance, &location);
                node
            }
            _ => {
                return Err(list
                    .directive_error("Prism has no light with this pbrt-v4 model")
                    .with_help("Prism reads point, spot, distant and infinite (uniform)"));
            }
        };
        list.finish()?;
        node.location = location;
        Ok(node)
    }

    /// pbrt's image infinite light: `equal_area_envmap` with the image `filename`, `scale`
    /// (the image's RGB as illuminants of luminance 1, as for `<rgb>` emission), placed by
    /// `ctm`.
    fn image_infinite_light(
        &mut self,
        list: &ParameterList,
        parameter: &Parameter,
        filename: &str,
        ctm: DMat4,
    ) -> Result<PluginNode> {
        let location = list.location.clone();
        if let Some(radiance) = list.get("L") {
            return Err(list
                .error(radiance, "cannot be given with \"filename\"")
                .with_help("give either a uniform \"L\" or an image, as pbrt-v4 requires"));
        }
        for refused in ["power", "illuminance"] {
            if let Some(parameter) = list.get(refused) {
                return Err(list
                    .error(parameter, "sets the light by a photometric quantity, which Prism's pbrt reader does not read for an image")
                    .with_help("give \"scale\" instead"));
            }
        }
        let mut node = plugin(
            PluginClass::Emitter,
            "equal_area_envmap",
            &location,
            &self.search_paths,
        );
        set(
            &mut node,
            "filename",
            PropertyValue::String(filename.to_string()),
            &parameter.location,
        );
        set(
            &mut node,
            "scale",
            PropertyValue::Float(list.float("scale", 1.0)?),
            &location,
        );
        set(
            &mut node,
            "to_world",
            PropertyValue::Transform(ctm),
            &location,
        );
        list.finish()?;
        Ok(node)
    }

    /// The radiance of the area light `ty`.
    pub(super) fn area_light(&mut self, ty: &str, list: &ParameterList) -> Result<PropertyValue> {
        if ty != "diffuse" {
            return Err(list
                .directive_error("Prism has no area light with this pbrt-v4 model")
                .with_help("use \"diffuse\""));
        }
        if list.boolean("twosided", false)? {
            let parameter = list.get("twosided").expect("given");
            return Err(list
                .error(
                    parameter,
                    "asks for a two-sided area light; Prism's emit from the front only",
                )
                .with_help("use two shapes facing away from each other"));
        }
        if let Some(parameter) = list.get("filename") {
            return Err(list.error(
                parameter,
                "is an image area light, which Prism does not read",
            ));
        }
        let radiance = self.emission(list, "L")?;
        list.finish()?;
        Ok(radiance)
    }
}

/// A frame at `from` whose +z points to `to`.
fn frame_towards(from: DVec3, to: DVec3) -> Option<DMat4> {
    let z = (to - from).try_normalize()?;
    let (x, y) = z.any_orthonormal_pair();
    Some(DMat4::from_cols(
        x.extend(0.0),
        y.extend(0.0),
        z.extend(0.0),
        from.extend(1.0),
    ))
}
