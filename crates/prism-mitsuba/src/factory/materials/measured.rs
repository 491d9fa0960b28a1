//! Mitsuba 3's `measured`: a material of the RGL database, read from its `.bsdf` file.

use std::sync::Arc;

use super::Build;
use crate::params::Params;
use crate::registry::{Default, Origin, ParamKind, ParamSpec, Plugin, params};
use prism_core::bsdf::{Bsdf, Measured, MeasuredData};
use prism_core::error::{Error, Result};

pub(super) const MEASURED: Plugin<Build> = Plugin {
    name: "measured",
    origin: Origin::Mitsuba3,
    summary: "A measured material of the RGL database (Dupuy & Jakob 2018), from its spectral \
              `.bsdf` file, evaluated and sampled as Mitsuba 3. Reflection only, one-sided.",
    params: &[MEASURED_FILENAME],
    build: |params, _| build_measured(params),
};

params! {
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
