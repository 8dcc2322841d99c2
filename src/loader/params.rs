//! A statement's parameters read through its kind's `ParamSpec` table, with
//! pbrt-v3's lookup rules (`TextureParams`): the shape's parameters first
//! when it may override its material's, a texture reference before a value
//! in each list; defaults, ranges and choices applied, and the named
//! materials a `mix` refers to returned for the caller to resolve. Every
//! table-driven family is read here (materials, textures, and the kinds of
//! [`super::kinds`]).

use super::color::sampled_to_rgb;
use super::fourier::fourier_table;
use super::lookup::{find_spectrum, float_opt, one, spectrum_value};
use super::Ctx;
use crate::lang::params::{ParamList, ParamType};
use crate::lang::Loc;
use crate::scene::kind::closest_name;
use crate::scene::Tex;
use crate::scene::{
    Elem, FloatTex, ParamKind, ParamSpec, ParamValue, ParamValues, Range, SpectrumDefault,
    SpectrumTex,
};
use glam::Vec3;
use std::collections::HashMap;
use std::sync::Arc;

/// A named texture and where it was defined.
#[derive(Clone, Debug)]
pub struct TexEntry<T> {
    pub tex: Tex<T>,
    pub loc: Loc,
    pub class: &'static str,
}

/// The textures visible at a statement, by name (pbrt-v3 keeps float and
/// spectrum textures in separate name spaces).
#[derive(Clone, Debug, Default)]
pub struct Textures {
    pub float: HashMap<String, TexEntry<f32>>,
    pub spectrum: HashMap<String, TexEntry<Vec3>>,
}

/// Material parameter lookup: shape parameters first (if they override), then the material's.
pub struct Lookup<'a> {
    pub first: Option<&'a ParamList>,
    pub second: &'a ParamList,
    pub textures: &'a Textures,
}

impl Lookup<'_> {
    pub fn lists(&self) -> impl Iterator<Item = &ParamList> {
        self.first.into_iter().chain(std::iter::once(self.second))
    }

    fn texture_ref(&self, name: &str, l: &ParamList) -> Option<(String, Loc)> {
        one(l, name, |t| t == ParamType::Texture).map(|q| (q.strs()[0].clone(), q.values_loc))
    }

    /// pbrt-v3 `GetSpectrumTextureOrNull`, with the value's location.
    pub fn spectrum(&self, ctx: &mut Ctx, name: &str) -> Option<(SpectrumTex, Loc)> {
        for l in self.lists() {
            if let Some((tex, loc)) = self.texture_ref(name, l) {
                return match self.textures.spectrum.get(&tex) {
                    Some(e) => Some((e.tex.clone(), loc)),
                    None => {
                        let hint = missing_hint(
                            &tex,
                            "float",
                            &self.textures.float,
                            &self.textures.spectrum,
                        );
                        ctx.warn(loc, format!("unknown spectrum texture \"{tex}\" for \"{name}\"{hint}: the default is used (as pbrt-v3)"), "no such \"color\" texture");
                        None
                    }
                };
            }
            if let Some(q) = find_spectrum(l, name) {
                return spectrum_value(ctx, q).map(|v| (SpectrumTex::Constant(v), q.values_loc));
            }
        }
        None
    }

    /// pbrt-v3 `GetFloatTextureOrNull`, with the value's location.
    pub fn float(&self, ctx: &mut Ctx, name: &str) -> Option<(FloatTex, Loc)> {
        for l in self.lists() {
            if let Some((tex, loc)) = self.texture_ref(name, l) {
                return match self.textures.float.get(&tex) {
                    Some(e) => Some((e.tex.clone(), loc)),
                    None => {
                        let hint = missing_hint(
                            &tex,
                            "spectrum",
                            &self.textures.spectrum,
                            &self.textures.float,
                        );
                        ctx.warn(loc, format!("unknown float texture \"{tex}\" for \"{name}\"{hint}: the default is used (as pbrt-v3)"), "no such \"float\" texture");
                        None
                    }
                };
            }
            if let Some((v, loc)) = float_opt(l, name) {
                return Some((FloatTex::Constant(v as f32), loc));
            }
        }
        None
    }

    /// A plain parameter of one type, shape list first (pbrt-v3's
    /// `TextureParams::FindFloat`/`FindBool`/`FindString`).
    pub(super) fn plain(&self, name: &str, ty: ParamType) -> Option<&crate::lang::params::Param> {
        self.lists().find_map(|l| one(l, name, |t| t == ty))
    }

    /// Marks the material's own parameters (not the shape's) used.
    pub fn mark_all(&self) {
        self.second.mark_all_used();
    }
}

/// Why a texture name was not found: defined with the other type, or a
/// near miss among the names of the right type.
fn missing_hint<A, B>(
    tex: &str,
    other_type: &str,
    other: &HashMap<String, A>,
    same: &HashMap<String, B>,
) -> String {
    if other.contains_key(tex) {
        return format!(" (\"{tex}\" is a {other_type} texture)");
    }
    // (Suggestions for one- and two-letter names are mostly noise.)
    if tex.chars().count() < 3 {
        return String::new();
    }
    let names: Vec<&str> = same.keys().map(String::as_str).collect();
    match closest_name(tex, &names) {
        Some(c) => format!(" (did you mean \"{c}\"?)"),
        None => String::new(),
    }
}

/// A `mix` reference to a named material, resolved by the caller.
#[derive(Debug)]
pub struct NamedRef {
    pub param: &'static str,
    pub name: String,
    pub loc: Loc,
}

/// The default values of a kind's parameters (no statement).
pub fn defaults(ctx: &mut Ctx, specs: &'static [ParamSpec]) -> ParamValues {
    let empty = ParamList::default();
    let textures = Textures::default();
    let l = Lookup {
        first: None,
        second: &empty,
        textures: &textures,
    };
    read_params(ctx, specs, &l).0
}

fn spectrum_default(d: SpectrumDefault) -> Vec3 {
    match d {
        SpectrumDefault::Rgb(c) => Vec3::from_array(c),
        SpectrumDefault::Sampled { lambda, values } => {
            let pairs: Vec<f64> = lambda
                .iter()
                .zip(values)
                .flat_map(|(&l, &v)| [l as f64, v as f64])
                .collect();
            sampled_to_rgb(&pairs)
        }
    }
}

/// Reads every parameter of `specs` through the lookup, applying defaults
/// and range checks; named-material references are returned to resolve.
pub fn read_params(
    ctx: &mut Ctx,
    specs: &'static [ParamSpec],
    l: &Lookup,
) -> (ParamValues, Vec<NamedRef>) {
    read_params_as(ctx, specs, l, true)
}

/// [`read_params`] for a texture of type float (`same_is_float`) or
/// spectrum: the type of its `SameTexture` and `SameValue` parameters.
pub fn read_params_as(
    ctx: &mut Ctx,
    specs: &'static [ParamSpec],
    l: &Lookup,
    same_is_float: bool,
) -> (ParamValues, Vec<NamedRef>) {
    let mut out = ParamValues::default();
    let mut refs = Vec::new();
    for s in specs {
        let value = match s.kind {
            ParamKind::FloatTexture(_)
            | ParamKind::SameTexture(_)
            | ParamKind::SameValue(_)
            | ParamKind::SpectrumTexture(_)
            | ParamKind::Spectrum(_)
            | ParamKind::SpectrumOrFloat(_) => texture_or_spectrum(ctx, s, l, same_is_float),
            ParamKind::NamedMaterial => {
                let (name, loc) = match l.plain(s.name, ParamType::String) {
                    Some(q) => (q.strs()[0].clone(), q.values_loc),
                    None => (String::new(), Loc::default()),
                };
                refs.push(NamedRef {
                    param: s.name,
                    name,
                    loc,
                });
                None
            }
            ParamKind::Unsupported(why) => {
                for list in l.lists() {
                    if let Some(q) = list.get(s.name) {
                        q.used.set(true);
                        ctx.warn(q.values_loc, why.to_string(), "ignored");
                    }
                }
                None
            }
            _ => plain_value(ctx, s, l),
        };
        if let Some(v) = value {
            out.set(s.name, v);
        }
        let given = |list: &ParamList| list.items.iter().any(|q| q.name == s.name && q.used.get());
        if l.lists().any(given) {
            out.given.push(s.name);
        }
    }
    (out, refs)
}

/// A texture or spectrum parameter: its texture or constant, pbrt-v3's
/// default, or for `SameTexture`/`SameValue` the texture's own type.
fn texture_or_spectrum(
    ctx: &mut Ctx,
    s: &ParamSpec,
    l: &Lookup,
    same_is_float: bool,
) -> Option<ParamValue> {
    match s.kind {
        ParamKind::FloatTexture(def) => match l.float(ctx, s.name) {
            Some((FloatTex::Constant(v), loc)) => {
                Some(FloatTex::Constant(check_range(ctx, s, v, loc)))
            }
            Some((t, _)) => Some(t),
            None => def.map(FloatTex::Constant),
        }
        .map(ParamValue::FloatTexture),
        ParamKind::SameTexture(def) if same_is_float => Some(ParamValue::FloatTexture(
            l.float(ctx, s.name)
                .map(|(t, _)| t)
                .unwrap_or(FloatTex::Constant(def)),
        )),
        ParamKind::SameTexture(def) => Some(ParamValue::SpectrumTexture(
            l.spectrum(ctx, s.name)
                .map(|(t, _)| t)
                .unwrap_or(SpectrumTex::Constant(Vec3::splat(def))),
        )),
        ParamKind::SameValue(def) if same_is_float => {
            let v = l
                .plain(s.name, ParamType::Float)
                .map(|q| q.nums()[0] as f32)
                .unwrap_or(def);
            Some(ParamValue::FloatTexture(FloatTex::Constant(v)))
        }
        ParamKind::SameValue(def) => {
            let v = l
                .lists()
                .find_map(|list| find_spectrum(list, s.name))
                .and_then(|q| spectrum_value(ctx, q))
                .unwrap_or(Vec3::splat(def));
            Some(ParamValue::SpectrumTexture(SpectrumTex::Constant(v)))
        }
        ParamKind::SpectrumTexture(def) => match l.spectrum(ctx, s.name) {
            Some((t, _)) => Some(t),
            None => def.map(|d| SpectrumTex::Constant(spectrum_default(d))),
        }
        .map(ParamValue::SpectrumTexture),
        ParamKind::Spectrum(def) => Some(ParamValue::Spectrum(
            l.lists()
                .find_map(|list| find_spectrum(list, s.name))
                .and_then(|q| spectrum_value(ctx, q))
                .unwrap_or(Vec3::from_array(def)),
        )),
        ParamKind::SpectrumOrFloat(def) => Some(ParamValue::Spectrum(
            match l.plain(s.name, ParamType::Float) {
                Some(q) => Vec3::splat(q.nums()[0] as f32),
                None => l
                    .lists()
                    .find_map(|list| find_spectrum(list, s.name))
                    .and_then(|q| spectrum_value(ctx, q))
                    .unwrap_or(Vec3::from_array(def)),
            },
        )),
        _ => unreachable!("not a texture or spectrum parameter"),
    }
}

/// A parameter of a plain type (numbers, booleans, strings, files, lists):
/// its value or its default.
fn plain_value(ctx: &mut Ctx, s: &ParamSpec, l: &Lookup) -> Option<ParamValue> {
    match s.kind {
        ParamKind::Int(def) => Some(ParamValue::Int(
            l.plain(s.name, ParamType::Integer)
                .map(|q| q.nums()[0].clamp(i32::MIN as f64, i32::MAX as f64) as i32)
                .unwrap_or(def),
        )),
        ParamKind::Vector3(def) => Some(ParamValue::Vector(
            l.plain(s.name, ParamType::Vector3)
                .map(|q| {
                    let v = q.nums();
                    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
                })
                .unwrap_or(Vec3::from_array(def)),
        )),
        ParamKind::BoolOpt => l
            .plain(s.name, ParamType::Bool)
            .map(|q| ParamValue::Bool(q.bools()[0])),
        ParamKind::Choice { default, options } => {
            Some(ParamValue::String(read_choice(ctx, s, l, default, options)))
        }
        // As written: the image reader resolves it against the scene
        // file's directory.
        ParamKind::Filename => Some(ParamValue::String(
            l.plain(s.name, ParamType::String)
                .map(|q| q.strs()[0].clone())
                .unwrap_or_default(),
        )),
        ParamKind::Float(def) => Some(ParamValue::Float(
            l.plain(s.name, ParamType::Float)
                .map(|q| check_range(ctx, s, q.nums()[0] as f32, q.values_loc))
                .unwrap_or(def),
        )),
        ParamKind::FloatOpt => l
            .plain(s.name, ParamType::Float)
            .map(|q| ParamValue::Float(check_range(ctx, s, q.nums()[0] as f32, q.values_loc))),
        ParamKind::Bool(def) => Some(ParamValue::Bool(
            l.plain(s.name, ParamType::Bool)
                .map(|q| q.bools()[0])
                .unwrap_or(def),
        )),
        ParamKind::String(def) => Some(ParamValue::String(
            l.plain(s.name, ParamType::String)
                .map(|q| q.strs()[0].clone())
                .unwrap_or_else(|| def.to_string()),
        )),
        // pbrt-v3's FindFilename: an empty name is no name; a missing
        // one is reported by `material` (which knows the statement).
        ParamKind::FourierFile => l
            .plain(s.name, ParamType::String)
            .filter(|q| !q.strs()[0].is_empty())
            .and_then(|q| fourier_table(ctx, &q.strs()[0], q.values_loc))
            .map(ParamValue::Fourier),
        ParamKind::Point3(def) => Some(ParamValue::Point(
            l.plain(s.name, ParamType::Point3)
                .map(|q| {
                    let v = q.nums();
                    glam::DVec3::new(v[0], v[1], v[2])
                })
                .unwrap_or(Vec3::from_array(def).as_dvec3()),
        )),
        ParamKind::Floats => l
            .lists()
            .find_map(|list| {
                list.items
                    .iter()
                    .find(|q| q.name == s.name && q.ty == ParamType::Float)
            })
            .map(|q| {
                q.used.set(true);
                ParamValue::Floats(Arc::from(q.nums()))
            }),
        ParamKind::IntOpt => l
            .plain(s.name, ParamType::Integer)
            .map(|q| ParamValue::Int(q.nums()[0].clamp(i32::MIN as f64, i32::MAX as f64) as i32)),
        // pbrt-v3 reads no image for an empty name.
        ParamKind::Image(decode) => l
            .plain(s.name, ParamType::String)
            .filter(|q| !q.strs()[0].is_empty())
            .and_then(|q| {
                let instead = format!("rendered as without \"{}\"", s.name);
                super::image::load_image(ctx, q.values_loc, &q.strs()[0], decode, &instead)
            })
            .map(ParamValue::Image),
        ParamKind::List(e) => l
            .lists()
            .find_map(|list| {
                list.items
                    .iter()
                    .find(|q| q.name == s.name && elem_accepts(e, q.ty))
            })
            .map(|q| {
                q.used.set(true);
                ParamValue::Floats(Arc::from(q.nums()))
            }),
        _ => unreachable!("read by read_params_as"),
    }
}

/// A `Choice` parameter: its value if pbrt-v3 knows it, else (with a
/// warning and a hint) the default.
fn read_choice(
    ctx: &mut Ctx,
    s: &ParamSpec,
    l: &Lookup,
    default: &str,
    options: &[&str],
) -> String {
    match l.plain(s.name, ParamType::String) {
        Some(q) => {
            let v = q.strs()[0].clone();
            if options.contains(&v.as_str()) {
                v
            } else {
                let hint = match closest_name(&v, options) {
                    Some(c) => format!("did you mean \"{c}\"?"),
                    None => format!(
                        "one of {}",
                        options
                            .iter()
                            .map(|o| format!("\"{o}\""))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                };
                ctx.warn(q.values_loc, format!("\"{}\" is \"{v}\", which pbrt-v3 does not know ({hint}): \"{default}\" is used (as pbrt-v3)", s.name), "unknown value");
                default.to_string()
            }
        }
        None => default.to_string(),
    }
}

/// The parameter types a [`ParamKind::List`] of `e` takes.
fn elem_accepts(e: Elem, ty: ParamType) -> bool {
    match e {
        Elem::Number => matches!(ty, ParamType::Float | ParamType::Integer),
        Elem::Int => ty == ParamType::Integer,
        Elem::Point2 => matches!(ty, ParamType::Point2 | ParamType::Float),
        Elem::Point3 => ty == ParamType::Point3,
        Elem::Normal => ty == ParamType::Normal,
    }
}

fn check_range(ctx: &mut Ctx, s: &ParamSpec, v: f32, loc: Loc) -> f32 {
    match s.range {
        Range::NonNegative if v < 0.0 || v.is_nan() => {
            ctx.warn(
                loc,
                format!("\"{}\" is {v}: it must not be negative; 0 is used", s.name),
                "negative",
            );
            0.0
        }
        _ => v,
    }
}
