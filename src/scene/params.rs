//! Entity parameters as data: what an entity kind declares it reads
//! ([`ParamSpec`], in the kind's own file), and the values the loader found
//! for them ([`ParamValues`]), with pbrt-v3's defaults already applied.
//!
//! The loader reads a statement's parameters through the kind's
//! `ParamSpec` list (pbrt-v3's lookup rules: shape parameters may override
//! the material's, texture references before values); `--check`, "did you
//! mean", `grammar/REFERENCE.md` and the tests read the same lists.

use super::fourier::FourierTable;
use super::textures::{FloatTex, SpectrumTex};
use super::MaterialId;
use glam::Vec3;
use std::sync::Arc;

/// A spectrum default: RGB, or a sampled spectrum the loader converts to RGB
/// as pbrt-v3's `FromSampled` does (e.g. the metals' measured copper).
#[derive(Clone, Copy, Debug)]
pub enum SpectrumDefault {
    Rgb([f32; 3]),
    Sampled {
        lambda: &'static [f32],
        values: &'static [f32],
    },
}

/// What a parameter is and its default.
#[derive(Clone, Copy, Debug)]
pub enum ParamKind {
    /// A float texture (a `float` value or a `texture` name); `None`: no
    /// default, the entity decides when it is absent.
    FloatTexture(Option<f32>),
    /// A spectrum texture (`rgb`/`color`, `xyz`, `blackbody`, `spectrum`, or
    /// a `texture` name).
    SpectrumTexture(Option<SpectrumDefault>),
    Float(f32),
    /// A float without a default: absent unless given (the entity decides).
    FloatOpt,
    Bool(bool),
    /// A bool without a default: absent unless given (the entity decides).
    BoolOpt,
    String(&'static str),
    Int(i32),
    /// A `vector3` (or `vector`) value.
    Vector3([f32; 3]),
    /// A string that must be one of `options` (else a warning, and the
    /// default, which is what pbrt-v3 falls back to in every such case).
    Choice {
        default: &'static str,
        options: &'static [&'static str],
    },
    /// A file name as written (readers resolve it against the scene file's
    /// directory, as pbrt-v3's `FindFilename`); empty if not given.
    Filename,
    /// Textures only: a texture of the texture's own type (a float texture
    /// for a `float` texture, a spectrum texture for a `color` one) with
    /// this default (a grey for spectra), e.g. `checkerboard`'s `tex1`.
    SameTexture(f32),
    /// Textures only: a plain value of the texture's own type (pbrt-v3's
    /// `FindFloat` / `FindSpectrum`, no texture reference), e.g. `bilerp`'s
    /// `v00`.
    SameValue(f32),
    /// The name of a material made by `MakeNamedMaterial` (`mix`).
    NamedMaterial,
    /// A tabulated Fourier BSDF file (`.bsdf`, pbrt-v3's format).
    FourierFile,
    /// Known to pbrt-v3 but not evaluated by pbrs yet: the loader warns
    /// when it is given, naming the reason.
    Unsupported(&'static str),
    /// A plain spectrum value (no texture), e.g. a medium's `sigma_a`.
    Spectrum([f32; 3]),
    /// A `point3` (or `point`) value.
    Point3([f32; 3]),
    /// A list of floats of any length, e.g. a grid medium's `density`.
    Floats,
    /// A plain spectrum, or a `float` taken as a grey (a light's `scale`:
    /// a spectrum in pbrt-v3, a float too in pbrs).
    SpectrumOrFloat([f32; 3]),
    /// An integer without a default: absent unless given (the entity
    /// decides, e.g. `samples`, which defaults to `nsamples`).
    IntOpt,
    /// An image file, read (once per scene) and converted as the `Decode`
    /// says; absent when not given or empty (a file that cannot be read is
    /// an error).
    Image(super::Decode),
    /// Values of one element type, any count, as numbers (no default):
    /// a mesh's `P`, `indices`, `N`, `uv`.
    List(Elem),
}

/// The element type of a [`ParamKind::List`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Elem {
    /// `float` or `integer` values.
    Number,
    Int,
    /// `point2` values (or `float`, as pbrt-v3 takes uv).
    Point2,
    Point3,
    Normal,
}

impl Elem {
    /// Its name in messages and `grammar/REFERENCE.md`.
    pub const fn name(self) -> &'static str {
        match self {
            Elem::Number => "number",
            Elem::Int => "integer",
            Elem::Point2 => "point2",
            Elem::Point3 => "point3",
            Elem::Normal => "normal",
        }
    }
}

/// A constraint the loader checks on constant values (with a located
/// warning, clamping the value).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Range {
    Any,
    NonNegative,
}

/// One parameter an entity kind reads.
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    pub name: &'static str,
    pub kind: ParamKind,
    pub range: Range,
    /// What it means, for `grammar/REFERENCE.md`.
    pub doc: &'static str,
}

impl ParamSpec {
    pub const fn float_tex(name: &'static str, default: f32, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::FloatTexture(Some(default)),
            range: Range::Any,
            doc,
        }
    }
    /// A float texture that must not be negative (roughness, σ, …).
    pub const fn nonneg_tex(name: &'static str, default: f32, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::FloatTexture(Some(default)),
            range: Range::NonNegative,
            doc,
        }
    }
    pub const fn float_tex_opt(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::FloatTexture(None),
            range: Range::Any,
            doc,
        }
    }
    pub const fn nonneg_tex_opt(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::FloatTexture(None),
            range: Range::NonNegative,
            doc,
        }
    }
    pub const fn spectrum(name: &'static str, default: f32, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::SpectrumTexture(Some(SpectrumDefault::Rgb([default; 3]))),
            range: Range::Any,
            doc,
        }
    }
    pub const fn spectrum_with(
        name: &'static str,
        default: SpectrumDefault,
        doc: &'static str,
    ) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::SpectrumTexture(Some(default)),
            range: Range::Any,
            doc,
        }
    }
    pub const fn spectrum_opt(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::SpectrumTexture(None),
            range: Range::Any,
            doc,
        }
    }
    pub const fn boolean(name: &'static str, default: bool, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Bool(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn float(name: &'static str, default: f32, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Float(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn float_opt(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::FloatOpt,
            range: Range::Any,
            doc,
        }
    }
    pub const fn string(name: &'static str, default: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::String(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn named_material(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::NamedMaterial,
            range: Range::Any,
            doc,
        }
    }
    pub const fn fourier_file(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::FourierFile,
            range: Range::Any,
            doc,
        }
    }
    pub const fn unsupported(name: &'static str, why: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Unsupported(why),
            range: Range::Any,
            doc: why,
        }
    }
    pub const fn bool_opt(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::BoolOpt,
            range: Range::Any,
            doc,
        }
    }
    pub const fn int(name: &'static str, default: i32, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Int(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn vector3(name: &'static str, default: [f32; 3], doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Vector3(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn choice(
        name: &'static str,
        default: &'static str,
        options: &'static [&'static str],
        doc: &'static str,
    ) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Choice { default, options },
            range: Range::Any,
            doc,
        }
    }
    pub const fn filename(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Filename,
            range: Range::Any,
            doc,
        }
    }
    pub const fn same_tex(name: &'static str, default: f32, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::SameTexture(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn same_value(name: &'static str, default: f32, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::SameValue(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn spectrum_value(
        name: &'static str,
        default: [f32; 3],
        doc: &'static str,
    ) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Spectrum(default),
            range: Range::NonNegative,
            doc,
        }
    }
    pub const fn point3(name: &'static str, default: [f32; 3], doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Point3(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn floats(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Floats,
            range: Range::NonNegative,
            doc,
        }
    }
    /// A plain spectrum of any sign (a light's `L`).
    pub const fn spectrum_any(
        name: &'static str,
        default: [f32; 3],
        doc: &'static str,
    ) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Spectrum(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn spectrum_or_float(
        name: &'static str,
        default: [f32; 3],
        doc: &'static str,
    ) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::SpectrumOrFloat(default),
            range: Range::Any,
            doc,
        }
    }
    pub const fn int_opt(name: &'static str, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::IntOpt,
            range: Range::Any,
            doc,
        }
    }
    pub const fn image(name: &'static str, decode: super::Decode, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::Image(decode),
            range: Range::Any,
            doc,
        }
    }
    pub const fn list(name: &'static str, elem: Elem, doc: &'static str) -> ParamSpec {
        ParamSpec {
            name,
            kind: ParamKind::List(elem),
            range: Range::Any,
            doc,
        }
    }
    /// pbrt-v3's `bumpmap`: a float texture of displacements along the
    /// shading normal, applied by `Material::bsdf_into` for every material.
    pub const BUMPMAP: ParamSpec = ParamSpec::float_tex_opt(
        "bumpmap",
        "displacement along the shading normal (pbrt-v3's Bump)",
    );
}

/// A value the loader found (or the default it applied).
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    FloatTexture(FloatTex),
    SpectrumTexture(SpectrumTex),
    Float(f32),
    Bool(bool),
    String(String),
    Int(i32),
    Vector(Vec3),
    Material(MaterialId),
    Fourier(Arc<FourierTable>),
    /// A plain spectrum as linear RGB (`ParamKind::Spectrum`).
    Spectrum(Vec3),
    /// A `point3`, in f64 as the scene's transforms.
    Point(glam::DVec3),
    /// A list of numbers, as written (`ParamKind::Floats`).
    Floats(Arc<[f64]>),
    /// An image as read (`ParamKind::Image`).
    Image(Arc<super::RgbImage>),
}

/// The values of one entity's parameters, by name (absent: no value and no
/// default). Entities read them with the typed getters, which panic on a
/// name the entity's `ParamSpec` list does not declare (a bug caught by the
/// tests that build every kind with its defaults).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamValues {
    pub values: Vec<(&'static str, ParamValue)>,
    /// The parameters the statement gave (the others have their defaults).
    pub given: Vec<&'static str>,
}

impl ParamValues {
    pub fn get(&self, name: &str) -> Option<&ParamValue> {
        self.values.iter().find(|(n, _)| *n == name).map(|(_, v)| v)
    }
    pub fn set(&mut self, name: &'static str, v: ParamValue) {
        match self.values.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = v,
            None => self.values.push((name, v)),
        }
    }
    pub fn float_tex(&self, name: &str) -> Option<FloatTex> {
        match self.get(name) {
            Some(ParamValue::FloatTexture(t)) => Some(t.clone()),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not a float texture"),
        }
    }
    pub fn spectrum_tex(&self, name: &str) -> Option<SpectrumTex> {
        match self.get(name) {
            Some(ParamValue::SpectrumTexture(t)) => Some(t.clone()),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not a spectrum texture"),
        }
    }
    pub fn float(&self, name: &str) -> f32 {
        match self.get(name) {
            Some(ParamValue::Float(f)) => *f,
            v => panic!("parameter \"{name}\" is {v:?}, not a float"),
        }
    }
    /// A [`ParamKind::FloatOpt`]: `None` unless given.
    pub fn float_opt(&self, name: &str) -> Option<f32> {
        match self.get(name) {
            Some(ParamValue::Float(f)) => Some(*f),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not a float"),
        }
    }
    pub fn boolean(&self, name: &str) -> bool {
        match self.get(name) {
            Some(ParamValue::Bool(b)) => *b,
            v => panic!("parameter \"{name}\" is {v:?}, not a bool"),
        }
    }
    pub fn bool_opt(&self, name: &str) -> Option<bool> {
        match self.get(name) {
            Some(ParamValue::Bool(b)) => Some(*b),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not a bool"),
        }
    }
    pub fn string(&self, name: &str) -> &str {
        match self.get(name) {
            Some(ParamValue::String(s)) => s,
            v => panic!("parameter \"{name}\" is {v:?}, not a string"),
        }
    }
    pub fn int(&self, name: &str) -> i32 {
        match self.get(name) {
            Some(ParamValue::Int(i)) => *i,
            v => panic!("parameter \"{name}\" is {v:?}, not an integer"),
        }
    }
    pub fn int_opt(&self, name: &str) -> Option<i32> {
        match self.get(name) {
            Some(ParamValue::Int(i)) => Some(*i),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not an integer"),
        }
    }
    pub fn image(&self, name: &str) -> Option<Arc<super::RgbImage>> {
        match self.get(name) {
            Some(ParamValue::Image(i)) => Some(i.clone()),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not an image"),
        }
    }
    pub fn vector(&self, name: &str) -> Vec3 {
        match self.get(name) {
            Some(ParamValue::Vector(v)) => *v,
            v => panic!("parameter \"{name}\" is {v:?}, not a vector"),
        }
    }
    pub fn material(&self, name: &str) -> Option<MaterialId> {
        match self.get(name) {
            Some(ParamValue::Material(m)) => Some(*m),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not a material"),
        }
    }
    pub fn spectrum(&self, name: &str) -> Vec3 {
        match self.get(name) {
            Some(ParamValue::Spectrum(v)) => *v,
            v => panic!("parameter \"{name}\" is {v:?}, not a spectrum"),
        }
    }
    pub fn point(&self, name: &str) -> glam::DVec3 {
        match self.get(name) {
            Some(ParamValue::Point(p)) => *p,
            v => panic!("parameter \"{name}\" is {v:?}, not a point"),
        }
    }
    /// A number list; empty when not given.
    pub fn floats(&self, name: &str) -> Arc<[f64]> {
        match self.get(name) {
            Some(ParamValue::Floats(v)) => v.clone(),
            None => Arc::from([]),
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not a list of numbers"),
        }
    }
    /// True when the statement gave the parameter (not just its default):
    /// for kinds whose pbrt-v3 code treats "given" differently.
    pub fn has(&self, name: &str) -> bool {
        self.get(name).is_some()
    }
    /// True when the statement gave the parameter (it may still hold its
    /// default's value): pbrt-v3's defaults that depend on other
    /// parameters (a medium's `preset`) need to know.
    pub fn given(&self, name: &str) -> bool {
        self.given.contains(&name)
    }
    pub fn fourier(&self, name: &str) -> Option<Arc<FourierTable>> {
        match self.get(name) {
            Some(ParamValue::Fourier(t)) => Some(t.clone()),
            None => None,
            Some(v) => panic!("parameter \"{name}\" is {v:?}, not a Fourier table"),
        }
    }
}
