//! Mitsuba 3's `measured` (a material of the RGL database, read from its `.bsdf` file) and
//! `measured_polarized` (a pBRDF of the KAIST database, from its `.pbsdf` file).

use std::sync::Arc;

use super::Build;
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::bsdf::{Bsdf, Measured, MeasuredData, MeasuredPolarized, MeasuredPolarizedData};
use prism_core::error::{Error, Result};

pub(super) const MEASURED: Plugin<Build> = Plugin {
    name: "measured",
    origin: Origin::Mitsuba3,
    summary: "A measured material of the RGL database (Dupuy & Jakob 2018), from its spectral \
              `.bsdf` file, evaluated and sampled as Mitsuba 3. Reflection only, one-sided.",
    params: &[MEASURED_FILENAME],
    build: |params, _| build_measured(params),
};

pub(super) const MEASURED_POLARIZED: Plugin<Build> = Plugin {
    name: "measured_polarized",
    origin: Origin::Mitsuba3,
    summary: "A measured polarimetric BRDF of the KAIST database (Baek et al. 2020), from its \
              `.pbsdf` file, evaluated and sampled as Mitsuba 3; a scene with one renders \
              polarized. Reflection only, one-sided.",
    params: &[PBSDF_FILENAME, ALPHA_SAMPLE, WAVELENGTH],
    build: |params, _| build_measured_polarized(params),
};

params! {
    PBSDF_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the `.pbsdf` file");
    ALPHA_SAMPLE = ParamSpec::new("alpha_sample", ParamKind::Float, Default::Float(0.1), "the GGX roughness (greater than 0) of the lobe that samples directions, 0.9 of them (the rest cosine-weighted): sets the noise, not the image");
    WAVELENGTH = ParamSpec::new("wavelength", ParamKind::Float, Default::Float(-1.0), "look the table up at this one wavelength (nm) for every wavelength of a path, or -1: at each path's own");
    MEASURED_FILENAME = ParamSpec::new("filename", ParamKind::String, Default::Required, "the `.bsdf` file (spectral; the RGB files are for Mitsuba's RGB variants)");
}

fn build_measured(params: &Params) -> Result<Bsdf> {
    let node = params.node();
    let location = params.location_of(&MEASURED_FILENAME);
    let filename = params.string_opt(&MEASURED_FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"material_spec.bsdf\"/>")
    })?;
    let path = node.resolve_file(filename, location)?;
    let bytes = crate::file_cache::read(&path).map_err(|e| {
        Error::input(
            location,
            format!(
                "cannot read the measured material \"{}\": {e}",
                path.display()
            ),
        )
    })?;
    let data = MeasuredData::parse(&bytes).map_err(|message| {
        Error::input(
            location,
            format!(
                "the measured material \"{}\" is unreadable: {message}",
                path.display()
            ),
        )
        .with_help("give a spectral .bsdf file of the RGL material database")
    })?;
    Ok(Bsdf::Measured(Measured {
        data: Arc::new(data),
    }))
}

fn build_measured_polarized(params: &Params) -> Result<Bsdf> {
    let node = params.node();
    let location = params.location_of(&PBSDF_FILENAME);
    let filename = params.string_opt(&PBSDF_FILENAME)?.ok_or_else(|| {
        Error::input(
            &node.location,
            format!("{} needs a \"filename\"", node.describe()),
        )
        .with_help("add <string name=\"filename\" value=\"6_gold_inpainted.pbsdf\"/>")
    })?;
    let alpha_sample = params.float(&ALPHA_SAMPLE)?;
    if !(alpha_sample > 0.0 && alpha_sample.is_finite()) {
        return Err(Error::input(
            params.location_of(&ALPHA_SAMPLE),
            format!("alpha_sample must be a number greater than 0, not {alpha_sample}"),
        ));
    }
    let wavelength = params.float(&WAVELENGTH)?;
    let wavelength = if wavelength == -1.0 {
        None
    } else if wavelength > 0.0 && wavelength.is_finite() {
        Some(wavelength as f32)
    } else {
        return Err(Error::input(
            params.location_of(&WAVELENGTH),
            format!("wavelength must be -1 or a wavelength in nm, not {wavelength}"),
        ));
    };
    let path = node.resolve_file(filename, location)?;
    let bytes = crate::file_cache::read(&path).map_err(|e| {
        Error::input(
            location,
            format!("cannot read the measured pBRDF \"{}\": {e}", path.display()),
        )
    })?;
    let data = MeasuredPolarizedData::parse(&bytes).map_err(|message| {
        Error::input(
            location,
            format!(
                "the measured pBRDF \"{}\" is unreadable: {message}",
                path.display()
            ),
        )
        .with_help("give a .pbsdf file of the KAIST pBRDF database")
    })?;
    Ok(Bsdf::MeasuredPolarized(MeasuredPolarized {
        data: Arc::new(data),
        alpha_sample: alpha_sample as f32,
        wavelength,
    }))
}
