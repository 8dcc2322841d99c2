//! Materials as declared (`MaterialSpec`, built lazily when a shape uses
//! one) and built from their kind's parameter table (`materials::MATERIALS`)
//! through [`super::params`].

use super::params::Textures;
use super::params::{defaults, read_params, Lookup, NamedRef};
use super::{Ctx, DeclaredKind};
use crate::lang::params::ParamType;
use crate::lang::Loc;
use crate::materials::{self, MaterialKind, Support, MATERIALS};
use crate::scene::kind::closest_name;
use crate::scene::{MaterialDesc, ParamKind, ParamValue, SpectrumTex};
use glam::Vec3;
use std::collections::HashMap;
use std::rc::Rc;

/// A material as declared (built lazily when a shape uses it).
#[derive(Debug)]
pub struct MaterialSpec {
    pub ty: String,
    /// The `Material`/`MakeNamedMaterial` statement; `None` for the initial matte.
    pub stmt: Option<usize>,
    pub loc: Loc,
    pub textures: Rc<Textures>,
    pub name: Option<String>,
    /// The named materials visible at the statement (what `mix` refers to).
    pub named: Rc<HashMap<String, Rc<MaterialSpec>>>,
}

impl MaterialSpec {
    pub fn new(
        ty: String,
        stmt: Option<usize>,
        loc: Loc,
        textures: Rc<Textures>,
        name: Option<String>,
        named: Rc<HashMap<String, Rc<MaterialSpec>>>,
    ) -> Self {
        MaterialSpec {
            ty,
            stmt,
            loc,
            textures,
            name,
            named,
        }
    }
    pub fn default_matte() -> Self {
        MaterialSpec {
            ty: "matte".into(),
            stmt: None,
            loc: Loc::default(),
            textures: Rc::new(Textures::default()),
            name: None,
            named: Rc::new(HashMap::new()),
        }
    }
}

/// Builds a material: its description, its declared kind for the summary,
/// and the named materials it refers to (for the caller to resolve).
pub fn material(
    ctx: &mut Ctx,
    spec: &MaterialSpec,
    l: &Lookup,
) -> (MaterialDesc, DeclaredKind, Vec<NamedRef>) {
    let what = match &spec.name {
        Some(n) => format!("named material \"{n}\""),
        None => format!("Material \"{}\"", spec.ty),
    };
    let matte = materials::kind("matte").expect("matte is in the table");
    let mut declared = None;
    let kind: &'static MaterialKind = match materials::kind(&spec.ty) {
        Some(k) => match k.support {
            Support::Supported => k,
            Support::Unsupported(why) => {
                let kd = l
                    .spectrum(ctx, "Kd")
                    .map(|(t, _)| t)
                    .unwrap_or(SpectrumTex::Constant(Vec3::splat(0.5)));
                let kept = l.lists().any(|p| p.get("Kd").is_some_and(|q| q.used.get()));
                l.mark_all();
                let keep = match (&kd, kept) {
                    (_, false) => "the default Kd 0.5".to_string(),
                    (SpectrumTex::Constant(c), true) => format!("its Kd {c}"),
                    (SpectrumTex::Texture(t), true) => format!("its Kd texture \"{}\"", t.name),
                };
                ctx.warn(spec.loc, format!("{what}: material type \"{}\" is not supported by pbrs ({why}): substituted by a matte with {keep}", spec.ty), "substituted by matte");
                let mut params = defaults(ctx, matte.params);
                params.set("Kd", ParamValue::SpectrumTexture(kd));
                return (
                    MaterialDesc {
                        kind: "matte",
                        params,
                    },
                    DeclaredKind::Table(k.name),
                    Vec::new(),
                );
            }
        },
        None => {
            let names: Vec<&str> = MATERIALS
                .iter()
                .filter(|k| !k.name.is_empty())
                .map(|k| k.name)
                .collect();
            let hint = match closest_name(&spec.ty, &names) {
                Some(c) => format!(" (did you mean \"{c}\"?)"),
                None => String::new(),
            };
            ctx.warn(spec.loc, format!("{what}: unknown material type \"{}\"{hint}: using \"matte\" with its parameters (as pbrt-v3)", spec.ty), "unknown material type");
            declared = Some(DeclaredKind::Unknown(spec.ty.clone()));
            matte
        }
    };
    let (params, refs) = read_params(ctx, kind.params, l);
    for s in kind.params {
        let named = l
            .plain(s.name, ParamType::String)
            .is_some_and(|q| !q.strs()[0].is_empty());
        if matches!(s.kind, ParamKind::FourierFile) && !named {
            ctx.warn(spec.loc, format!("{what}: \"string {}\" is not given: the material does not scatter light (black, as pbrt-v3, which cannot open a file named \"\")", s.name), "no BSDF file");
        }
    }
    if kind.name == "disney" {
        for msg in materials::Disney::load_warnings(&params) {
            ctx.warn(spec.loc, format!("{what}: {msg}"), "disney");
        }
    }
    if kind.name == "hair" {
        for msg in materials::Hair::load_warnings(&params) {
            ctx.warn(spec.loc, format!("{what}: {msg}"), "hair");
        }
    }
    if kind.name == "subsurface" {
        for msg in materials::Subsurface::load_warnings(&params) {
            ctx.warn(spec.loc, format!("{what}: {msg}"), "subsurface");
        }
    }
    (
        MaterialDesc {
            kind: kind.name,
            params,
        },
        declared.unwrap_or(DeclaredKind::Table(kind.name)),
        refs,
    )
}
