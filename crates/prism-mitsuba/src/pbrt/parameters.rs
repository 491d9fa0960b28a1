//! A directive's parameter list (pbrt-v4's `ParameterDictionary`): `"type name" value`
//! pairs, where the value is one token or a bracketed list, read with their types checked.
//!
//! Every read marks its parameter used; [`ParameterList::finish`] refuses any parameter that no
//! translation read, with its location, so that a parameter Prism cannot render faithfully is
//! never dropped silently.

use std::cell::Cell;

use glam::DVec3;

use super::tokenizer::{Token, TokenKind};
use crate::element::quote;
use prism_core::error::{Error, Result, SourceLocation};

/// The parameter types of pbrt-v4's scene format.
const TYPES: &[&str] = &[
    "integer",
    "float",
    "point2",
    "vector2",
    "point3",
    "vector3",
    "normal3",
    "point",
    "vector",
    "normal",
    "bool",
    "string",
    "texture",
    "rgb",
    "spectrum",
    "blackbody",
];

/// The values of one parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    Numbers(Vec<f64>),
    Strings(Vec<String>),
    Bools(Vec<bool>),
}

/// One `"type name" value` pair.
#[derive(Debug)]
pub struct Parameter {
    /// The type as written (`point` and `point3` stay distinct here; see [`Parameter::is`]).
    pub ty: String,
    pub name: String,
    pub values: Values,
    /// Where the `"type name"` string starts.
    pub location: SourceLocation,
    used: Cell<bool>,
}

impl Parameter {
    /// Whether the parameter has the type `ty`, pbrt's synonyms included.
    pub fn is(&self, ty: &str) -> bool {
        canonical(&self.ty) == canonical(ty)
    }

    /// `"float radius"`, for messages.
    pub fn describe(&self) -> String {
        format!("\"{} {}\"", self.ty, self.name)
    }
}

fn canonical(ty: &str) -> &str {
    match ty {
        "point" => "point3",
        "vector" => "vector3",
        "normal" => "normal3",
        other => other,
    }
}

/// A spectrum-valued parameter (`rgb`, `spectrum`, `blackbody`) or a texture reference.
#[derive(Clone, Debug, PartialEq)]
pub enum SpectrumParam {
    Rgb([f64; 3]),
    /// (wavelength in nm, value) pairs in increasing wavelength.
    Samples(Vec<(f64, f64)>),
    /// A named spectrum of pbrt-v4 (`metal-Cu-eta`, `glass-BK7`, `stdillum-D65`, ...).
    Named(String),
    /// A blackbody at this temperature in kelvin, normalised to a peak of 1.
    Blackbody(f64),
    /// The name of a texture.
    Texture(String),
}

/// The parameters of one directive.
#[derive(Debug)]
pub struct ParameterList {
    /// The directive and its type, for messages: `Shape "sphere"`.
    pub directive: String,
    pub location: SourceLocation,
    parameters: Vec<Parameter>,
}

impl ParameterList {
    pub fn new(directive: String, location: SourceLocation, parameters: Vec<Parameter>) -> Self {
        ParameterList {
            directive,
            location,
            parameters,
        }
    }

    /// The parameter called `name`, marked used.
    pub fn get(&self, name: &str) -> Option<&Parameter> {
        let parameter = self.parameters.iter().find(|p| p.name == name)?;
        parameter.used.set(true);
        Some(parameter)
    }

    /// Marks the parameters called `names` used, whatever their values (those that do not
    /// change the image).
    pub fn ignore(&self, names: &[&str]) {
        for name in names {
            self.get(name);
        }
    }

    /// An error about `parameter`.
    pub fn error(&self, parameter: &Parameter, problem: impl std::fmt::Display) -> Error {
        Error::input(
            &parameter.location,
            format!(
                "{}: parameter {} {problem}",
                self.directive,
                parameter.describe()
            ),
        )
    }

    /// An error about the directive.
    pub fn directive_error(&self, problem: impl std::fmt::Display) -> Error {
        Error::input(&self.location, format!("{}: {problem}", self.directive))
    }

    fn wrong_type(&self, parameter: &Parameter, expected: &str) -> Error {
        self.error(parameter, format!("must be of type {expected}"))
            .with_help(format!("write it as \"{expected} {}\"", parameter.name))
    }

    fn numbers(&self, name: &str, types: &[&str]) -> Result<Option<(&Parameter, &[f64])>> {
        let Some(parameter) = self.get(name) else {
            return Ok(None);
        };
        if !types.iter().any(|ty| parameter.is(ty)) {
            return Err(self.wrong_type(parameter, types[0]));
        }
        match &parameter.values {
            Values::Numbers(values) => Ok(Some((parameter, values))),
            _ => Err(self.wrong_type(parameter, types[0])),
        }
    }

    /// Exactly `count` numbers of one of `types`.
    fn fixed(&self, name: &str, types: &[&str], count: usize) -> Result<Option<&[f64]>> {
        let Some((parameter, values)) = self.numbers(name, types)? else {
            return Ok(None);
        };
        if values.len() != count {
            return Err(self.error(
                parameter,
                format!("has {} values, but {count} are expected", values.len()),
            ));
        }
        Ok(Some(values))
    }

    /// A `float`, or `default` when absent.
    pub fn float(&self, name: &str, default: f64) -> Result<f64> {
        Ok(self.float_opt(name)?.unwrap_or(default))
    }

    /// A `float`, if given.
    pub fn float_opt(&self, name: &str) -> Result<Option<f64>> {
        Ok(self.fixed(name, &["float"], 1)?.map(|v| v[0]))
    }

    /// An `integer`, or `default` when absent.
    pub fn integer(&self, name: &str, default: i64) -> Result<i64> {
        let Some((parameter, values)) = self.numbers(name, &["integer"])? else {
            return Ok(default);
        };
        match values {
            [v] if v.fract() == 0.0 && v.abs() < 9.0e15 => Ok(*v as i64),
            [_] => Err(self.error(parameter, "is not a whole number")),
            _ => Err(self.error(
                parameter,
                format!("has {} values, but 1 is expected", values.len()),
            )),
        }
    }

    /// A `bool`, or `default` when absent.
    pub fn boolean(&self, name: &str, default: bool) -> Result<bool> {
        let Some(parameter) = self.get(name) else {
            return Ok(default);
        };
        match (&parameter.values, parameter.is("bool")) {
            (Values::Bools(values), true) if values.len() == 1 => Ok(values[0]),
            (Values::Bools(values), true) => Err(self.error(
                parameter,
                format!("has {} values, but 1 is expected", values.len()),
            )),
            _ => Err(self.wrong_type(parameter, "bool")),
        }
    }

    /// A `string`, if given.
    pub fn string_opt(&self, name: &str) -> Result<Option<&str>> {
        Ok(self.strings(name, "string")?.map(|(_, v)| v[0].as_str()))
    }

    /// A `string`, or `default` when absent.
    pub fn string<'s>(&'s self, name: &str, default: &'s str) -> Result<&'s str> {
        Ok(self.string_opt(name)?.unwrap_or(default))
    }

    /// The strings of a `string` or `texture` parameter, at least one.
    pub fn strings(&self, name: &str, ty: &str) -> Result<Option<(&Parameter, &[String])>> {
        let Some(parameter) = self.get(name) else {
            return Ok(None);
        };
        match (&parameter.values, parameter.is(ty)) {
            (Values::Strings(values), true) if !values.is_empty() => {
                Ok(Some((parameter, values.as_slice())))
            }
            _ => Err(self.wrong_type(parameter, ty)),
        }
    }

    /// A `point3`, if given.
    pub fn point3_opt(&self, name: &str) -> Result<Option<DVec3>> {
        Ok(self
            .fixed(name, &["point3"], 3)?
            .map(|v| DVec3::new(v[0], v[1], v[2])))
    }

    /// A `vector3`, or `default` when absent.
    pub fn vector3(&self, name: &str, default: DVec3) -> Result<DVec3> {
        Ok(self
            .fixed(name, &["vector3"], 3)?
            .map_or(default, |v| DVec3::new(v[0], v[1], v[2])))
    }

    /// A `point3`, or `default` when absent.
    pub fn point3(&self, name: &str, default: DVec3) -> Result<DVec3> {
        Ok(self.point3_opt(name)?.unwrap_or(default))
    }

    /// The numbers of an array parameter of one of `types` whose length is a multiple of
    /// `group` (3 for points, 2 for texture coordinates), with the parameter for messages.
    pub fn array(
        &self,
        name: &str,
        types: &[&str],
        group: usize,
    ) -> Result<Option<(&Parameter, &[f64])>> {
        let Some((parameter, values)) = self.numbers(name, types)? else {
            return Ok(None);
        };
        if values.is_empty() || values.len() % group != 0 {
            return Err(self.error(
                parameter,
                format!(
                    "has {} values, which is not a positive multiple of {group}",
                    values.len()
                ),
            ));
        }
        Ok(Some((parameter, values)))
    }

    /// A spectrum (`rgb`, `spectrum`, `blackbody`) or, where `textured`, a `texture` reference;
    /// `None` when absent.
    pub fn spectrum(
        &self,
        name: &str,
        textured: bool,
    ) -> Result<Option<(SpectrumParam, &Parameter)>> {
        let Some(parameter) = self.get(name) else {
            return Ok(None);
        };
        let expected = if textured {
            "rgb, spectrum, blackbody or texture"
        } else {
            "rgb, spectrum or blackbody"
        };
        let value = match (canonical(&parameter.ty), &parameter.values) {
            ("rgb", Values::Numbers(v)) if v.len() == 3 => SpectrumParam::Rgb([v[0], v[1], v[2]]),
            ("rgb", _) => return Err(self.error(parameter, "needs 3 numbers")),
            ("blackbody", Values::Numbers(v)) if v.len() == 1 && v[0] > 0.0 => {
                SpectrumParam::Blackbody(v[0])
            }
            ("blackbody", _) => {
                return Err(self.error(parameter, "needs one temperature in kelvin, above 0"));
            }
            ("spectrum", Values::Strings(v)) if v.len() == 1 => SpectrumParam::Named(v[0].clone()),
            ("spectrum", Values::Numbers(v)) => {
                let pairs: Vec<(f64, f64)> = v.chunks_exact(2).map(|c| (c[0], c[1])).collect();
                let increasing = pairs.windows(2).all(|w| w[0].0 < w[1].0);
                if v.len() < 2 || v.len() % 2 != 0 || !increasing {
                    return Err(self.error(
                        parameter,
                        "needs (wavelength, value) pairs in increasing wavelength",
                    ));
                }
                SpectrumParam::Samples(pairs)
            }
            ("texture", Values::Strings(v)) if textured && v.len() == 1 => {
                SpectrumParam::Texture(v[0].clone())
            }
            _ => return Err(self.wrong_type(parameter, expected)),
        };
        Ok(Some((value, parameter)))
    }

    /// A `float` or, where `textured`, a `texture` reference.
    pub fn float_or_texture(&self, name: &str) -> Result<Option<(FloatParam, &Parameter)>> {
        let Some(parameter) = self.get(name) else {
            return Ok(None);
        };
        let value = match (canonical(&parameter.ty), &parameter.values) {
            ("float", Values::Numbers(v)) if v.len() == 1 => FloatParam::Value(v[0]),
            ("texture", Values::Strings(v)) if v.len() == 1 => FloatParam::Texture(v[0].clone()),
            _ => return Err(self.wrong_type(parameter, "float or texture")),
        };
        Ok(Some((value, parameter)))
    }

    /// Refuses every parameter nobody read.
    pub fn finish(&self) -> Result<()> {
        match self.parameters.iter().find(|p| !p.used.get()) {
            None => Ok(()),
            Some(parameter) => Err(self.error(parameter, "is not read by Prism").with_help(
                "Prism renders a pbrt-v4 parameter only where it has the same model; \
                     see docs/pbrt.md for what is read",
            )),
        }
    }
}

/// A float-valued parameter that may be a texture.
#[derive(Clone, Debug, PartialEq)]
pub enum FloatParam {
    Value(f64),
    Texture(String),
}

/// Reads a parameter's value after its `"type name"` string: one token or a bracketed list of
/// numbers, strings or booleans, all of one kind. `next` yields the following tokens.
pub fn parse_parameter(
    declaration: &Token,
    mut next: impl FnMut() -> Result<Option<Token>>,
) -> Result<Parameter> {
    let words: Vec<&str> = declaration.text.split_whitespace().collect();
    let [ty, name] = words[..] else {
        return Err(Error::input(
            &declaration.location,
            format!(
                "\"{}\" is not a parameter declaration",
                quote(&declaration.text)
            ),
        )
        .with_help("declare a parameter as \"type name\", e.g. \"float radius\" 2"));
    };
    if !TYPES.contains(&ty) {
        return Err(Error::input(
            &declaration.location,
            format!("unknown parameter type \"{}\"", quote(ty)),
        )
        .with_help(format!("the types are {}", TYPES.join(", "))));
    }
    let missing = || {
        Error::input(
            &declaration.location,
            format!("parameter \"{}\" has no value", quote(&declaration.text)),
        )
    };
    let first = next()?.ok_or_else(missing)?;
    let mut tokens = Vec::new();
    match first.kind {
        TokenKind::Open => loop {
            let token = next()?.ok_or_else(|| {
                Error::input(&first.location, "this \"[\" is never closed")
                    .with_help("close the list with \"]\"")
            })?;
            match token.kind {
                TokenKind::Close => break,
                TokenKind::Open => {
                    return Err(Error::input(&token.location, "a list may not nest \"[\""));
                }
                _ => tokens.push(token),
            }
        },
        TokenKind::Close => return Err(missing()),
        _ => tokens.push(first),
    }
    let values = values_of(ty, &tokens, declaration)?;
    Ok(Parameter {
        ty: ty.to_string(),
        name: name.to_string(),
        values,
        location: declaration.location.clone(),
        used: Cell::new(false),
    })
}

fn values_of(ty: &str, tokens: &[Token], declaration: &Token) -> Result<Values> {
    let bad = |token: &Token, what: &str| {
        Error::input(
            &token.location,
            format!(
                "parameter \"{}\" expects {what}, but \"{}\" is not",
                quote(&declaration.text),
                quote(&token.text)
            ),
        )
        .with_help(format!("give \"{ty}\" parameters {what}"))
    };
    match ty {
        "bool" => tokens
            .iter()
            .map(|token| match token.text.as_str() {
                "true" => Ok(true),
                "false" => Ok(false),
                _ => Err(bad(token, "true or false")),
            })
            .collect::<Result<_>>()
            .map(Values::Bools),
        "string" | "texture" => tokens
            .iter()
            .map(|token| match token.kind {
                TokenKind::Quoted => Ok(token.text.clone()),
                _ => Err(bad(token, "quoted strings")),
            })
            .collect::<Result<_>>()
            .map(Values::Strings),
        "spectrum" if tokens.first().is_some_and(|t| t.kind == TokenKind::Quoted) => match tokens {
            [token] => Ok(Values::Strings(vec![token.text.clone()])),
            _ => Err(bad(&tokens[1], "one name or file, or numbers")),
        },
        _ => tokens
            .iter()
            .map(|token| {
                let number = match token.kind {
                    TokenKind::Word => token.text.parse::<f64>().ok(),
                    _ => None,
                };
                number
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(token, "finite numbers"))
            })
            .collect::<Result<_>>()
            .map(Values::Numbers),
    }
}
