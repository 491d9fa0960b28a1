//! The plugin reference: every class of plugins Prism reads, with each plugin's declared
//! parameters, as `prism plugins` prints it and `docs/plugins.md` holds it.

use std::fmt::Write;

use crate::description::PluginClass;
use crate::registry::{Origin, ParamSpec, Registry};

/// What the reference says of each plugin of a class.
fn entries<B>(registry: &Registry<B>) -> Vec<PluginReference> {
    registry
        .plugins
        .iter()
        .map(|p| PluginReference {
            name: p.name,
            origin: p.origin,
            summary: p.summary,
            params: p.params,
        })
        .collect()
}

/// What the reference says of one plugin.
pub struct PluginReference {
    pub name: &'static str,
    pub origin: Origin,
    pub summary: &'static str,
    pub params: &'static [ParamSpec],
}

/// What the reference says of one class of plugins.
pub struct ClassReference {
    pub class: PluginClass,
    pub about: &'static str,
    pub plugins: Vec<PluginReference>,
}

/// Every class of plugins Prism reads, with its plugins, in the reference's order.
pub fn reference() -> Vec<ClassReference> {
    let classes: Vec<(PluginClass, &'static str, Vec<PluginReference>)> = vec![
        (
            PluginClass::Integrator,
            "Estimators of the light arriving at the camera.",
            entries(&crate::factory::integrators::INTEGRATORS),
        ),
        (
            PluginClass::Sensor,
            "Cameras; a sensor nests its `film` and `sampler`.",
            entries(&crate::factory::sensor::SENSORS),
        ),
        (
            PluginClass::Film,
            "Where the image forms; a film nests its `rfilter`.",
            entries(&crate::factory::sensor::film::FILMS),
        ),
        (
            PluginClass::Rfilter,
            "Reconstruction filters (of the film, and of the shutter's time). Offsets are drawn with \
             p ∝ |k(x)k(y)| and weighted k/p with its sign, so negative lobes are kept; pixels \
             divide by the sample count.",
            entries(&crate::factory::sensor::rfilter::RFILTERS),
        ),
        (
            PluginClass::Sampler,
            "Per-pixel samplers of the primary dimensions (wavelength, time, film position, lens).",
            entries(&crate::factory::sensor::sampler::SAMPLERS),
        ),
        (
            PluginClass::Shape,
            "Shapes; any shape nests at most one `bsdf` (a reference or inline) and one `area` \
             `emitter`. An emitting shape without a BSDF is black (Mitsuba's rule).",
            entries(&crate::factory::shapes::SHAPES),
        ),
        (
            PluginClass::Bsdf,
            "Surface scattering. Any colour or number a BSDF takes may be a `<texture>`, inline or \
             declared at the top level and referenced with `<ref name=\"...\" id=\"...\"/>`, where \
             the type says so.",
            entries(&crate::factory::materials::BSDFS),
        ),
        (
            PluginClass::Texture,
            "Values that vary over a surface, read as colours, as numbers or (normal maps) as raw RGB.",
            entries(&crate::factory::textures::TEXTURES),
        ),
        (
            PluginClass::Emitter,
            "Light sources. A scene has at most one environment (`constant` or `envmap`).",
            entries(&crate::factory::lights::EMITTERS),
        ),
        (
            PluginClass::Medium,
            "Participating media, for the `volpath` and `volpathmis` integrators: a shape nests \
             them as `<medium name=\"interior\">` or `name=\"exterior\"` (inline or `<ref>`), the \
             sensor as the medium it sits in. Give a medium's boundary a `null` BSDF to let light \
             through unchanged. `distrib` refuses media; `path` ignores them, as Mitsuba's does.",
            entries(&crate::factory::media::MEDIA),
        ),
        (
            PluginClass::Phase,
            "Phase functions of media, nested in a `<medium>`.",
            entries(&crate::factory::media::PHASES),
        ),
        (
            PluginClass::Volume,
            "Quantities over space for `heterogeneous` media: `<volume name=\"sigma_t\" ...>` or \
             `name=\"albedo\"`.",
            entries(&crate::factory::media::VOLUMES),
        ),
        (
            PluginClass::Spectrum,
            "Spectra given as nested plugins: `<spectrum type=\"...\" name=\"...\">`.",
            entries(&crate::factory::spectra::SPECTRA),
        ),
    ];
    classes
        .into_iter()
        .map(|(class, about, plugins)| ClassReference {
            class,
            about,
            plugins,
        })
        .collect()
}

/// The reference of every plugin Prism reads, in Markdown: the contents of `docs/plugins.md`.
pub fn plugins_markdown() -> String {
    let mut text = String::from(
        "# Plugins\n\n\
         Every plugin Prism reads from a Mitsuba scene file, with its parameters and their \
         defaults. This file is generated from the plugins' declarations \
         (`crates/prism-mitsuba/src/factory/`) by `prism plugins --markdown > docs/plugins.md`; \
         a test fails when it is stale.\n\n\
         Values: `<rgb>` reflectances are upsampled to spectra (Jakob & Hanika 2019); `<rgb>` \
         and `<float>` emission is that times CIE D65 of luminance 1, as in Mitsuba 3's \
         spectral variants; `<spectrum value=\"400:0.1, 500:0.5, ...\">` is piecewise linear \
         and zero outside its range; `<spectrum value=\"v\">` is the constant v.\n",
    );
    for ClassReference {
        class,
        about,
        plugins: entries,
    } in reference()
    {
        let _ = write!(text, "\n## {}\n\n{about}\n\n", class.tag());
        text += "| type | from | what |\n| --- | --- | --- |\n";
        for e in &entries {
            let _ = writeln!(
                text,
                "| `{}` | {} | {} |",
                e.name,
                e.origin.label(),
                e.summary
            );
        }
        for e in &entries {
            let _ = write!(
                text,
                "\n### {} `{}`\n\n{}\n\n",
                class.tag(),
                e.name,
                e.summary
            );
            if e.params.is_empty() {
                text += "No parameters.\n";
                continue;
            }
            text += "| parameter | type | default | meaning |\n| --- | --- | --- | --- |\n";
            for p in e.params {
                let _ = writeln!(
                    text,
                    "| `{}` | {} | {} | {} |",
                    p.name,
                    p.kind.describe(),
                    p.default.describe(),
                    p.doc
                );
            }
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/plugins.md is the reference generated from the declarations, not a copy that drifts.
    #[test]
    fn the_plugin_reference_in_docs_is_current() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/plugins.md");
        let written =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            written == plugins_markdown(),
            "docs/plugins.md is stale: regenerate it with \
             `cargo run --release -- plugins --markdown > docs/plugins.md`"
        );
    }

    /// Within a plugin every parameter is declared once, and every class has unique names.
    #[test]
    fn declarations_are_unique() {
        for class in reference() {
            let mut names: Vec<&str> = class.plugins.iter().map(|p| p.name).collect();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), class.plugins.len(), "{}", class.class.tag());
            for plugin in &class.plugins {
                let mut params: Vec<&str> = plugin.params.iter().map(|p| p.name).collect();
                params.sort_unstable();
                let count = params.len();
                params.dedup();
                assert_eq!(params.len(), count, "{} {}", class.class.tag(), plugin.name);
                for p in plugin.params {
                    assert!(
                        !p.doc.is_empty(),
                        "{} {}: {}",
                        class.class.tag(),
                        plugin.name,
                        p.name
                    );
                }
            }
        }
    }

    /// Summaries and parameter docs are prose on one line: a run of spaces is a broken line
    /// continuation in a string literal.
    #[test]
    fn texts_have_no_runs_of_spaces() {
        for class in reference() {
            for plugin in &class.plugins {
                let texts =
                    std::iter::once(plugin.summary).chain(plugin.params.iter().map(|p| p.doc));
                for text in texts {
                    assert!(
                        !text.contains("  "),
                        "{} {}: {text:?}",
                        class.class.tag(),
                        plugin.name
                    );
                }
            }
        }
    }
}
