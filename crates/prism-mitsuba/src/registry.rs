//! The plugin registry: every plugin Prism reads from a scene, one table per class, each plugin
//! declaring its parameters once (name, type, default, meaning).
//!
//! The builders read their parameters through these declarations ([`crate::params::Params`]
//! takes a [`ParamSpec`], never a bare name), so a parameter's default is written in one place;
//! an undeclared parameter in a file is reported with the declared ones as suggestions; and the
//! plugin reference `docs/plugins.md` is generated from the same tables ([`plugins_markdown`];
//! a test fails when the file is stale).

use std::fmt::Write;

use crate::description::{PluginClass, PluginNode};
use crate::factory::spectra::Range;
use crate::params::closest_match;
use prism_core::error::{Error, Result};

/// Where a plugin comes from, for the reference: Mitsuba 3's plugin set, a form Mitsuba 0.6
/// scenes use, or Prism's own extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    Mitsuba3,
    Mitsuba06,
    Prism,
}

impl Origin {
    pub fn label(self) -> &'static str {
        match self {
            Origin::Mitsuba3 => "Mitsuba 3",
            Origin::Mitsuba06 => "Mitsuba 0.6",
            Origin::Prism => "Prism",
        }
    }
}

/// What a parameter holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    Float,
    Integer,
    Boolean,
    String,
    /// One of these strings.
    Choice(&'static [&'static str]),
    /// A `<transform>`.
    Transform,
    /// A `<transform>` or, for motion, an `<animation>` of them.
    AnimatedTransform,
    Point,
    Vector,
    /// A colour or spectrum (`<rgb>`, `<spectrum>`, `<float>`), or with `textured` a nested
    /// `<texture>` read as colours.
    Spectrum {
        range: Range,
        textured: bool,
    },
    /// A number within `Bounds`, or a nested `<texture>` read as numbers.
    FloatTexture(Bounds),
    /// An index of refraction: a number, a name, a spectrum or a dispersion formula.
    Ior,
    /// A nested plugin of a class.
    Nested(PluginClass),
}

impl ParamKind {
    fn describe(&self) -> String {
        match self {
            ParamKind::Float => "float".into(),
            ParamKind::Integer => "integer".into(),
            ParamKind::Boolean => "boolean".into(),
            ParamKind::String => "string".into(),
            ParamKind::Choice(choices) => format!("string: {}", choices.join(", ")),
            ParamKind::Transform => "transform".into(),
            ParamKind::AnimatedTransform => "transform or animation".into(),
            ParamKind::Point => "point".into(),
            ParamKind::Vector => "vector".into(),
            ParamKind::Spectrum { range, textured } => {
                let what = match range {
                    Range::Albedo => "reflectance",
                    Range::Emission => "emission",
                    Range::Unbounded => "spectrum",
                };
                if *textured {
                    format!("{what} or texture")
                } else {
                    what.into()
                }
            }
            ParamKind::FloatTexture(bounds) => format!("float or texture, {}", bounds.describe()),
            ParamKind::Ior => "index of refraction".into(),
            ParamKind::Nested(class) => format!("nested {}", class.tag()),
        }
    }
}

/// The values a number may take: at least (or, `min_exclusive`, above) `min`, at most `max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: f32,
    pub min_exclusive: bool,
    pub max: f32,
}

impl Bounds {
    /// At least 0.
    pub const NON_NEGATIVE: Bounds = Bounds {
        min: 0.0,
        min_exclusive: false,
        max: f32::INFINITY,
    };
    /// Above 0.
    pub const POSITIVE: Bounds = Bounds {
        min: 0.0,
        min_exclusive: true,
        max: f32::INFINITY,
    };
    /// In [0, 1].
    pub const UNIT: Bounds = Bounds {
        min: 0.0,
        min_exclusive: false,
        max: 1.0,
    };

    /// "in [0, 1]", "greater than 0", ...
    pub fn describe(&self) -> String {
        let (min, max) = (self.min, self.max);
        match (self.min_exclusive, max.is_finite()) {
            (true, true) => format!("in ({min}, {max}]"),
            (true, false) => format!("greater than {min}"),
            (false, true) => format!("in [{min}, {max}]"),
            (false, false) => format!("at least {min}"),
        }
    }

    pub fn contains(&self, value: f32) -> bool {
        let above_min = if self.min_exclusive {
            value > self.min
        } else {
            value >= self.min
        };
        above_min && value <= self.max && value.is_finite()
    }
}

/// A parameter's default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Default {
    Float(f64),
    Integer(i64),
    Boolean(bool),
    Str(&'static str),
    /// A default that depends on other parameters or is not a plain value, in words.
    Text(&'static str),
    /// The parameter must be given.
    Required,
    /// Absent means absent (an optional factor, an optional nested plugin).
    None,
}

impl Default {
    fn describe(&self) -> String {
        match self {
            Default::Float(v) => format_number(*v),
            Default::Integer(v) => v.to_string(),
            Default::Boolean(v) => v.to_string(),
            Default::Str(s) => format!("`{s}`"),
            Default::Text(t) => (*t).to_string(),
            Default::Required => "required".into(),
            Default::None => "—".into(),
        }
    }
}

/// A number as the reference prints it: at most four significant digits, no trailing zeros.
fn format_number(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e6 {
        return format!("{v}");
    }
    let text = format!("{v:.4}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// One declared parameter of a plugin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    pub name: &'static str,
    pub kind: ParamKind,
    pub default: Default,
    pub doc: &'static str,
}

impl ParamSpec {
    pub const fn new(
        name: &'static str,
        kind: ParamKind,
        default: Default,
        doc: &'static str,
    ) -> ParamSpec {
        ParamSpec {
            name,
            kind,
            default,
            doc,
        }
    }

    /// A nested plugin of `class`, listed in the reference under the class's tag.
    pub const fn nested(class: PluginClass, default: Default, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name: class.tag(),
            kind: ParamKind::Nested(class),
            default,
            doc,
        }
    }
}

/// A plugin: its name in scene files, where it comes from, what it is, its parameters and the
/// function that builds it (whose type depends on the class).
pub struct Plugin<B: 'static> {
    pub name: &'static str,
    pub origin: Origin,
    pub summary: &'static str,
    pub params: &'static [ParamSpec],
    pub build: B,
}

/// The plugins of one class.
pub struct Registry<B: 'static> {
    pub class: PluginClass,
    pub plugins: &'static [Plugin<B>],
}

impl<B> Registry<B> {
    /// The plugin a node names; an unknown type is an error listing the known ones.
    pub fn find(&self, node: &PluginNode) -> Result<&'static Plugin<B>> {
        let name = node.plugin_type.as_str();
        if let Some(plugin) = self.plugins.iter().find(|p| p.name == name) {
            return Ok(plugin);
        }
        let mut names = self.names();
        names.sort_unstable();
        let mut help = format!("supported {} types: {}", self.class.tag(), names.join(", "));
        if let Some(closest) = closest_match(name, &names) {
            help = format!("did you mean \"{closest}\"? {help}");
        }
        Err(Error::input(
            &node.location,
            format!("unknown {} type \"{name}\"", self.class.tag()),
        )
        .with_help(help))
    }

    /// The plugins' names, in the table's order.
    pub fn names(&self) -> Vec<&'static str> {
        self.plugins.iter().map(|p| p.name).collect()
    }

    /// The plugin called `name`.
    pub fn get(&self, name: &str) -> Option<&'static Plugin<B>> {
        self.plugins.iter().find(|p| p.name == name)
    }

    /// The reference entries of the class.
    fn entries(&self) -> Vec<PluginReference> {
        self.plugins
            .iter()
            .map(|p| PluginReference {
                name: p.name,
                origin: p.origin,
                summary: p.summary,
                params: p.params,
            })
            .collect()
    }
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
            crate::factory::integrators::INTEGRATORS.entries(),
        ),
        (
            PluginClass::Sensor,
            "Cameras; a sensor nests its `film` and `sampler`.",
            crate::factory::sensor::SENSORS.entries(),
        ),
        (
            PluginClass::Film,
            "Where the image forms; a film nests its `rfilter`.",
            crate::factory::sensor::FILMS.entries(),
        ),
        (
            PluginClass::Rfilter,
            "Reconstruction filters (of the film, and of the shutter's time). Offsets are drawn with \
             p ∝ |k(x)k(y)| and weighted k/p with its sign, so negative lobes are kept; pixels \
             divide by the sample count.",
            crate::factory::sensor::RFILTERS.entries(),
        ),
        (
            PluginClass::Sampler,
            "Per-pixel samplers of the primary dimensions (wavelength, time, film position, lens).",
            crate::factory::sensor::SAMPLERS.entries(),
        ),
        (
            PluginClass::Shape,
            "Shapes; any shape nests at most one `bsdf` (a reference or inline) and one `area` \
             `emitter`. An emitting shape without a BSDF is black (Mitsuba's rule).",
            crate::factory::shapes::SHAPES.entries(),
        ),
        (
            PluginClass::Bsdf,
            "Surface scattering. Any colour or number a BSDF takes may be a `<texture>`, inline or \
             declared at the top level and referenced with `<ref name=\"...\" id=\"...\"/>`, where \
             the type says so.",
            crate::factory::materials::BSDFS.entries(),
        ),
        (
            PluginClass::Texture,
            "Values that vary over a surface, read as colours, as numbers or (normal maps) as raw RGB.",
            crate::factory::textures::TEXTURES.entries(),
        ),
        (
            PluginClass::Emitter,
            "Light sources. A scene has at most one environment (`constant` or `envmap`).",
            crate::factory::lights::EMITTERS.entries(),
        ),
        (
            PluginClass::Spectrum,
            "Spectra given as nested plugins: `<spectrum type=\"...\" name=\"...\">`.",
            crate::factory::spectra::SPECTRA.entries(),
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
}
