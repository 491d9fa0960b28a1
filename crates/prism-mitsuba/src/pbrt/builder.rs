//! The directives of a pbrt-v4 scene, read in order into pbrt's graphics state (the current
//! transformation matrix, material, area light, media and orientation, saved and restored by
//! `AttributeBegin`/`AttributeEnd`) and from it into plugin nodes: pbrt-v4's `BasicSceneBuilder`
//! (`src/pbrt/scene.cpp`) with Prism's plugins in place of pbrt's objects.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DMat4, DVec3};

use super::parameters::{ParameterList, parse_parameter};
use super::tokenizer::{Token, TokenKind, Tokenizer};
use super::{PbrtScene, nest, plugin, set, transforms};
use crate::description::{
    NestedPlugin, PluginClass, PluginNode, PropertyValue, Warning, find_file,
};
use crate::element::quote;
use crate::suggest::closest_match;
use prism_core::error::{Error, Result, SourceLocation};

/// How deep `Include` and `Import` may nest (a file that includes itself stops here).
const MAX_INCLUDE_DEPTH: usize = 32;

/// pbrt-v4's directives.
const DIRECTIVES: &[&str] = &[
    "Accelerator",
    "ActiveTransform",
    "AreaLightSource",
    "Attribute",
    "AttributeBegin",
    "AttributeEnd",
    "Camera",
    "ColorSpace",
    "ConcatTransform",
    "CoordinateSystem",
    "CoordSysTransform",
    "Film",
    "Identity",
    "Import",
    "Include",
    "Integrator",
    "LightSource",
    "LookAt",
    "MakeNamedMaterial",
    "MakeNamedMedium",
    "Material",
    "MediumInterface",
    "NamedMaterial",
    "ObjectBegin",
    "ObjectEnd",
    "ObjectInstance",
    "Option",
    "PixelFilter",
    "ReverseOrientation",
    "Rotate",
    "Sampler",
    "Scale",
    "Shape",
    "Texture",
    "Transform",
    "TransformBegin",
    "TransformEnd",
    "TransformTimes",
    "Translate",
    "WorldBegin",
];

/// The attributes `AttributeBegin` saves.
#[derive(Clone)]
pub(super) struct GraphicsState {
    /// Object to world.
    pub ctm: DMat4,
    pub reverse_orientation: bool,
    /// The current material; `None` is pbrt's default, diffuse 0.5.
    pub material: Option<Arc<PluginNode>>,
    /// The radiance of the current `AreaLightSource`, and where it is declared.
    pub area_light: Option<(PropertyValue, SourceLocation)>,
    /// The media of `MediumInterface` ("" is none).
    pub inside: String,
    pub outside: String,
}

/// A saved graphics state: by `AttributeBegin` (all of it) or `TransformBegin` (the CTM).
struct Saved {
    state: GraphicsState,
    location: SourceLocation,
    attributes: bool,
}

/// The `Camera` directive, kept until the film is known.
pub(super) struct CameraDirective {
    pub ty: String,
    pub parameters: ParameterList,
    pub camera_from_world: DMat4,
    /// The medium the camera sits in (the outside medium when it is declared).
    pub medium: String,
}

/// An `ObjectBegin` being read.
struct ObjectDefinition {
    name: String,
    location: SourceLocation,
    shapes: Vec<NestedPlugin>,
}

/// The scene read so far.
pub(super) struct Builder {
    /// The main scene file.
    main_file: PathBuf,
    pub search_paths: Arc<Vec<PathBuf>>,
    pub warnings: Vec<Warning>,
    pub camera: Option<CameraDirective>,
    pub film: Option<(String, ParameterList)>,
    pub sampler: Option<(String, ParameterList)>,
    pub filter: Option<(String, ParameterList)>,
    pub integrator: Option<(String, ParameterList)>,
    /// `Option "seed"`.
    pub seed: Option<i64>,
    world: bool,
    state: GraphicsState,
    saved: Vec<Saved>,
    coordinate_systems: HashMap<String, DMat4>,
    pub float_textures: HashMap<String, Arc<PluginNode>>,
    pub spectrum_textures: HashMap<String, Arc<PluginNode>>,
    pub named_materials: HashMap<String, Arc<PluginNode>>,
    pub media: HashMap<String, Arc<PluginNode>>,
    default_material: Option<Arc<PluginNode>>,
    shapes: Vec<NestedPlugin>,
    emitters: Vec<NestedPlugin>,
    /// Each object's `shapegroup`; `None` for an object without shapes.
    objects: HashMap<String, Option<Arc<PluginNode>>>,
    object: Option<ObjectDefinition>,
}

/// The tokens of one file, with one token of lookahead.
struct Stream<'a> {
    tokenizer: Tokenizer<'a>,
    peeked: Option<Token>,
}

impl Stream<'_> {
    fn next(&mut self) -> Result<Option<Token>> {
        match self.peeked.take() {
            Some(token) => Ok(Some(token)),
            None => self.tokenizer.next_token(),
        }
    }

    fn peek_kind(&mut self) -> Result<Option<TokenKind>> {
        if self.peeked.is_none() {
            self.peeked = self.tokenizer.next_token()?;
        }
        Ok(self.peeked.as_ref().map(|t| t.kind))
    }

    /// The next token, which `directive` needs.
    fn required(&mut self, directive: &Token, what: &str) -> Result<Token> {
        self.next()?.ok_or_else(|| {
            Error::input(
                &directive.location,
                format!("{} needs {what}, but the file ends", directive.text),
            )
        })
    }

    /// A quoted string argument of `directive`.
    fn string(&mut self, directive: &Token) -> Result<Token> {
        let token = self.required(directive, "a quoted string")?;
        if token.kind != TokenKind::Quoted {
            return Err(Error::input(
                &token.location,
                format!(
                    "{} needs a quoted string here, not \"{}\"",
                    directive.text,
                    quote(&token.text)
                ),
            ));
        }
        Ok(token)
    }

    /// `count` numbers, optionally in brackets.
    fn numbers(&mut self, directive: &Token, count: usize) -> Result<Vec<f64>> {
        let bracketed = self.peek_kind()? == Some(TokenKind::Open);
        if bracketed {
            self.next()?;
        }
        let mut values = Vec::with_capacity(count);
        for _ in 0..count {
            let token = self.required(directive, &format!("{count} numbers"))?;
            let value = match token.kind {
                TokenKind::Word => token.text.parse::<f64>().ok().filter(|v| v.is_finite()),
                _ => None,
            };
            values.push(value.ok_or_else(|| {
                Error::input(
                    &token.location,
                    format!(
                        "{} needs {count} numbers, but \"{}\" is not a finite number",
                        directive.text,
                        quote(&token.text)
                    ),
                )
            })?);
        }
        if bracketed {
            let token = self.required(directive, "\"]\"")?;
            if token.kind != TokenKind::Close {
                return Err(Error::input(
                    &token.location,
                    format!("{} takes {count} numbers; \"]\" expected", directive.text),
                ));
            }
        }
        Ok(values)
    }

    /// The parameter list that follows a directive's arguments.
    fn parameters(
        &mut self,
        directive: String,
        location: &SourceLocation,
    ) -> Result<ParameterList> {
        let mut parameters = Vec::new();
        while self.peek_kind()? == Some(TokenKind::Quoted) {
            let declaration = self.next()?.expect("peeked");
            parameters.push(parse_parameter(&declaration, || self.next())?);
        }
        Ok(ParameterList::new(directive, location.clone(), parameters))
    }
}

impl Builder {
    pub fn new(main_file: &Path, search_paths: Arc<Vec<PathBuf>>) -> Self {
        Builder {
            main_file: main_file.to_path_buf(),
            search_paths,
            warnings: Vec::new(),
            camera: None,
            film: None,
            sampler: None,
            filter: None,
            integrator: None,
            seed: None,
            world: false,
            state: GraphicsState {
                ctm: DMat4::IDENTITY,
                reverse_orientation: false,
                material: None,
                area_light: None,
                inside: String::new(),
                outside: String::new(),
            },
            saved: Vec::new(),
            coordinate_systems: HashMap::new(),
            float_textures: HashMap::new(),
            spectrum_textures: HashMap::new(),
            named_materials: HashMap::new(),
            media: HashMap::new(),
            default_material: None,
            shapes: Vec::new(),
            emitters: Vec::new(),
            objects: HashMap::new(),
            object: None,
        }
    }

    pub fn warn(&mut self, location: &SourceLocation, message: impl Into<String>) {
        self.warnings.push(Warning {
            location: location.clone(),
            message: message.into(),
        });
    }

    /// Reads the directives of one file (`depth` counts the `Include`s around it).
    pub fn read_text(&mut self, text: &str, path: &Path, depth: usize) -> Result<()> {
        let mut stream = Stream {
            tokenizer: Tokenizer::new(text, path),
            peeked: None,
        };
        while let Some(token) = stream.next()? {
            if token.kind != TokenKind::Word {
                return Err(Error::input(
                    &token.location,
                    format!("expected a directive, found \"{}\"", quote(&token.text)),
                )
                .with_help("a parameter list follows its directive; check for a missing quote"));
            }
            self.directive(&token, &mut stream, depth)?;
        }
        Ok(())
    }

    fn options_only(&self, directive: &Token) -> Result<()> {
        if self.world {
            return Err(Error::input(
                &directive.location,
                format!("{} must come before WorldBegin", directive.text),
            ));
        }
        Ok(())
    }

    fn world_only(&self, directive: &Token) -> Result<()> {
        if !self.world {
            return Err(Error::input(
                &directive.location,
                format!("{} must come after WorldBegin", directive.text),
            ));
        }
        Ok(())
    }

    fn apply(&mut self, directive: &Token, matrix: Option<DMat4>, problem: &str) -> Result<()> {
        let matrix = matrix.ok_or_else(|| {
            Error::input(
                &directive.location,
                format!("{}: {problem}", directive.text),
            )
        })?;
        self.state.ctm *= matrix;
        Ok(())
    }

    fn directive(&mut self, token: &Token, stream: &mut Stream, depth: usize) -> Result<()> {
        let location = &token.location;
        match token.text.as_str() {
            "Include" | "Import" => {
                let name = stream.string(token)?;
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(Error::input(
                        &name.location,
                        format!("files are included more than {MAX_INCLUDE_DEPTH} deep"),
                    )
                    .with_help("check for a file that includes itself"));
                }
                let path = find_file(&name.text, &self.search_paths, &name.location)?;
                if path.extension().is_some_and(|e| e == "gz") {
                    return Err(Error::input(
                        &name.location,
                        "Prism does not read gzip-compressed pbrt files",
                    )
                    .with_help("decompress the file with gunzip"));
                }
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    Error::io(&path, &e, "read the included file").at(&name.location)
                })?;
                self.read_text(&text, &path, depth + 1)
            }
            "Identity" => {
                self.state.ctm = DMat4::IDENTITY;
                Ok(())
            }
            "Translate" => {
                let v = stream.numbers(token, 3)?;
                let m = transforms::translate(DVec3::new(v[0], v[1], v[2]));
                self.apply(token, Some(m), "")
            }
            "Scale" => {
                let v = stream.numbers(token, 3)?;
                let m = transforms::scale(DVec3::new(v[0], v[1], v[2]));
                self.apply(token, Some(m), "")
            }
            "Rotate" => {
                let v = stream.numbers(token, 4)?;
                let m = transforms::rotate(v[0], DVec3::new(v[1], v[2], v[3]));
                self.apply(token, m, "the axis has no length")
            }
            "LookAt" => {
                let v = stream.numbers(token, 9)?;
                let m = transforms::look_at(
                    DVec3::new(v[0], v[1], v[2]),
                    DVec3::new(v[3], v[4], v[5]),
                    DVec3::new(v[6], v[7], v[8]),
                );
                self.apply(
                    token,
                    m,
                    "the eye and the target are the same point, or \"up\" is parallel to the \
                     viewing direction",
                )
            }
            "Transform" | "ConcatTransform" => {
                let v = stream.numbers(token, 16)?;
                let m = transforms::from_columns(&v.try_into().expect("16 numbers"));
                if token.text == "Transform" {
                    self.state.ctm = m;
                } else {
                    self.state.ctm *= m;
                }
                Ok(())
            }
            "CoordinateSystem" => {
                let name = stream.string(token)?;
                self.coordinate_systems.insert(name.text, self.state.ctm);
                Ok(())
            }
            "CoordSysTransform" => {
                let name = stream.string(token)?;
                let Some(&m) = self.coordinate_systems.get(&name.text) else {
                    let names: Vec<&str> =
                        self.coordinate_systems.keys().map(String::as_str).collect();
                    return Err(Error::input(
                        &name.location,
                        format!("unknown coordinate system \"{}\"", quote(&name.text)),
                    )
                    .with_help(format!(
                        "declare it with CoordinateSystem first; known: {}",
                        if names.is_empty() {
                            "none".to_string()
                        } else {
                            names.join(", ")
                        }
                    )));
                };
                self.state.ctm = m;
                Ok(())
            }
            "ReverseOrientation" => {
                self.state.reverse_orientation = !self.state.reverse_orientation;
                Ok(())
            }
            "AttributeBegin" | "TransformBegin" => {
                self.saved.push(Saved {
                    state: self.state.clone(),
                    location: location.clone(),
                    attributes: token.text == "AttributeBegin",
                });
                Ok(())
            }
            "AttributeEnd" | "TransformEnd" => self.pop(token),
            "ActiveTransform" => {
                let which = stream.required(token, "All, StartTime or EndTime")?;
                if which.text != "All" {
                    return Err(Error::input(
                        &which.location,
                        format!(
                            "ActiveTransform {}: Prism does not read pbrt's moving transforms",
                            quote(&which.text)
                        ),
                    )
                    .with_help(
                        "remove the motion, or write the scene in Mitsuba XML with an <animation>",
                    ));
                }
                Ok(())
            }
            "TransformTimes" => stream.numbers(token, 2).map(|_| ()),
            "Option" => {
                let list = stream.parameters("Option".into(), location)?;
                if list.get("seed").is_some() {
                    self.seed = Some(list.integer("seed", 0)?);
                }
                // The space rendering is done in does not change the image.
                list.ignore(&["rendercoordsys"]);
                list.finish()
            }
            "ColorSpace" => {
                let name = stream.string(token)?;
                if name.text != "srgb" {
                    return Err(Error::input(
                        &name.location,
                        format!(
                            "ColorSpace \"{}\": Prism reads sRGB colours only",
                            quote(&name.text)
                        ),
                    ));
                }
                Ok(())
            }
            "Camera" | "Film" | "Sampler" | "PixelFilter" | "Integrator" | "Accelerator" => {
                self.options_only(token)?;
                let ty = stream.string(token)?;
                let list =
                    stream.parameters(format!("{} \"{}\"", token.text, ty.text), location)?;
                match token.text.as_str() {
                    "Camera" => {
                        let camera_from_world = self.state.ctm;
                        if transforms::is_invertible(camera_from_world) {
                            self.coordinate_systems
                                .insert("camera".into(), camera_from_world.inverse());
                        }
                        self.camera = Some(CameraDirective {
                            ty: ty.text,
                            parameters: list,
                            camera_from_world,
                            medium: self.state.outside.clone(),
                        });
                    }
                    "Film" => self.film = Some((ty.text, list)),
                    "Sampler" => self.sampler = Some((ty.text, list)),
                    "PixelFilter" => self.filter = Some((ty.text, list)),
                    "Integrator" => self.integrator = Some((ty.text, list)),
                    // The acceleration structure does not change the image.
                    _ => {}
                }
                Ok(())
            }
            "WorldBegin" => {
                self.options_only(token)?;
                self.world = true;
                self.state.ctm = DMat4::IDENTITY;
                self.coordinate_systems
                    .insert("world".into(), DMat4::IDENTITY);
                Ok(())
            }
            "Attribute" => Err(Error::input(
                location,
                "Attribute: Prism does not read default parameters set by Attribute",
            )
            .with_help("give the parameters on each directive instead")),
            "Shape" => {
                self.world_only(token)?;
                let ty = stream.string(token)?;
                let list = stream.parameters(format!("Shape \"{}\"", ty.text), location)?;
                self.add_shape(&ty.text, &list)
            }
            "Material" => {
                self.world_only(token)?;
                let ty = stream.string(token)?;
                let list = stream.parameters(format!("Material \"{}\"", ty.text), location)?;
                let material = self.material(&ty.text, &list)?;
                self.state.material = Some(material);
                Ok(())
            }
            "MakeNamedMaterial" => {
                self.world_only(token)?;
                let name = stream.string(token)?;
                let list =
                    stream.parameters(format!("MakeNamedMaterial \"{}\"", name.text), location)?;
                let ty = match list.strings("type", "string")? {
                    Some((_, types)) => types[0].clone(),
                    None => return Err(list.directive_error("needs a \"string type\" parameter")),
                };
                if self.named_materials.contains_key(&name.text) {
                    return Err(Error::input(
                        &name.location,
                        format!("the material \"{}\" is defined twice", quote(&name.text)),
                    ));
                }
                let material = self.material(&ty, &list)?;
                self.named_materials.insert(name.text, material);
                Ok(())
            }
            "NamedMaterial" => {
                self.world_only(token)?;
                let name = stream.string(token)?;
                let material = self.named_material(&name.text, &name.location)?;
                self.state.material = Some(material);
                Ok(())
            }
            "Texture" => {
                self.world_only(token)?;
                let name = stream.string(token)?;
                let kind = stream.string(token)?;
                let class = stream.string(token)?;
                let list = stream.parameters(
                    format!(
                        "Texture \"{}\" \"{}\" \"{}\"",
                        name.text, kind.text, class.text
                    ),
                    location,
                )?;
                self.add_texture(&name, &kind, &class.text, &list, self.state.ctm)
            }
            "LightSource" => {
                self.world_only(token)?;
                let ty = stream.string(token)?;
                let list = stream.parameters(format!("LightSource \"{}\"", ty.text), location)?;
                if self.object.is_some() {
                    return Err(
                        list.directive_error("lights cannot be part of an object (ObjectBegin)")
                    );
                }
                let light = self.light(&ty.text, &list, self.state.ctm)?;
                self.emitters.push(NestedPlugin {
                    name: None,
                    node: Arc::new(light),
                    location: location.clone(),
                });
                Ok(())
            }
            "AreaLightSource" => {
                self.world_only(token)?;
                let ty = stream.string(token)?;
                let list =
                    stream.parameters(format!("AreaLightSource \"{}\"", ty.text), location)?;
                let radiance = self.area_light(&ty.text, &list)?;
                self.state.area_light = Some((radiance, location.clone()));
                Ok(())
            }
            "MakeNamedMedium" => {
                let name = stream.string(token)?;
                let list =
                    stream.parameters(format!("MakeNamedMedium \"{}\"", name.text), location)?;
                let medium = self.medium(&list, self.state.ctm)?;
                self.media.insert(name.text, Arc::new(medium));
                Ok(())
            }
            "MediumInterface" => {
                let inside = stream.string(token)?;
                let outside = if stream.peek_kind()? == Some(TokenKind::Quoted) {
                    stream.string(token)?.text
                } else {
                    inside.text.clone()
                };
                self.state.inside = inside.text;
                self.state.outside = outside;
                Ok(())
            }
            "ObjectBegin" => {
                self.world_only(token)?;
                let name = stream.string(token)?;
                if let Some(object) = &self.object {
                    return Err(Error::input(
                        location,
                        format!("ObjectBegin inside the object \"{}\"", object.name),
                    )
                    .with_help(format!(
                        "close it with ObjectEnd first (it begins at {})",
                        object.location
                    )));
                }
                if self.objects.contains_key(&name.text) {
                    return Err(Error::input(
                        &name.location,
                        format!("the object \"{}\" is defined twice", quote(&name.text)),
                    ));
                }
                self.saved.push(Saved {
                    state: self.state.clone(),
                    location: location.clone(),
                    attributes: true,
                });
                self.object = Some(ObjectDefinition {
                    name: name.text,
                    location: location.clone(),
                    shapes: Vec::new(),
                });
                Ok(())
            }
            "ObjectEnd" => {
                let Some(object) = self.object.take() else {
                    return Err(Error::input(location, "ObjectEnd without ObjectBegin"));
                };
                self.pop(token)?;
                let group = (!object.shapes.is_empty()).then(|| {
                    let mut group = plugin(
                        PluginClass::Shape,
                        "shapegroup",
                        &object.location,
                        &self.search_paths,
                    );
                    group.id = Some(object.name.clone());
                    group.children = object.shapes;
                    let group = Arc::new(group);
                    self.shapes.push(NestedPlugin {
                        name: None,
                        node: group.clone(),
                        location: object.location.clone(),
                    });
                    group
                });
                self.objects.insert(object.name, group);
                Ok(())
            }
            "ObjectInstance" => {
                self.world_only(token)?;
                let name = stream.string(token)?;
                if self.object.is_some() {
                    return Err(Error::input(
                        location,
                        "ObjectInstance inside an object: Prism does not nest instances",
                    ));
                }
                let Some(group) = self.objects.get(&name.text) else {
                    return Err(Error::input(
                        &name.location,
                        format!("unknown object \"{}\"", quote(&name.text)),
                    )
                    .with_help("define it with ObjectBegin ... ObjectEnd before its instances"));
                };
                if let Some(group) = group {
                    let mut instance =
                        plugin(PluginClass::Shape, "instance", location, &self.search_paths);
                    set(
                        &mut instance,
                        "to_world",
                        PropertyValue::Transform(self.state.ctm),
                        location,
                    );
                    nest(&mut instance, None, group.clone(), location);
                    self.shapes.push(NestedPlugin {
                        name: None,
                        node: Arc::new(instance),
                        location: location.clone(),
                    });
                }
                Ok(())
            }
            "WorldEnd" => {
                self.warn(
                    location,
                    "WorldEnd is pbrt-v3's; pbrt-v4 has none, and Prism ignores it",
                );
                Ok(())
            }
            other => {
                let mut help = format!("pbrt-v4's directives are {}", DIRECTIVES.join(", "));
                if let Some(close) = closest_match(other, DIRECTIVES) {
                    help = format!("did you mean \"{close}\"? {help}");
                }
                Err(
                    Error::input(location, format!("unknown directive \"{}\"", quote(other)))
                        .with_help(help),
                )
            }
        }
    }

    /// `AttributeEnd` or `TransformEnd` (`ObjectEnd` too, which ends its `ObjectBegin`'s
    /// attributes).
    fn pop(&mut self, token: &Token) -> Result<()> {
        let attributes = token.text != "TransformEnd";
        let Some(saved) = self.saved.pop() else {
            return Err(Error::input(
                &token.location,
                format!("{} without a matching begin", token.text),
            ));
        };
        if saved.attributes != attributes {
            return Err(Error::input(
                &token.location,
                format!(
                    "{} does not match the begin at {}",
                    token.text, saved.location
                ),
            ));
        }
        if attributes {
            self.state = saved.state;
        } else {
            self.state.ctm = saved.state.ctm;
        }
        Ok(())
    }

    /// The material named `name`.
    pub fn named_material(&self, name: &str, location: &SourceLocation) -> Result<Arc<PluginNode>> {
        self.named_materials.get(name).cloned().ok_or_else(|| {
            let names: Vec<&str> = self.named_materials.keys().map(String::as_str).collect();
            let mut error = Error::input(location, format!("unknown material \"{}\"", quote(name)));
            if let Some(close) = closest_match(name, &names) {
                error = error.with_help(format!("did you mean \"{close}\"?"));
            } else {
                error = error.with_help("define it with MakeNamedMaterial first");
            }
            error
        })
    }

    /// The medium named `name`, for a shape or the camera.
    pub fn named_medium(&self, name: &str, location: &SourceLocation) -> Result<Arc<PluginNode>> {
        self.media.get(name).cloned().ok_or_else(|| {
            Error::input(location, format!("unknown medium \"{}\"", quote(name)))
                .with_help("define it with MakeNamedMedium before it is used")
        })
    }

    /// A shape with the current material, area light and media.
    fn add_shape(&mut self, ty: &str, list: &ParameterList) -> Result<()> {
        let state = self.state.clone();
        let mut shape = self.shape(ty, list, &state)?;
        list.finish()?;
        let location = &list.location;
        let material = match &state.material {
            Some(material) => material.clone(),
            None => self.default_material(location)?,
        };
        nest(&mut shape, None, material, location);
        if let Some((radiance, light_location)) = &state.area_light {
            if self.object.is_some() {
                return Err(list.directive_error(
                    "an area light cannot be part of an object (ObjectBegin), as in pbrt-v4",
                ));
            }
            let mut emitter = plugin(
                PluginClass::Emitter,
                "area",
                light_location,
                &self.search_paths,
            );
            set(&mut emitter, "radiance", radiance.clone(), light_location);
            nest(&mut shape, None, Arc::new(emitter), light_location);
        }
        if state.inside != state.outside {
            for (name, medium) in [("interior", &state.inside), ("exterior", &state.outside)] {
                if !medium.is_empty() {
                    let node = self.named_medium(medium, location)?;
                    nest(&mut shape, Some(name), node, location);
                }
            }
        }
        let shape = NestedPlugin {
            name: None,
            node: Arc::new(shape),
            location: location.clone(),
        };
        match &mut self.object {
            Some(object) => object.shapes.push(shape),
            None => self.shapes.push(shape),
        }
        Ok(())
    }

    /// pbrt's default material, diffuse 0.5, built once.
    fn default_material(&mut self, location: &SourceLocation) -> Result<Arc<PluginNode>> {
        if let Some(material) = &self.default_material {
            return Ok(material.clone());
        }
        let list = ParameterList::new("the default material".into(), location.clone(), Vec::new());
        let material = self.material("diffuse", &list)?;
        self.default_material = Some(material.clone());
        Ok(material)
    }

    /// The scene: its integrator, camera, shapes and lights.
    pub fn finish(mut self) -> Result<PbrtScene> {
        if let Some(saved) = self.saved.last() {
            let what = if saved.attributes {
                "AttributeBegin"
            } else {
                "TransformBegin"
            };
            return Err(Error::input(
                &saved.location,
                format!("this {what} is never ended"),
            ));
        }
        let location = SourceLocation::new(self.main_file.clone(), 1, 1);
        let integrator = self.integrator_node(&location)?;
        let sensor = self.sensor_node(&location)?;
        let mut root = plugin(PluginClass::Scene, "scene", &location, &self.search_paths);
        nest(&mut root, None, Arc::new(integrator), &location);
        nest(&mut root, None, Arc::new(sensor), &location);
        root.children.append(&mut self.shapes);
        root.children.append(&mut self.emitters);
        Ok(PbrtScene {
            root: Arc::new(root),
            warnings: self.warnings,
        })
    }
}
