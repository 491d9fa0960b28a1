//! The plugin registry: every plugin Prism reads from a scene, one table per class, each plugin
//! declaring its parameters once (name, type, default, meaning).
//!
//! The builders read their parameters through these declarations ([`crate::params::Params`]
//! takes a [`ParamSpec`], never a bare name), so a parameter's default is written in one place;
//! an undeclared parameter in a file is reported with the declared ones as suggestions; and the
//! plugin reference `docs/plugins.md` is generated from the same tables ([`plugins_markdown`];
//! a test fails when the file is stale).

use std::any::Any;

use crate::description::{PluginClass, PluginNode};
use crate::suggest::closest_match;
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

/// How a spectral parameter may be valued.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Range {
    /// A reflectance: every value in [0, 1] (RGB components above 1 are accepted and upsampled
    /// as unbounded colours, as Mitsuba renders them).
    Albedo,
    /// Emitted radiance or intensity: non-negative.
    Emission,
    /// The real or imaginary part of a conductor's index of refraction: any non-negative
    /// value, but an `<rgb>` is read as Mitsuba 3's spectral variants read it, each component
    /// clamped to [0, 1] and the result upsampled as a reflectance (so (3.9, 2.5, 2.1) is the
    /// constant 1). The same XML then gives the same image; docs/mitsuba-compatibility.md.
    IndexPart,
    /// A medium's coefficient: any non-negative value, with `<rgb>` upsampled as a reflectance
    /// (as Mitsuba 3's spectral variants read it) and components above 1 let through unbounded.
    Coefficient,
}

/// What a parameter holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    Float,
    Integer,
    Boolean,
    String,
    /// A float within `Bounds`.
    FloatIn(Bounds),
    /// One of these strings, each selecting its value.
    Choice(&'static [Choice]),
    /// A `<transform>`.
    Transform,
    /// A `<transform>` or, for motion, an `<animation>` of them.
    AnimatedTransform,
    Point,
    Vector,
    /// A `<float>` or a `<vector>` (three raw values).
    FloatOrVector,
    /// A colour or spectrum (`<rgb>`, `<spectrum>`, `<float>`), or with `textured` a nested
    /// `<texture>` read as colours.
    Spectrum {
        range: Range,
        textured: bool,
    },
    /// A colour or spectrum, or a nested `<volume>` (a quantity over space).
    Volume(Range),
    /// A number within `Bounds`, or a nested `<texture>` read as numbers.
    FloatTexture(Bounds),
    /// An index of refraction: a number, a name, a spectrum or a dispersion formula.
    Ior,
    /// A nested plugin of a class.
    Nested(PluginClass),
    /// A list of numbers (no XML form: the pbrt-v4 reader writes it).
    Numbers,
    /// An array of numbers of given dimensions (no XML form: Mitsuba's tensors, from scene
    /// dictionaries).
    Tensor,
}

impl ParamKind {
    pub fn describe(&self) -> String {
        match self {
            ParamKind::Float => "float".into(),
            ParamKind::Integer => "integer".into(),
            ParamKind::Boolean => "boolean".into(),
            ParamKind::String => "string".into(),
            ParamKind::FloatIn(bounds) => format!("float, {}", bounds.describe()),
            ParamKind::Choice(choices) => format!("string: {}", Choice::names(choices).join(", ")),
            ParamKind::Transform => "transform".into(),
            ParamKind::AnimatedTransform => "transform or animation".into(),
            ParamKind::Point => "point".into(),
            ParamKind::Vector => "vector".into(),
            ParamKind::FloatOrVector => "float or vector".into(),
            ParamKind::Spectrum { range, textured } => {
                let what = match range {
                    Range::Albedo => "reflectance",
                    Range::Emission => "emission",
                    Range::IndexPart => "spectrum",
                    Range::Coefficient => "coefficient",
                };
                if *textured {
                    format!("{what} or texture")
                } else {
                    what.into()
                }
            }
            ParamKind::Volume(range) => match range {
                Range::Albedo => "reflectance or volume".into(),
                _ => "coefficient or volume".into(),
            },
            ParamKind::FloatTexture(bounds) => format!("float or texture, {}", bounds.describe()),
            ParamKind::Ior => "index of refraction".into(),
            ParamKind::Nested(class) => format!("nested {}", class.tag()),
            ParamKind::Numbers => "list of numbers".into(),
            ParamKind::Tensor => "tensor (scene dictionaries only)".into(),
        }
    }
}

/// One option of a choice parameter: the name a scene gives and the value it selects (`()`
/// for an option that is accepted and means nothing to Prism).
#[derive(Clone, Copy, Debug)]
pub struct Choice {
    pub name: &'static str,
    pub value: &'static (dyn Any + Send + Sync),
}

impl Choice {
    /// The option called `name`, which selects `value`.
    pub const fn new<T: Any + Send + Sync>(name: &'static str, value: &'static T) -> Choice {
        Choice { name, value }
    }

    /// Options that Prism accepts and ignores (each selects `()`).
    pub const fn accepted<const N: usize>(names: [&'static str; N]) -> [Choice; N] {
        let mut choices = [Choice::new("", &()); N];
        let mut i = 0;
        while i < N {
            choices[i] = Choice::new(names[i], &());
            i += 1;
        }
        choices
    }

    /// The options' names, in their order.
    pub fn names(choices: &[Choice]) -> Vec<&'static str> {
        choices.iter().map(|c| c.name).collect()
    }
}

impl PartialEq for Choice {
    fn eq(&self, other: &Choice) -> bool {
        self.name == other.name
    }
}

/// The values a number may take: at least (or, `min_exclusive`, above) `min`, at most `max`
/// (`f32::MAX`: any finite number).
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
    /// Any finite number.
    pub const FINITE: Bounds = Bounds::between(f32::MIN, f32::MAX);
    /// At least 0 and finite.
    pub const FINITE_NON_NEGATIVE: Bounds = Bounds::between(0.0, f32::MAX);

    /// In [min, max].
    pub const fn between(min: f32, max: f32) -> Bounds {
        Bounds {
            min,
            min_exclusive: false,
            max,
        }
    }

    /// "in [0, 1]", "greater than 0", ...
    pub fn describe(&self) -> String {
        let (min, max) = (self.min, self.max);
        if *self == Bounds::FINITE {
            return "finite".into();
        }
        match (self.min_exclusive, max < f32::MAX) {
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
    /// A Mitsuba 0.6 parameter whose meaning is clear but which Prism does not implement: it is
    /// read and ignored, with a warning ([`crate::description::Warning`]).
    Ignored,
}

impl Default {
    pub fn describe(&self) -> String {
        match self {
            Default::Float(v) => format_number(*v),
            Default::Integer(v) => v.to_string(),
            Default::Boolean(v) => v.to_string(),
            Default::Str(s) => format!("`{s}`"),
            Default::Text(t) => (*t).to_string(),
            Default::Required => "required".into(),
            Default::None => "—".into(),
            Default::Ignored => "ignored, with a warning".into(),
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

/// Declares parameters one a line, `NAME = spec;` each a `const` [`ParamSpec`], so that a
/// plugin's parameters read as a table: name, kind (with its bounds or options), default and
/// meaning.
macro_rules! params {
    ($($(#[$attr:meta])* $vis:vis $name:ident = $spec:expr;)*) => {
        $($(#[$attr])* $vis const $name: $crate::registry::ParamSpec = $spec;)*
    };
}
pub(crate) use params;

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
}
