//! The `Texture` directive: a texture of a class in
//! `textures::TEXTURES`, its parameters read through the class's
//! `ParamSpec` list with pbrt-v3's rules (`TextureParams` over the
//! statement's own parameters: texture references by name resolve to the
//! textures defined before, of the type the parameter needs), its mapping,
//! and its images. Also the shapes' `alpha` and `shadowalpha` textures.

use super::image::{load_image, load_ptex};
use super::lookup::one;
use super::params::{read_params, read_params_as, Lookup, TexEntry, Textures};
use super::Ctx;
use crate::lang::params::{ParamList, ParamType};
use crate::lang::parser::Name;
use crate::lang::Loc;
use crate::scene::kind::closest_name;
use crate::scene::{Decode, FloatTex, ParamValues, RgbImage, Tex};
use crate::textures::ptex_file::PtexFile;
use crate::textures::{
    self, ImageSource, Mapping2D, Mapping3D, MappingUse, MipCache, TexBuilder, TexValue,
    TextureClass, MAPPING_KINDS, PLANAR_MAPPING_PARAMS, TEXTURES, UV_MAPPING_PARAMS,
};
use glam::{DMat4, Vec3};
use std::sync::Arc;

/// A texture a `Texture` statement defined.
pub enum Defined {
    Float(TexEntry<f32>),
    Spectrum(TexEntry<Vec3>),
}

/// What texture building keeps for the whole scene: MIP maps shared by
/// image textures with the same file and settings, and counts by class for
/// `--check`.
#[derive(Default)]
pub struct TextureState {
    pub mips: MipCache,
    pub by_class: std::collections::BTreeMap<&'static str, usize>,
}

/// The loader's images for image textures (read once per scene).
struct Images<'a> {
    ctx: &'a mut Ctx,
    loc: Loc,
}

impl ImageSource for Images<'_> {
    fn image(&mut self, path: &str) -> Option<Arc<RgbImage>> {
        // Raw values: the texture decodes them (a float texture decodes the
        // luminance, not each channel).
        load_image(
            self.ctx,
            self.loc,
            path,
            Decode::Raw,
            "a constant grey texture (0.5) is used instead",
        )
    }
    fn ptex(&mut self, path: &str, substitute: &str) -> Option<Arc<PtexFile>> {
        load_ptex(self.ctx, self.loc, path, substitute)
    }
}

/// `Texture "name" "float"|"color"|"spectrum" "class" params`.
#[allow(clippy::too_many_arguments)]
pub fn texture(
    ctx: &mut Ctx,
    name: &Name,
    kind: &Name,
    class: &Name,
    params: &ParamList,
    textures: &Textures,
    ctm: DMat4,
    state: &mut TextureState,
) -> Option<Defined> {
    let is_float = match kind.value.as_str() {
        "float" => true,
        "color" | "spectrum" => false,
        other => {
            params.mark_all_used();
            ctx.warn(kind.loc, format!("texture type \"{other}\" is neither \"float\", \"color\" nor \"spectrum\": texture \"{}\" ignored", name.value), "unknown texture type");
            return None;
        }
    };
    let Some(k) = textures::class(&class.value) else {
        params.mark_all_used();
        let names: Vec<&str> = TEXTURES.iter().map(|c| c.name).collect();
        let hint = match closest_name(&class.value, &names) {
            Some(c) => format!(" (did you mean \"{c}\"?)"),
            None => String::new(),
        };
        ctx.warn(
            class.loc,
            format!(
                "unknown texture class \"{}\"{hint}: texture \"{}\" ignored (as pbrt-v3)",
                class.value, name.value
            ),
            "not a pbrt-v3 texture class",
        );
        return None;
    };
    if let Some(why) = k.unsupported() {
        ctx.warn(
            class.loc,
            format!(
                "texture class \"{}\" is not supported by pbrs ({why}): texture \"{}\"",
                k.name, name.value
            ),
            "not read",
        );
    }
    let what = format!("Texture \"{}\"", name.value);
    let defined = if is_float {
        build::<f32>(
            ctx,
            name,
            class,
            k,
            k.build.float,
            params,
            textures,
            ctm,
            state,
        )
        .map(|tex| Defined::Float(entry(tex, name, k)))
    } else {
        build::<Vec3>(
            ctx,
            name,
            class,
            k,
            k.build.spectrum,
            params,
            textures,
            ctm,
            state,
        )
        .map(|tex| Defined::Spectrum(entry(tex, name, k)))
    };
    ctx.report_unused(params, &what);
    if defined.is_some() {
        *state.by_class.entry(k.name).or_default() += 1;
    }
    defined
}

fn entry<T>(tex: Tex<T>, name: &Name, k: &TextureClass) -> TexEntry<T> {
    TexEntry {
        tex,
        loc: name.loc,
        class: k.name,
    }
}

#[allow(clippy::too_many_arguments)]
fn build<T: TexValue>(
    ctx: &mut Ctx,
    name: &Name,
    class: &Name,
    k: &'static TextureClass,
    builder: Option<textures::Build<T>>,
    params: &ParamList,
    textures: &Textures,
    ctm: DMat4,
    state: &mut TextureState,
) -> Option<Tex<T>> {
    let ty = if T::IS_FLOAT { "float" } else { "color" };
    let Some(builder) = builder else {
        params.mark_all_used();
        ctx.warn(
            class.loc,
            format!("pbrt-v3 has no {ty} texture of class \"{}\" (only color): texture \"{}\" is not defined (as pbrt-v3)", k.name, name.value),
            "no such texture type",
        );
        return None;
    };
    let l = Lookup {
        first: None,
        second: params,
        textures,
    };
    let (values, _) = read_params_as(ctx, k.params, &l, T::IS_FLOAT);
    if k.params.iter().any(|s| s.name == "octaves") {
        let n = values.int("octaves");
        if n > textures::MAX_OCTAVES {
            let at = params.get("octaves").map_or(class.loc, |q| q.values_loc);
            ctx.warn(
                at,
                format!("\"octaves\" is {n}: pbrs sums at most {} octaves (past them the frequency 1.99^k overflows a float), which is used", textures::MAX_OCTAVES),
                "octaves clamped",
            );
        }
    }
    let two_d = match k.build.mapping {
        MappingUse::TwoD => true,
        MappingUse::ByDimension => values.int("dimension") == 2,
        MappingUse::None | MappingUse::ThreeD => false,
    };
    let mapping2d = if two_d {
        mapping_2d(ctx, &l, ctm)
    } else {
        Mapping2D::default()
    };
    let loc = params
        .get("filename")
        .map(|q| q.values_loc)
        .unwrap_or(class.loc);
    let mut images = Images { ctx, loc };
    let mut b = TexBuilder {
        name: &name.value,
        params: &values,
        mapping2d,
        mapping3d: Mapping3D::new(ctm),
        images: &mut images,
        mips: &mut state.mips,
    };
    match builder(&mut b) {
        Ok(t) => Some(t),
        Err(e) => {
            ctx.warn(
                class.loc,
                format!("texture \"{}\": {e}: not defined", name.value),
                "texture not defined",
            );
            None
        }
    }
}

/// The 2D mapping of a texture statement (pbrt-v3 reads each mapping's
/// parameters only for that mapping; the others are then unused).
fn mapping_2d(ctx: &mut Ctx, l: &Lookup, tex_to_world: DMat4) -> Mapping2D {
    let (kind, loc) = match one(l.second, "mapping", |t| t == ParamType::String) {
        Some(q) => (q.strs()[0].clone(), q.values_loc),
        None => ("uv".to_string(), Loc::default()),
    };
    let read = |ctx: &mut Ctx, specs| -> ParamValues { read_params(ctx, specs, l).0 };
    match kind.as_str() {
        "uv" => {
            let p = read(ctx, UV_MAPPING_PARAMS);
            Mapping2D::Uv {
                su: p.float("uscale"),
                sv: p.float("vscale"),
                du: p.float("udelta"),
                dv: p.float("vdelta"),
            }
        }
        "spherical" => Mapping2D::spherical(tex_to_world),
        "cylindrical" => Mapping2D::cylindrical(tex_to_world),
        "planar" => {
            let p = read(ctx, PLANAR_MAPPING_PARAMS);
            Mapping2D::Planar {
                vs: p.vector("v1"),
                vt: p.vector("v2"),
                ds: p.float("udelta"),
                dt: p.float("vdelta"),
            }
        }
        other => {
            let hint = match closest_name(other, MAPPING_KINDS) {
                Some(c) => format!(" (did you mean \"{c}\"?)"),
                None => String::new(),
            };
            ctx.warn(
                loc,
                format!("2D texture mapping \"{other}\" unknown{hint}: \"uv\" with its defaults is used (as pbrt-v3)"),
                "unknown mapping",
            );
            Mapping2D::default()
        }
    }
}

/// A shape's `alpha` or `shadowalpha` (pbrt-v3's triangle mesh rules): a
/// named float texture, or a float that counts only when it is 0.
/// `None`: no alpha test (a constant that is not 0 never cuts anything).
pub fn shape_alpha(
    ctx: &mut Ctx,
    p: &ParamList,
    param: &str,
    textures: &Textures,
) -> Option<FloatTex> {
    if let Some(q) = one(p, param, |t| t == ParamType::Texture) {
        let tex = &q.strs()[0];
        return match textures.float.get(tex) {
            Some(e) => match e.tex {
                Tex::Constant(c) if c != 0.0 => None,
                ref t => Some(t.clone()),
            },
            None => {
                let hint = if textures.spectrum.contains_key(tex) {
                    format!(" (\"{tex}\" is a spectrum texture)")
                } else {
                    String::new()
                };
                ctx.warn(q.values_loc, format!("couldn't find float texture \"{tex}\" for \"{param}\"{hint}: no alpha test (as pbrt-v3)"), "no such \"float\" texture");
                None
            }
        };
    }
    let v = one(p, param, |t| t == ParamType::Float)?.nums()[0];
    (v == 0.0).then_some(Tex::Constant(0.0))
}
