//! Objects made from one directive's parameters, with pbrt-v3's defaults:
//! cameras, film, filters, samplers, integrators, materials, textures, lights and
//! shapes. Every lookup marks its parameter used.

use super::color::{blackbody_to_rgb, repeated_wavelength, sampled_to_rgb, xyz_to_rgb};
use super::kinds::{self, Family, StatementReport, Unknown};
use super::spd;
use super::Ctx;
use crate::lang::params::{Param, ParamList, ParamType};
use crate::lang::parser::Name;
use crate::lang::Loc;
use crate::filters::{Filter, FILTERS};
use crate::lights::{AreaLightBuild, LightBuild, AREA_LIGHTS, LIGHTS};
use crate::samplers::SAMPLERS;
use crate::scene::kind;
use crate::scene::*;
use glam::{DMat4, Vec3};
use std::path::PathBuf;

pub const MAX_RESOLUTION: i64 = 32768;
pub const MAX_SAMPLES: i64 = 1 << 24;

// ---------------------------------------------------------------- lookups

pub(super) fn one<'a>(
    p: &'a ParamList,
    name: &str,
    ty: impl Fn(ParamType) -> bool,
) -> Option<&'a Param> {
    p.items
        .iter()
        .find(|q| q.name == name && ty(q.ty) && q.count() == 1)
        .inspect(|q| q.used.set(true))
}

pub fn float(p: &ParamList, name: &str, def: f64) -> f64 {
    one(p, name, |t| t == ParamType::Float)
        .map(|q| q.nums()[0])
        .unwrap_or(def)
}

pub(super) fn float_opt(p: &ParamList, name: &str) -> Option<(f64, Loc)> {
    one(p, name, |t| t == ParamType::Float).map(|q| (q.nums()[0], q.values_loc))
}

pub fn int(p: &ParamList, name: &str, def: i64) -> (i64, Option<Loc>) {
    one(p, name, |t| t == ParamType::Integer)
        .map(|q| (q.nums()[0] as i64, Some(q.values_loc)))
        .unwrap_or((def, None))
}

pub fn boolean(p: &ParamList, name: &str, def: bool) -> bool {
    one(p, name, |t| t == ParamType::Bool)
        .map(|q| q.bools()[0])
        .unwrap_or(def)
}

pub fn string<'a>(p: &'a ParamList, name: &str) -> Option<(&'a str, Loc)> {
    one(p, name, |t| t == ParamType::String).map(|q| (q.strs()[0].as_str(), q.values_loc))
}

/// A spectrum-typed parameter as linear RGB (`None` for a type that is not a spectrum).
pub(super) fn spectrum_value(ctx: &mut Ctx, q: &Param) -> Option<Vec3> {
    let v = q.nums();
    match q.ty {
        ParamType::Rgb => Some(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)),
        ParamType::Xyz => Some(xyz_to_rgb(v[0], v[1], v[2])),
        ParamType::Blackbody => Some(blackbody_to_rgb(v[0], v[1])),
        ParamType::Spectrum if !q.strs().is_empty() => Some(spectrum_file(ctx, q)),
        ParamType::Spectrum => {
            if let Some(l) = repeated_wavelength(v) {
                ctx.warn(q.values_loc, format!("\"{}\": wavelength {l} nm is given twice (pbrt-v3 stops on a failed check here): read as a step", q.name), "repeated wavelength");
            }
            Some(sampled_to_rgb(v))
        }
        _ => None,
    }
}

/// A spectrum file named by `q` (pbrt-v3 `AddSampledSpectrumFiles`): read once
/// per scene through `ctx.loader`, relative to the top-level file's directory.
/// A file that cannot be read, or that holds no pair, gives black, as in
/// pbrt-v3; problems inside it are warnings at the parameter.
fn spectrum_file(ctx: &mut Ctx, q: &Param) -> Vec3 {
    let name = &q.strs()[0];
    let path = ctx.resolve(q.values_loc, name);
    if let Some(&c) = ctx.spectra.get(&path) {
        return c;
    }
    let shown = path.display().to_string();
    let rgb = match ctx.loader.load(&path) {
        Err(e) => {
            ctx.warn(
                q.values_loc,
                format!("cannot read spectrum file \"{shown}\" for \"{}\": {e}: black is used (as pbrt-v3)", q.name),
                "spectrum file not read",
            );
            Vec3::ZERO
        }
        Ok(bytes) => {
            let file = spd::parse(&String::from_utf8_lossy(&bytes));
            for n in &file.notes {
                ctx.warn(
                    q.values_loc,
                    format!("spectrum file \"{shown}\": {n}"),
                    "in this spectrum file",
                );
            }
            if file.pairs.is_empty() {
                ctx.warn(q.values_loc, format!("spectrum file \"{shown}\" for \"{}\" holds no (wavelength, value) pair: black is used", q.name), "empty spectrum file");
            } else if let Some(l) = repeated_wavelength(&file.pairs) {
                ctx.warn(q.values_loc, format!("spectrum file \"{shown}\": wavelength {l} nm is given twice (pbrt-v3 stops on a failed check here): read as a step"), "repeated wavelength");
            }
            sampled_to_rgb(&file.pairs)
        }
    };
    ctx.spectra.insert(path, rgb);
    rgb
}

pub(super) fn find_spectrum<'a>(p: &'a ParamList, name: &str) -> Option<&'a Param> {
    let q = p
        .items
        .iter()
        .find(|q| q.name == name && q.ty.is_spectrum())?;
    // One spectrum: one triple for rgb/xyz, one pair for blackbody, any pairs
    // or one file name for spectrum (several files are several spectra).
    let single = match q.ty {
        ParamType::Spectrum => q.strs().len() <= 1,
        _ => q.count() == 1,
    };
    if single {
        q.used.set(true);
        Some(q)
    } else {
        None
    }
}

/// A spectrum parameter (rgb, color, xyz, blackbody or spectrum) as RGB.
pub fn spectrum(ctx: &mut Ctx, p: &ParamList, name: &str, def: Vec3) -> Vec3 {
    find_spectrum(p, name)
        .and_then(|q| spectrum_value(ctx, q))
        .unwrap_or(def)
}

/// pbrt-v3 `shapeMaySetMaterialParameters` (api.cpp): whether a shape's parameters
/// may override its material's.
pub fn shape_may_set_material_params(p: &ParamList) -> bool {
    p.items.iter().any(|q| match q.ty {
        ParamType::Texture => q.name != "alpha" && q.name != "shadowalpha",
        ParamType::Float => q.count() == 1 && q.name != "radius",
        ParamType::String => {
            q.count() == 1 && !matches!(q.name.as_str(), "filename" | "type" | "scheme")
        }
        ParamType::Spectrum => true,
        _ => q.count() == 1,
    })
}

// ---------------------------------------------------------------- lights

const LIGHT_FAMILY: Family<LightBuild> = Family {
    directive: "LightSource",
    noun: "light type",
    table: LIGHTS,
    unknown: Unknown::Warn,
};

const AREA_LIGHT_FAMILY: Family<AreaLightBuild> = Family {
    directive: "AreaLightSource",
    noun: "area light",
    table: AREA_LIGHTS,
    unknown: Unknown::Warn,
};

/// `LightSource`: a type of `lights::LIGHTS`, its parameters read
/// through its table and the light built by its builder with the CTM as
/// light-to-world; types pbrs does not render, unknown types and lights
/// the builder refuses are warned about and skipped.
pub fn light(ctx: &mut Ctx, name: &Name, p: &ParamList, ctm: DMat4) -> Option<Light> {
    let r = kinds::read(ctx, &LIGHT_FAMILY, name, p)?;
    if r.kind.unsupported().is_some() {
        p.mark_all_used();
        ctx.warn(
            name.loc,
            format!("light \"{}\" is not supported by pbrs: ignored", name.value),
            "light ignored",
        );
        return None;
    }
    let mut report = StatementReport {
        ctx,
        at: name.loc,
        params: p,
    };
    let light = (r.kind.build)(&r.params, ctm, &mut report);
    kinds::report_unused(ctx, &LIGHT_FAMILY, &r, name, p);
    light
}

/// Whether `AreaLightSource` names a type of `lights::AREA_LIGHTS`
/// (else a warning: later shapes do not emit). Its parameters are read by
/// [`area_light`] when a shape first uses it.
pub fn area_light_known(ctx: &mut Ctx, name: &Name, p: &ParamList) -> bool {
    if kind::find(AREA_LIGHTS, &name.value).is_some() {
        return true;
    }
    p.mark_all_used();
    let known = AREA_LIGHTS
        .iter()
        .map(|k| {
            let aliases: String = k
                .aliases
                .iter()
                .map(|a| format!(", alias \"{a}\""))
                .collect();
            format!("\"{}\"{aliases}", k.name)
        })
        .collect::<Vec<_>>()
        .join("; ");
    ctx.warn(
        name.loc,
        format!(
            "unknown area light \"{}\" (pbrt-v3 has {known}): ignored, later shapes are not emissive",
            name.value
        ),
        "not an area light type",
    );
    false
}

/// `AreaLightSource`'s emission, read through its type's table (`None`
/// for an unknown type, which [`area_light_known`] reported).
pub fn area_light(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<DiffuseEmission> {
    let r = kinds::read(ctx, &AREA_LIGHT_FAMILY, name, p)?;
    let mut report = StatementReport {
        ctx,
        at: name.loc,
        params: p,
    };
    let emission = (r.kind.build)(&r.params, &mut report);
    kinds::report_unused(ctx, &AREA_LIGHT_FAMILY, &r, name, p);
    Some(emission)
}

// ---------------------------------------------------------------- options

type Ent<'a> = Option<(&'a Name, &'a ParamList)>;

/// The `Camera` directive (see `loader/camera.rs`); `film` gives the
/// realistic camera its sensor size.
pub fn camera(
    ctx: &mut Ctx,
    c: Option<((&Name, &ParamList), DMat4)>,
    film: &FilmDesc,
) -> CameraDesc {
    super::camera::camera(ctx, c, film)
}

fn checked_count(ctx: &mut Ctx, p: &ParamList, name: &str, def: i64, max: i64, what: &str) -> u32 {
    let (v, loc) = int(p, name, def);
    if v < 1 || v > max {
        let loc = loc.unwrap_or_default();
        ctx.error(
            loc,
            format!("{what} \"{name}\" is {v}: it must be between 1 and {max}"),
            "out of range",
            None,
        );
        return def as u32;
    }
    v as u32
}

pub fn film(ctx: &mut Ctx, f: Ent) -> FilmDesc {
    let empty = ParamList::default();
    let p = match f {
        Some((name, p)) if name.value != "image" => {
            p.mark_all_used();
            ctx.error(
                name.loc,
                format!(
                    "unknown film \"{}\" (pbrt-v3 has only \"image\")",
                    name.value
                ),
                "unknown film",
                None,
            );
            &empty
        }
        Some((_, p)) => p,
        None => &empty,
    };
    let xresolution = checked_count(
        ctx,
        p,
        "xresolution",
        1280,
        MAX_RESOLUTION,
        "film resolution",
    );
    let yresolution = checked_count(
        ctx,
        p,
        "yresolution",
        720,
        MAX_RESOLUTION,
        "film resolution",
    );
    let mut cropwindow = [0.0, 1.0, 0.0, 1.0];
    if let Some(q) = p
        .items
        .iter()
        .find(|q| q.name == "cropwindow" && q.ty == ParamType::Float)
    {
        q.used.set(true);
        let v = q.nums();
        if v.len() == 4 {
            let c = |a: f64| a.clamp(0.0, 1.0) as f32;
            cropwindow = [
                c(v[0].min(v[1])),
                c(v[0].max(v[1])),
                c(v[2].min(v[3])),
                c(v[2].max(v[3])),
            ];
            if cropwindow[0] >= cropwindow[1] || cropwindow[2] >= cropwindow[3] {
                ctx.error(
                    q.values_loc,
                    "\"cropwindow\" is empty: it covers no pixels",
                    "empty crop window",
                    None,
                );
                cropwindow = [0.0, 1.0, 0.0, 1.0];
            }
        } else {
            ctx.warn(
                q.values_loc,
                format!(
                    "\"cropwindow\" needs 4 values, found {}: ignored (as pbrt-v3)",
                    v.len()
                ),
                "expected 4 values",
            );
        }
    }
    let filename = string(p, "filename")
        .map(|(s, _)| s.to_string())
        .unwrap_or_else(|| "pbrt.exr".into());
    let scale = float(p, "scale", 1.0) as f32;
    let diagonal = float(p, "diagonal", 35.0) as f32;
    let max_sample_luminance = float(p, "maxsampleluminance", f64::INFINITY) as f32;
    if let Some((name, _)) = f {
        ctx.report_unused(p, &format!("Film \"{}\"", name.value));
    }
    FilmDesc {
        xresolution,
        yresolution,
        cropwindow,
        filename: PathBuf::from(filename),
        scale,
        max_sample_luminance,
        diagonal,
    }
}

/// `PixelFilter`: the kind's builder from [`FILTERS`] (pbrt-v3's default
/// when there is no statement: a box of radius 0.5).
pub fn filter(ctx: &mut Ctx, f: Ent) -> Filter {
    let family = Family {
        directive: "PixelFilter",
        noun: "filter",
        table: FILTERS,
        unknown: Unknown::Error,
    };
    f.and_then(|(name, p)| kinds::build(ctx, &family, name, p))
        .unwrap_or_default()
}

/// `Sampler`: the kind's builder from [`SAMPLERS`] (pbrt-v3's default
/// when there is no statement: halton, 16 samples per pixel).
pub fn sampler(ctx: &mut Ctx, s: Ent) -> SamplerDesc {
    let family = Family {
        directive: "Sampler",
        noun: "sampler",
        table: SAMPLERS,
        unknown: Unknown::Error,
    };
    s.and_then(|(name, p)| kinds::build(ctx, &family, name, p))
        .unwrap_or(SamplerDesc {
            kind: SamplerKind::Halton,
            pixel_samples: 16,
            sample_pixel_center: false,
        })
}

/// The integrator of an `Integrator` statement, read through
/// [`INTEGRATORS`](crate::integrators::INTEGRATORS): the kind's
/// builder checks its settings; a kind pbrs does not render is `path` with
/// the statement's `maxdepth`, with a warning.
pub fn integrator(ctx: &mut Ctx, s: Ent) -> IntegratorSettings {
    use super::kinds::{self, Family, StatementReport, Unknown};
    let family = Family {
        directive: "Integrator",
        noun: "integrator",
        table: crate::integrators::INTEGRATORS,
        unknown: Unknown::Error,
    };
    let Some((name, p)) = s else {
        return IntegratorSettings::default();
    };
    let Some(read) = kinds::read(ctx, &family, name, p) else {
        return IntegratorSettings::default();
    };
    let mut report = StatementReport {
        ctx,
        at: name.loc,
        params: p,
    };
    let settings = (read.kind.build)(&read.params, &mut report);
    if read.kind.unsupported().is_some() {
        p.mark_all_used();
        ctx.warn(name.loc, format!("integrator \"{}\" is not supported by pbrs: substituted by \"path\" with maxdepth {}", name.value, settings.max_depth()), "substituted by path");
    }
    kinds::report_unused(ctx, &family, &read, name, p);
    settings
}
