//! `MakeNamedMedium`: pbrt-v4's `homogeneous` medium as Mitsuba's, σ_a and σ_s times `scale`,
//! and its `uniformgrid` as a `heterogeneous` medium in Prism's form of pbrt's grid media, an
//! `inlinegrid` density times σ_a and σ_s; both with a Henyey-Greenstein phase function of
//! parameter `g`. pbrt's emissive media (`Le`, `temperature`) and its measured presets are
//! refused.
//!
//! pbrt's grid medium scales σ_a and σ_s by a density d(p) over the box `p0`–`p1`:
//! σ_t(p, λ) = scale (σ_a(λ) + σ_s(λ)) d(p) with a constant albedo σ_s / (σ_a + σ_s). d is
//! interpolated trilinearly between voxel centres, and a lookup beyond the outermost centres
//! reads 0 (pbrt-v4's `SampledGrid::Lookup`), so the density fades to half its value at the
//! box's faces.
//! The translation surrounds the grid with a layer of empty voxels, so that Prism's grid,
//! clamped at its faces, has pbrt's density everywhere inside the box.
//!
//! pbrt reads a medium's RGB coefficients as unbounded spectra (`SpectrumType::Unbounded`:
//! 2·max(rgb) times the spectrum fitted to rgb / (2·max(rgb))), where Prism's factory upsamples
//! an `<rgb>` whose components are at most 1 as a reflectance, a different spectrum of the same
//! colour that light crossing the medium would tell apart; so the reader gives the factory
//! pbrt's spectrum for such a triple, sampled every 5 nm (above 1 the factory scales the triple
//! as pbrt does, and it is passed as it is).

use std::sync::Arc;

use glam::{DMat4, DVec3};

use super::builder::Builder;
use super::parameters::{ParameterList, SpectrumParam};
use super::spectra;
use super::{nest, plugin, set};
use crate::description::{PluginClass, PluginNode, PropertyValue, SpectrumValue};
use prism_core::error::Result;
use prism_core::spectrum::{RgbIntent, Spectrum};

impl Builder {
    /// The medium of `MakeNamedMedium`'s parameters, in the space `ctm` places.
    pub(super) fn medium(&mut self, list: &ParameterList, ctm: DMat4) -> Result<PluginNode> {
        let ty = match list.strings("type", "string")? {
            Some((_, types)) => types[0].clone(),
            None => return Err(list.directive_error("needs a \"string type\" parameter")),
        };
        let mut node = match ty.as_str() {
            "homogeneous" => self.homogeneous(list)?,
            "uniformgrid" => self.uniform_grid(list, ctm)?,
            _ => {
                return Err(list
                    .directive_error(format!("Prism has no medium like pbrt-v4's \"{ty}\""))
                    .with_help("Prism reads \"homogeneous\" and \"uniformgrid\""));
            }
        };
        let location = list.location.clone();
        let g = list.float("g", 0.0)?;
        if g != 0.0 {
            let mut phase = plugin(PluginClass::Phase, "hg", &location, &self.search_paths);
            set(&mut phase, "g", PropertyValue::Float(g), &location);
            nest(&mut node, None, Arc::new(phase), &location);
        }
        list.finish()?;
        Ok(node)
    }

    /// Refuses an emitting medium (a non-zero `Le`).
    fn refuse_emission(list: &ParameterList) -> Result<()> {
        if let Some((value, parameter)) = list.spectrum("Le", false)? {
            let is_zero = match &value {
                SpectrumParam::Rgb(rgb) => rgb.iter().all(|&c| c == 0.0),
                SpectrumParam::Samples(s) => s.iter().all(|&(_, v)| v == 0.0),
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
        Ok(())
    }

    fn homogeneous(&mut self, list: &ParameterList) -> Result<PluginNode> {
        let location = list.location.clone();
        if let Some(parameter) = list.get("preset") {
            return Err(list.error(
                parameter,
                "names pbrt's measured media, which Prism does not have",
            ));
        }
        Self::refuse_emission(list)?;
        let mut node = plugin(
            PluginClass::Medium,
            "homogeneous",
            &location,
            &self.search_paths,
        );
        self.coefficients(&mut node, list)?;
        Ok(node)
    }

    /// `sigma_a` and `sigma_s` (1 by default) and `scale`, which a homogeneous and a grid
    /// medium read alike.
    fn coefficients(&self, node: &mut PluginNode, list: &ParameterList) -> Result<()> {
        for name in ["sigma_a", "sigma_s"] {
            match list.spectrum(name, false)? {
                Some((value, parameter)) => {
                    let value = match value {
                        SpectrumParam::Rgb(rgb) if is_coloured_coefficient(rgb) => {
                            unbounded_samples(rgb)
                        }
                        _ => spectra::spectrum(list, parameter, &value, &self.search_paths)?,
                    };
                    set(node, name, value, &parameter.location);
                }
                None => set(node, name, PropertyValue::Float(1.0), &list.location),
            }
        }
        set(
            node,
            "scale",
            PropertyValue::Float(list.float("scale", 1.0)?),
            &list.location,
        );
        Ok(())
    }

    /// pbrt's `uniformgrid`: `density` (`nx` × `ny` × `nz` values, x fastest) over `p0`–`p1`
    /// in the medium's space (the current transformation), `sigma_a`, `sigma_s` and `scale`.
    fn uniform_grid(&mut self, list: &ParameterList, ctm: DMat4) -> Result<PluginNode> {
        let location = list.location.clone();
        Self::refuse_emission(list)?;
        if let Some(parameter) = list.get("temperature") {
            return Err(list.error(
                parameter,
                "makes the medium glow as a blackbody, which Prism's media do not",
            ));
        }
        list.ignore(&["temperaturescale", "temperatureoffset", "temperaturecutoff"]);
        let Some((density_parameter, density)) = list.array("density", &["float"], 1)? else {
            return Err(list.directive_error("needs the grid's \"float density\" values"));
        };
        let mut resolution = [0usize; 3];
        for (axis, name) in ["nx", "ny", "nz"].into_iter().enumerate() {
            let count = list.integer(name, 1)?;
            resolution[axis] = match usize::try_from(count) {
                Ok(n) if (1..=65536).contains(&n) => n,
                _ => {
                    let parameter = list.get(name).expect("given");
                    return Err(list.error(parameter, "must be between 1 and 65536"));
                }
            };
        }
        let [nx, ny, nz] = resolution;
        if nx * ny * nz != density.len() {
            return Err(list.error(
                density_parameter,
                format!(
                    "has {} values, but nx × ny × nz = {nx} × {ny} × {nz} = {} are expected",
                    density.len(),
                    nx * ny * nz
                ),
            ));
        }
        if let Some(bad) = density.iter().find(|v| !(**v >= 0.0)) {
            return Err(list.error(
                density_parameter,
                format!("holds {bad}; densities must be at least 0"),
            ));
        }
        let p0 = list.point3("p0", DVec3::ZERO)?;
        let p1 = list.point3("p1", DVec3::ONE)?;
        if !(p1.cmpgt(p0).all()) {
            return Err(list.directive_error("\"p1\" must exceed \"p0\" along every axis"));
        }

        // The grid with a layer of empty voxels around it, over the box grown by one voxel.
        let padded = [nx + 2, ny + 2, nz + 2];
        let mut values = vec![0.0; padded[0] * padded[1] * padded[2]];
        for z in 0..nz {
            for y in 0..ny {
                let from = (z * ny + y) * nx;
                let to = ((z + 1) * padded[1] + y + 1) * padded[0] + 1;
                values[to..to + nx].copy_from_slice(&density[from..from + nx]);
            }
        }
        let voxel = (p1 - p0) / DVec3::new(nx as f64, ny as f64, nz as f64);
        let (lo, hi) = (p0 - voxel, p1 + voxel);
        let to_world = ctm * DMat4::from_translation(lo) * DMat4::from_scale(hi - lo);
        let mut grid = plugin(
            PluginClass::Volume,
            "inlinegrid",
            &location,
            &self.search_paths,
        );
        set(
            &mut grid,
            "values",
            PropertyValue::Numbers(values),
            &density_parameter.location,
        );
        for (name, count) in ["resolution_x", "resolution_y", "resolution_z"]
            .into_iter()
            .zip(padded)
        {
            set(
                &mut grid,
                name,
                PropertyValue::Integer(count as i64),
                &location,
            );
        }
        set(
            &mut grid,
            "to_world",
            PropertyValue::Transform(to_world),
            &location,
        );
        self.warn(
            &location,
            "pbrt-v4's grid medium is empty outside p0–p1; Prism's keeps the grid's faded border \
             for half a voxel beyond them: the same image where the medium's shapes lie within \
             p0–p1",
        );

        let mut node = plugin(
            PluginClass::Medium,
            "heterogeneous",
            &location,
            &self.search_paths,
        );
        nest(&mut node, Some("density"), Arc::new(grid), &location);
        self.coefficients(&mut node, list)?;
        Ok(node)
    }
}

/// Whether an RGB coefficient is one the factory would upsample otherwise than pbrt does: of
/// several colours (a grey one is a constant either way), with every component in [0, 1] (above
/// 1 the factory scales it as pbrt does; the factory refuses negative and non-finite ones with
/// its own message).
fn is_coloured_coefficient(rgb: [f64; 3]) -> bool {
    rgb.iter().all(|c| (0.0..=1.0).contains(c)) && (rgb[0] != rgb[1] || rgb[1] != rgb[2])
}

/// pbrt-v4's unbounded spectrum of `rgb`, sampled every 5 nm over 360–830 nm.
fn unbounded_samples(rgb: [f64; 3]) -> PropertyValue {
    let spectrum = Spectrum::from_rgb(rgb.map(|c| c as f32), RgbIntent::Unbounded);
    let samples = (0..=94)
        .map(|i| {
            let lambda = 360.0 + 5.0 * i as f32;
            (f64::from(lambda), f64::from(spectrum.value(lambda)))
        })
        .collect();
    PropertyValue::Spectrum(SpectrumValue::Samples(samples))
}
