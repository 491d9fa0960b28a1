//! pbrt-v4's spectra as Prism's property values: RGB colours, sampled spectra, blackbodies and
//! the named spectra, each read with the intent of its parameter.
//!
//! pbrt-v4 divides every light's spectrum by its photometric integral ∫ȳ(λ)S(λ)dλ
//! (`SpectrumToPhotometric`, `src/pbrt/util/spectrum.cpp`), so that `scale` sets the light's
//! luminance, and its film adds up x̄(λ)L(λ) without dividing by ∫ȳ. Prism's film divides by
//! ∫ȳ, so the same image needs S·scale·∫ȳ / ∫ȳS: the spectrum scaled to luminance `scale`
//! ([`illuminant`]). An RGB illuminant is the colour times D65 in both, D65 of luminance 1 in
//! Prism's `<rgb>`, so it only takes the scale.

use std::path::PathBuf;

use super::parameters::{Parameter, ParameterList, SpectrumParam};
use crate::description::{PropertyValue, SpectrumValue, find_file};
use prism_core::error::{Error, Result};
use prism_core::spectrum::cie::{CIE_Y_INTEGRAL_F32, cie_y};

/// A spectrum `value` of `parameter` that is not emitted (a reflectance, an index of
/// refraction, a coefficient) as a property value: the plugin's parameter gives its range.
pub fn spectrum(
    list: &ParameterList,
    parameter: &Parameter,
    value: &SpectrumParam,
    search_paths: &[PathBuf],
) -> Result<PropertyValue> {
    Ok(match value {
        SpectrumParam::Rgb(rgb) => PropertyValue::Rgb(*rgb),
        SpectrumParam::Samples(samples) => {
            PropertyValue::Spectrum(SpectrumValue::Samples(samples.clone()))
        }
        SpectrumParam::Blackbody(kelvin) => {
            let samples = blackbody_samples(*kelvin);
            let peak = samples.iter().map(|s| s.1).fold(0.0, f64::max);
            if !(peak > 0.0 && peak.is_finite()) {
                return Err(
                    list.error(parameter, "is a blackbody too cold to emit over 360-830 nm")
                );
            }
            PropertyValue::Spectrum(SpectrumValue::Samples(
                samples.into_iter().map(|(l, v)| (l, v / peak)).collect(),
            ))
        }
        SpectrumParam::Named(name) => match glass(name) {
            Some(samples) => PropertyValue::Spectrum(SpectrumValue::Samples(samples.to_vec())),
            None => match spectrum_file(list, parameter, name, search_paths)? {
                Some(samples) => PropertyValue::Spectrum(SpectrumValue::Samples(samples)),
                None => return Err(unknown_name(list, parameter, name)),
            },
        },
        SpectrumParam::Texture(_) => unreachable!("textures are resolved by the caller"),
    })
}

/// An emitted spectrum `value` of `parameter` with pbrt's `scale`, as the property value that
/// renders the same image in Prism (see the module's documentation).
pub fn illuminant(
    list: &ParameterList,
    parameter: Option<&Parameter>,
    value: Option<&SpectrumParam>,
    scale: f64,
    search_paths: &[PathBuf],
) -> Result<PropertyValue> {
    let samples = match value {
        None => return Ok(PropertyValue::Rgb([scale; 3])),
        Some(SpectrumParam::Rgb(rgb)) => return Ok(PropertyValue::Rgb(rgb.map(|c| c * scale))),
        Some(SpectrumParam::Named(name)) if name == "stdillum-D65" => {
            return Ok(PropertyValue::Rgb([scale; 3]));
        }
        Some(SpectrumParam::Samples(samples)) => samples.clone(),
        Some(SpectrumParam::Blackbody(kelvin)) => blackbody_samples(*kelvin),
        Some(SpectrumParam::Named(name)) => {
            let parameter = parameter.expect("a named spectrum comes from a parameter");
            if let Some(samples) = spectrum_file(list, parameter, name, search_paths)? {
                return illuminant(
                    list,
                    Some(parameter),
                    Some(&SpectrumParam::Samples(samples)),
                    scale,
                    search_paths,
                );
            }
            return Err(unknown_name(list, parameter, name).with_help(
                "Prism knows the illuminant \"stdillum-D65\"; give other illuminants as \
                 \"spectrum\" samples, a file of samples or \"blackbody\"",
            ));
        }
        Some(SpectrumParam::Texture(_)) => unreachable!("lights take no textures"),
    };
    let luminance = luminance(&samples);
    if !(luminance > 0.0) {
        let parameter = parameter.expect("samples come from a parameter");
        return Err(list
            .error(parameter, "has no luminance (it is zero over 360-830 nm)")
            .with_help("pbrt-v4 divides a light's spectrum by its luminance"));
    }
    let factor = scale / luminance;
    Ok(PropertyValue::Spectrum(SpectrumValue::Samples(
        samples.into_iter().map(|(l, v)| (l, v * factor)).collect(),
    )))
}

/// The samples of the spectrum file `name` (pbrt-v4's `PiecewiseLinearSpectrum::Read`):
/// wavelength and value pairs separated by whitespace, in increasing wavelength, `#` starting a
/// comment; `None` when there is no such file.
fn spectrum_file(
    list: &ParameterList,
    parameter: &Parameter,
    name: &str,
    search_paths: &[PathBuf],
) -> Result<Option<Vec<(f64, f64)>>> {
    let Ok(path) = find_file(name, search_paths, &parameter.location) else {
        return Ok(None);
    };
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path)
        .map_err(|e| Error::io(&path, &e, "read the spectrum").at(&parameter.location))?;
    let mut numbers = Vec::new();
    for line in text.lines() {
        let data = line.split('#').next().unwrap_or("");
        for token in data.split_whitespace() {
            match token.parse::<f64>() {
                Ok(value) if value.is_finite() => numbers.push(value),
                _ => {
                    return Err(list.error(
                        parameter,
                        format!("names the file \"{name}\", in which \"{token}\" is not a number"),
                    ));
                }
            }
        }
    }
    let pairs: Vec<(f64, f64)> = numbers.chunks_exact(2).map(|c| (c[0], c[1])).collect();
    if numbers.len() < 2 || numbers.len() % 2 != 0 || !pairs.windows(2).all(|w| w[0].0 < w[1].0) {
        return Err(list.error(
            parameter,
            format!(
                "names the file \"{name}\", which does not hold (wavelength, value) pairs in \
                 increasing wavelength"
            ),
        ));
    }
    Ok(Some(pairs))
}

/// The luminance ∫ȳS / ∫ȳ of samples interpolated linearly (zero outside their range), summed
/// at every nanometre from 360 to 830 as pbrt-v4's `InnerProduct` does.
pub fn luminance(samples: &[(f64, f64)]) -> f64 {
    let mut sum = 0.0;
    for lambda in 360..=830 {
        let lambda = f64::from(lambda);
        sum += f64::from(cie_y(lambda as f32)) * interpolate(samples, lambda);
    }
    sum / f64::from(CIE_Y_INTEGRAL_F32)
}

fn interpolate(samples: &[(f64, f64)], lambda: f64) -> f64 {
    let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
        return 0.0;
    };
    if lambda < first.0 || lambda > last.0 {
        return 0.0;
    }
    if samples.len() == 1 {
        return first.1;
    }
    let i = samples
        .partition_point(|s| s.0 <= lambda)
        .clamp(1, samples.len() - 1);
    let (a, b) = (samples[i - 1], samples[i]);
    if b.0 == a.0 {
        return a.1;
    }
    a.1 + (lambda - a.0) / (b.0 - a.0) * (b.1 - a.1)
}

/// Planck's law at every nanometre from 360 to 830 nm (any common factor: pbrt normalises
/// blackbodies).
fn blackbody_samples(kelvin: f64) -> Vec<(f64, f64)> {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    (360..=830)
        .map(|nm| {
            let lambda = f64::from(nm) * 1e-9;
            let value = (2.0 * H * C * C)
                / (lambda.powi(5) * ((H * C / (lambda * KB * kelvin)).exp() - 1.0));
            (f64::from(nm), value)
        })
        .collect()
}

fn unknown_name(
    list: &ParameterList,
    parameter: &Parameter,
    name: &str,
) -> prism_core::error::Error {
    list.error(
        parameter,
        format!("names the spectrum \"{name}\", which Prism does not know here"),
    )
    .with_help(format!(
        "named spectra Prism reads: stdillum-D65 (lights), {} (indices of refraction), \
         metal-*-eta and metal-*-k (conductors); or give \"spectrum\" samples or the name of \
         a file of samples",
        GLASSES.iter().map(|g| g.0).collect::<Vec<_>>().join(", ")
    ))
}

/// The index of refraction of a glass pbrt-v4 names.
pub fn glass(name: &str) -> Option<&'static [(f64, f64)]> {
    GLASSES.iter().find(|g| g.0 == name).map(|g| g.1)
}

/// pbrt-v4's glasses, as its `src/pbrt/util/spectrum.cpp` tabulates them: (nm, η).
const GLASSES: &[(&str, &[(f64, f64)])] = &[
    (
        "glass-BK7",
        &[
            (300.0, 1.5527702635739),
            (322.0, 1.5458699289209),
            (344.0, 1.5404466868331),
            (366.0, 1.536090527917),
            (388.0, 1.53252773217),
            (410.0, 1.529568767224),
            (432.0, 1.5270784291406),
            (454.0, 1.5249578457324),
            (476.0, 1.5231331738499),
            (498.0, 1.5215482528369),
            (520.0, 1.5201596882463),
            (542.0, 1.5189334783109),
            (564.0, 1.5178426478869),
            (586.0, 1.516865556749),
            (608.0, 1.5159846691816),
            (630.0, 1.5151856452759),
            (652.0, 1.5144566604975),
            (674.0, 1.513787889767),
            (696.0, 1.5131711117948),
            (718.0, 1.5125994024544),
            (740.0, 1.5120668948646),
            (762.0, 1.5115685899969),
            (784.0, 1.5111002059336),
            (806.0, 1.5106580569705),
            (828.0, 1.5102389559626),
            (850.0, 1.5098401349174),
            (872.0, 1.5094591800239),
            (894.0, 1.5090939781792),
            (916.0, 1.5087426727363),
        ],
    ),
    (
        "glass-BAF10",
        &[
            (350.0, 1.7126880848268),
            (371.0, 1.7044510025682),
            (393.0, 1.6978539633931),
            (414.0, 1.6924597573902),
            (436.0, 1.6879747521657),
            (457.0, 1.6841935148947),
            (479.0, 1.6809676313681),
            (500.0, 1.6781870617363),
            (522.0, 1.6757684467878),
            (543.0, 1.6736474831891),
            (565.0, 1.6717737892968),
            (586.0, 1.6701073530462),
            (608.0, 1.6686160168249),
            (629.0, 1.6672736605352),
            (651.0, 1.6660588657981),
            (672.0, 1.6649539185393),
            (694.0, 1.6639440538738),
            (715.0, 1.6630168772865),
            (737.0, 1.6621619159417),
            (758.0, 1.6613702672977),
            (780.0, 1.6606343213443),
            (801.0, 1.6599475391478),
            (823.0, 1.6593042748862),
            (844.0, 1.6586996317841),
            (866.0, 1.6581293446924),
            (887.0, 1.6575896837763),
            (909.0, 1.6570773750475),
        ],
    ),
    (
        "glass-FK51A",
        &[
            (290.0, 1.5145777204082),
            (312.0, 1.5092112868865),
            (334.0, 1.5049961987453),
            (356.0, 1.5016153970446),
            (378.0, 1.4988558885761),
            (400.0, 1.496569610433),
            (422.0, 1.4946506898002),
            (444.0, 1.4930216011953),
            (466.0, 1.4916244098644),
            (488.0, 1.49041505042),
            (511.0, 1.4893594837084),
            (533.0, 1.4884310526027),
            (555.0, 1.4876086240083),
            (577.0, 1.486875258765),
            (599.0, 1.486217243501),
            (621.0, 1.4856233753353),
            (643.0, 1.4850844262039),
            (665.0, 1.4845927367446),
            (687.0, 1.484141904927),
            (709.0, 1.483726544853),
            (732.0, 1.4833420981287),
            (754.0, 1.4829846850495),
            (776.0, 1.482650986233),
            (798.0, 1.4823381477539),
            (820.0, 1.4820437045732),
            (842.0, 1.4817655183243),
            (864.0, 1.481501726448),
            (886.0, 1.4812507003621),
            (908.0, 1.4810110108734),
        ],
    ),
    (
        "glass-LASF9",
        &[
            (370.0, 1.9199725545705),
            (391.0, 1.9057858245373),
            (412.0, 1.8945401582481),
            (433.0, 1.8854121949451),
            (455.0, 1.877863643024),
            (476.0, 1.8715257028176),
            (497.0, 1.8661362648008),
            (519.0, 1.8615034773283),
            (540.0, 1.8574834752011),
            (561.0, 1.8539661699122),
            (583.0, 1.8508658556),
            (604.0, 1.8481148099285),
            (625.0, 1.8456588222442),
            (646.0, 1.8434539988324),
            (668.0, 1.8414644361915),
            (689.0, 1.8396604975285),
            (710.0, 1.8380175167434),
            (732.0, 1.8365148106821),
            (753.0, 1.8351349171703),
            (774.0, 1.8338630007484),
            (796.0, 1.8326863845545),
            (817.0, 1.8315941782006),
            (838.0, 1.8305769794709),
            (859.0, 1.8296266333424),
            (881.0, 1.8287360359155),
            (902.0, 1.8278989738228),
        ],
    ),
    (
        "glass-F5",
        &[
            (370.0, 1.7286549847245),
            (391.0, 1.7170151864402),
            (412.0, 1.7079037179421),
            (433.0, 1.7005724270177),
            (455.0, 1.6945472844297),
            (476.0, 1.6895110487297),
            (497.0, 1.685242265691),
            (519.0, 1.6815810964),
            (540.0, 1.678409006027),
            (561.0, 1.6756360973958),
            (583.0, 1.6731928929908),
            (604.0, 1.6710248234743),
            (625.0, 1.6690884260039),
            (646.0, 1.6673486579281),
            (668.0, 1.6657769585173),
            (689.0, 1.6643498246044),
            (710.0, 1.6630477468358),
            (732.0, 1.6618544037398),
            (753.0, 1.6607560432197),
            (774.0, 1.6597410023473),
            (796.0, 1.6587993305922),
            (817.0, 1.6579224913632),
            (838.0, 1.6571031234995),
            (859.0, 1.6563348491305),
            (881.0, 1.6556121177295),
            (902.0, 1.654930078671),
        ],
    ),
    (
        "glass-F10",
        &[
            (380.0, 1.7905788948419),
            (401.0, 1.7776074571692),
            (422.0, 1.7673620572474),
            (443.0, 1.7590649148507),
            (464.0, 1.7522127524444),
            (486.0, 1.7464635698826),
            (507.0, 1.741575877046),
            (528.0, 1.7373738218659),
            (549.0, 1.7337260730259),
            (570.0, 1.7305324562829),
            (592.0, 1.7277151818026),
            (613.0, 1.7252129043714),
            (634.0, 1.7229765939984),
            (655.0, 1.7209665988467),
            (676.0, 1.719150514229),
            (698.0, 1.7175016091415),
            (719.0, 1.7159976462946),
            (740.0, 1.7146199848831),
            (761.0, 1.7133528897994),
            (782.0, 1.7121829937648),
            (804.0, 1.7110988742233),
            (825.0, 1.7100907173852),
            (846.0, 1.7091500491754),
            (867.0, 1.7082695180523),
            (888.0, 1.7074427184169),
            (910.0, 1.7066640460471),
        ],
    ),
    (
        "glass-F11",
        &[
            (370.0, 1.8700216173234),
            (391.0, 1.8516255860581),
            (412.0, 1.8374707714715),
            (433.0, 1.8262323798466),
            (455.0, 1.8170946940119),
            (476.0, 1.8095242343848),
            (497.0, 1.803155581666),
            (519.0, 1.7977291183308),
            (540.0, 1.7930548640505),
            (561.0, 1.7889903663666),
            (583.0, 1.7854266026774),
            (604.0, 1.7822786683156),
            (625.0, 1.7794794394722),
            (646.0, 1.7769751487395),
            (668.0, 1.7747222267051),
            (689.0, 1.7726850031375),
            (710.0, 1.770834004936),
            (732.0, 1.7691446766161),
            (753.0, 1.7675964052635),
            (774.0, 1.7661717683505),
            (796.0, 1.764855947008),
            (817.0, 1.7636362637211),
            (838.0, 1.7625018146862),
            (859.0, 1.7614431749629),
            (881.0, 1.7604521601554),
            (902.0, 1.7595216323879),
        ],
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_spectrum_over_the_tables_has_its_value_as_luminance() {
        let l = luminance(&[(360.0, 2.0), (830.0, 2.0)]);
        assert!((l - 2.0).abs() < 1e-5, "{l}");
    }

    #[test]
    fn interpolation_is_linear_and_zero_outside() {
        let s = [(400.0, 1.0), (500.0, 3.0)];
        assert_eq!(interpolate(&s, 450.0), 2.0);
        assert_eq!(interpolate(&s, 399.0), 0.0);
        assert_eq!(interpolate(&s, 500.0), 3.0);
        assert_eq!(interpolate(&s, 501.0), 0.0);
        // One sample is a spike at its wavelength.
        assert_eq!(interpolate(&[(400.0, 2.0)], 400.0), 2.0);
        assert_eq!(interpolate(&[(400.0, 2.0)], 401.0), 0.0);
    }

    #[test]
    fn a_blackbody_peaks_where_wien_says() {
        // Wien's displacement law: λ_max = 2.897771955e-3 m·K / T.
        let samples = blackbody_samples(5000.0);
        let peak = samples
            .iter()
            .cloned()
            .fold((0.0, 0.0), |a, s| if s.1 > a.1 { s } else { a });
        assert!((peak.0 - 579.55).abs() <= 1.0, "{peak:?}");
    }
}
