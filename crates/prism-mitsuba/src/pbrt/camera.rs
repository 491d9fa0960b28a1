//! The rendering options: `Camera`, `Film`, `PixelFilter`, `Sampler` and `Integrator` as
//! Mitsuba's sensor (with its film, reconstruction filter and sampler) and integrator.
//!
//! pbrt-v4's `perspective` camera measures `fov` along the shorter image axis (Mitsuba's
//! `fov_axis` = `smaller`); its `orthographic` camera spans [−1, 1] along the shorter axis, where
//! Mitsuba's spans [−1, 1] along x, so a wide film scales the camera by its aspect ratio. pbrt's
//! `maxdepth` counts scattering events, Mitsuba's `max_depth` path segments: one more.

use std::sync::Arc;

use glam::{DMat4, DVec3};

use super::builder::Builder;
use super::parameters::ParameterList;
use super::{nest, plugin, set, transforms};
use crate::description::{PluginClass, PluginNode, PropertyValue};
use prism_core::error::{Result, SourceLocation};

/// pbrt's far end of a camera ray is unbounded; Prism's must be finite.
const FAR_CLIP: f64 = 1e9;

impl Builder {
    /// The `Integrator` (pbrt-v4's default: `volpath`, `maxdepth` 5): `path`, `volpath` or
    /// `bdpt`, whose `maxdepth` counts bounces (Prism's `max_depth` is one more).
    pub(super) fn integrator_node(&mut self, location: &SourceLocation) -> Result<PluginNode> {
        let empty = ParameterList::new("Integrator".into(), location.clone(), Vec::new());
        let given = self.integrator.take();
        let (ty, list) = match &given {
            Some((ty, list)) => (ty.as_str(), list),
            None => ("volpath", &empty),
        };
        if !matches!(ty, "path" | "volpath" | "bdpt") {
            return Err(list
                .directive_error("Prism has no integrator with pbrt-v4's model")
                .with_help("use \"path\", \"volpath\" or \"bdpt\""));
        }
        let max_depth = list.integer("maxdepth", 5)?;
        if max_depth < -1 {
            let parameter = list.get("maxdepth").expect("read above");
            return Err(list.error(parameter, "must be −1 (unbounded) or at least 0"));
        }
        if list.boolean("regularize", false)? {
            let parameter = list.get("regularize").expect("read above");
            return Err(list.error(
                parameter,
                "asks for pbrt's BSDF regularisation, which Prism does not have",
            ));
        }
        let bidirectional = ty == "bdpt";
        if bidirectional {
            for flag in ["visualizestrategies", "visualizeweights"] {
                if list.boolean(flag, false)? {
                    let parameter = list.get(flag).expect("read above");
                    return Err(list.error(
                        parameter,
                        "asks for pbrt's images of each strategy, which Prism does not write",
                    ));
                }
            }
        }
        // pbrt-v4's bdpt chooses lights by power, its path tracers by its light BVH.
        let default_sampler = if bidirectional { "power" } else { "bvh" };
        let emitter_sampling = match list.string("lightsampler", default_sampler)? {
            "bvh" => "exhaustive",
            "power" => "power",
            "uniform" => "uniform",
            other => {
                let parameter = list.get("lightsampler").expect("read above");
                return Err(list.error(
                    parameter,
                    format!("names the unknown light sampler \"{other}\""),
                ));
            }
        };
        if bidirectional && emitter_sampling != "power" {
            let parameter = list
                .get("lightsampler")
                .expect("only a given sampler differs");
            return Err(list.error(parameter, "Prism's bdpt chooses lights by power only"));
        }
        list.finish()?;
        let location = &list.location;
        let mut node = plugin(PluginClass::Integrator, ty, location, &self.search_paths);
        let max_depth = if max_depth < 0 { -1 } else { max_depth + 1 };
        set(
            &mut node,
            "max_depth",
            PropertyValue::Integer(max_depth),
            location,
        );
        if !bidirectional {
            set(
                &mut node,
                "emitter_sampling",
                PropertyValue::String(emitter_sampling.into()),
                location,
            );
        }
        Ok(node)
    }

    /// The `Camera` with its `Film`, `PixelFilter` and `Sampler`.
    pub(super) fn sensor_node(&mut self, location: &SourceLocation) -> Result<PluginNode> {
        let film = self.film_node(location)?;
        let (width, height) = film.1;
        let sampler = self.sampler_node(location)?;
        let camera = self.camera.take();
        let empty = ParameterList::new(
            "Camera \"perspective\"".into(),
            location.clone(),
            Vec::new(),
        );
        let (ty, list, camera_from_world, medium) = match &camera {
            Some(c) => (
                c.ty.as_str(),
                &c.parameters,
                c.camera_from_world,
                c.medium.as_str(),
            ),
            None => ("perspective", &empty, DMat4::IDENTITY, ""),
        };
        let location = &list.location;
        let Some(mut to_world) = transforms::sensor_to_world(camera_from_world) else {
            return Err(list.directive_error("the camera's transform is singular"));
        };
        for name in ["frameaspectratio", "screenwindow"] {
            if let Some(parameter) = list.get(name) {
                return Err(list.error(
                    parameter,
                    "is not read by Prism: the film's shape sets the image's extent",
                ));
            }
        }
        let open = list.float("shutteropen", 0.0)?;
        let close = list.float("shutterclose", 1.0)?;
        if close - open != 1.0 {
            let parameter = list
                .get("shutterclose")
                .or_else(|| list.get("shutteropen"))
                .expect("given");
            return Err(list
                .error(
                    parameter,
                    "makes pbrt scale the image by the exposure time, which Prism does not do",
                )
                .with_help("keep the shutter open for 1 unit of time (pbrt-v4's default)"));
        }
        let lens_radius = list.float("lensradius", 0.0)?;
        let focal_distance = list.float("focaldistance", 1e6)?;
        let plugin_type = match ty {
            "perspective" if lens_radius > 0.0 => "thinlens",
            "perspective" => "perspective",
            "orthographic" if lens_radius == 0.0 => "orthographic",
            _ => {
                return Err(list
                    .directive_error("Prism has no camera with this pbrt-v4 model")
                    .with_help(
                        "use \"perspective\" (with or without a lens) or \"orthographic\"",
                    ));
            }
        };
        let mut node = plugin(
            PluginClass::Sensor,
            plugin_type,
            location,
            &self.search_paths,
        );
        if ty == "perspective" {
            let fov = list.float("fov", 90.0)?;
            set(&mut node, "fov", PropertyValue::Float(fov), location);
            set(
                &mut node,
                "fov_axis",
                PropertyValue::String("smaller".into()),
                location,
            );
        } else {
            let aspect = width as f64 / height as f64;
            if aspect > 1.0 {
                to_world *= DMat4::from_scale(DVec3::new(aspect, aspect, 1.0));
            }
        }
        if plugin_type == "thinlens" {
            set(
                &mut node,
                "aperture_radius",
                PropertyValue::Float(lens_radius),
                location,
            );
            set(
                &mut node,
                "focus_distance",
                PropertyValue::Float(focal_distance),
                location,
            );
        }
        list.finish()?;
        set(
            &mut node,
            "to_world",
            PropertyValue::Transform(to_world),
            location,
        );
        set(
            &mut node,
            "far_clip",
            PropertyValue::Float(FAR_CLIP),
            location,
        );
        nest(&mut node, None, Arc::new(film.0), location);
        nest(&mut node, None, Arc::new(sampler), location);
        if !medium.is_empty() {
            let medium = self.named_medium(medium, location)?;
            nest(&mut node, Some("medium"), medium, location);
        }
        Ok(node)
    }

    /// The `Film` and its `PixelFilter`, with the film's full size.
    fn film_node(&mut self, location: &SourceLocation) -> Result<(PluginNode, (i64, i64))> {
        let empty = ParameterList::new("Film \"rgb\"".into(), location.clone(), Vec::new());
        let given = self.film.take();
        let (ty, list) = match &given {
            Some((ty, list)) => (ty.as_str(), list),
            None => ("rgb", &empty),
        };
        if ty != "rgb" {
            return Err(list
                .directive_error("Prism has no film with this pbrt-v4 model")
                .with_help("use Film \"rgb\""));
        }
        let location = list.location.clone();
        let width = list.integer("xresolution", 1280)?;
        let height = list.integer("yresolution", 720)?;
        let mut crop = [0, width, 0, height];
        if let Some((parameter, window)) = list.array("cropwindow", &["float"], 4)? {
            if window.len() != 4 || !(window[0] < window[1] && window[2] < window[3]) {
                return Err(list.error(
                    parameter,
                    "must be 4 numbers x0 x1 y0 y1 with x0 < x1, y0 < y1",
                ));
            }
            let at =
                |fraction: f64, size: i64| ((size as f64 * fraction.clamp(0.0, 1.0)).ceil()) as i64;
            crop = [
                at(window[0], width),
                at(window[1], width),
                at(window[2], height),
                at(window[3], height),
            ];
        }
        if let Some((parameter, bounds)) = list.array("pixelbounds", &["integer"], 4)? {
            if bounds.len() != 4 {
                return Err(list.error(parameter, "must be 4 numbers x0 x1 y0 y1"));
            }
            crop = [
                bounds[0] as i64,
                bounds[1] as i64,
                bounds[2] as i64,
                bounds[3] as i64,
            ];
        }
        if let Some(name) = list.string_opt("filename")? {
            let message = format!(
                "Prism writes the image where the command line says (prism render -o), not to \"{name}\""
            );
            self.warn(&location, message);
        }
        if list.float("iso", 100.0)? != 100.0 {
            let parameter = list.get("iso").expect("given");
            return Err(list
                .error(parameter, "scales the image, which Prism does not do")
                .with_help("remove it (pbrt-v4's default is 100)"));
        }
        if list.float("whitebalance", 0.0)? != 0.0 {
            let parameter = list.get("whitebalance").expect("given");
            return Err(list.error(
                parameter,
                "asks for white balancing, which Prism does not do",
            ));
        }
        if list.string("sensor", "cie1931")? != "cie1931" {
            let parameter = list.get("sensor").expect("given");
            return Err(list.error(
                parameter,
                "names a camera sensor; Prism's film is the CIE 1931 observer",
            ));
        }
        if let Some(parameter) = list.get("maxcomponentvalue") {
            return Err(list.error(parameter, "clamps samples, which Prism does not do"));
        }
        // Half or full floats in the file do not change the image.
        list.ignore(&["savefp16"]);
        list.finish()?;
        let mut node = plugin(PluginClass::Film, "hdrfilm", &location, &self.search_paths);
        set(&mut node, "width", PropertyValue::Integer(width), &location);
        set(
            &mut node,
            "height",
            PropertyValue::Integer(height),
            &location,
        );
        if crop != [0, width, 0, height] {
            set(
                &mut node,
                "crop_offset_x",
                PropertyValue::Integer(crop[0]),
                &location,
            );
            set(
                &mut node,
                "crop_offset_y",
                PropertyValue::Integer(crop[2]),
                &location,
            );
            set(
                &mut node,
                "crop_width",
                PropertyValue::Integer(crop[1] - crop[0]),
                &location,
            );
            set(
                &mut node,
                "crop_height",
                PropertyValue::Integer(crop[3] - crop[2]),
                &location,
            );
        }
        let filter = self.filter_node(&location)?;
        nest(&mut node, None, Arc::new(filter), &location);
        Ok((node, (width.max(1), height.max(1))))
    }

    /// The `PixelFilter` (pbrt-v4's default: `gaussian`, σ = 0.5, radius 1.5).
    fn filter_node(&mut self, location: &SourceLocation) -> Result<PluginNode> {
        let empty = ParameterList::new(
            "PixelFilter \"gaussian\"".into(),
            location.clone(),
            Vec::new(),
        );
        let given = self.filter.take();
        let (ty, list) = match &given {
            Some((ty, list)) => (ty.as_str(), list),
            None => ("gaussian", &empty),
        };
        let location = list.location.clone();
        let radius = |default: f64| -> Result<f64> {
            let x = list.float("xradius", default)?;
            let y = list.float("yradius", default)?;
            if x != y {
                let parameter = list
                    .get("yradius")
                    .or_else(|| list.get("xradius"))
                    .expect("given");
                return Err(list.error(
                    parameter,
                    "differs from xradius; Prism's filters are symmetric",
                ));
            }
            Ok(x)
        };
        let mut node = match ty {
            "box" => {
                let mut node = plugin(PluginClass::Rfilter, "box", &location, &self.search_paths);
                set(
                    &mut node,
                    "radius",
                    PropertyValue::Float(radius(0.5)?),
                    &location,
                );
                node
            }
            "triangle" => {
                let mut node = plugin(PluginClass::Rfilter, "tent", &location, &self.search_paths);
                set(
                    &mut node,
                    "radius",
                    PropertyValue::Float(radius(2.0)?),
                    &location,
                );
                node
            }
            "mitchell" => {
                if radius(2.0)? != 2.0 {
                    let parameter = list.get("xradius").expect("given");
                    return Err(
                        list.error(parameter, "is not 2, the radius of Prism's Mitchell filter")
                    );
                }
                let mut node = plugin(
                    PluginClass::Rfilter,
                    "mitchell",
                    &location,
                    &self.search_paths,
                );
                set(
                    &mut node,
                    "B",
                    PropertyValue::Float(list.float("B", 1.0 / 3.0)?),
                    &location,
                );
                set(
                    &mut node,
                    "C",
                    PropertyValue::Float(list.float("C", 1.0 / 3.0)?),
                    &location,
                );
                node
            }
            "gaussian" => {
                let sigma = list.float("sigma", 0.5)?;
                let cut = radius(1.5)?;
                let message = format!(
                    "pbrt's gaussian filter (σ = {sigma}, cut at {cut} pixels less its value there) is \
                     rendered with Prism's gaussian (σ = {sigma}, cut at 4σ)"
                );
                self.warn(&location, message);
                let mut node = plugin(
                    PluginClass::Rfilter,
                    "gaussian",
                    &location,
                    &self.search_paths,
                );
                set(&mut node, "stddev", PropertyValue::Float(sigma), &location);
                node
            }
            _ => {
                return Err(list
                    .directive_error("Prism has no pixel filter with this pbrt-v4 model")
                    .with_help("use \"box\", \"triangle\", \"mitchell\" or \"gaussian\""));
            }
        };
        list.finish()?;
        node.location = location;
        Ok(node)
    }

    /// The `Sampler` (pbrt-v4's default: `zsobol`, 16 samples per pixel).
    fn sampler_node(&mut self, location: &SourceLocation) -> Result<PluginNode> {
        let empty = ParameterList::new(
            "Sampler \"independent\"".into(),
            location.clone(),
            Vec::new(),
        );
        let given = self.sampler.take();
        let (ty, list) = match &given {
            Some((ty, list)) => (ty.as_str(), list),
            None => ("independent", &empty),
        };
        let location = list.location.clone();
        let (plugin_type, count) = match ty {
            "independent" => ("independent", list.integer("pixelsamples", 16)?),
            "stratified" => {
                let x = list.integer("xsamples", 4)?;
                let y = list.integer("ysamples", 4)?;
                if x != y {
                    let parameter = list
                        .get("ysamples")
                        .or_else(|| list.get("xsamples"))
                        .expect("given");
                    return Err(list.error(
                        parameter,
                        "differs from xsamples; Prism's stratified sampler is square",
                    ));
                }
                if !list.boolean("jitter", true)? {
                    let parameter = list.get("jitter").expect("given");
                    return Err(list.error(
                        parameter,
                        "is false: samples at the strata's centres do not converge",
                    ));
                }
                if x < 1 {
                    let parameter = list.get("xsamples").expect("given");
                    return Err(list.error(parameter, "must be at least 1"));
                }
                ("stratified", x.saturating_mul(y))
            }
            "halton" | "sobol" | "paddedsobol" | "zsobol" | "pmj02bn" => {
                list.ignore(&["randomization"]);
                let message = format!(
                    "pbrt's \"{ty}\" sampler is rendered with Prism's independent sampler: the same \
                     image, with other noise"
                );
                self.warn(&location, message);
                ("independent", list.integer("pixelsamples", 16)?)
            }
            _ => return Err(list.directive_error("unknown sampler")),
        };
        // The sampler's own seed wins over `Option "seed"`, as in pbrt-v4.
        let seed = list.integer("seed", self.seed.unwrap_or(0))?;
        list.finish()?;
        let mut node = plugin(
            PluginClass::Sampler,
            plugin_type,
            &location,
            &self.search_paths,
        );
        set(
            &mut node,
            "sample_count",
            PropertyValue::Integer(count),
            &location,
        );
        set(&mut node, "seed", PropertyValue::Integer(seed), &location);
        Ok(node)
    }
}
