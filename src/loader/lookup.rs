//! Parameters of a statement looked up by name, for the statements that are
//! not read through a kind's table (graphics state, refined shapes, the
//! material parameters a shape overrides); spectra in any of pbrt-v3's forms
//! (rgb, xyz, blackbody, sampled values, `.spd` files) reduced to RGB. Every
//! lookup marks its parameter used.

use super::color::{blackbody_to_rgb, repeated_wavelength, sampled_to_rgb, xyz_to_rgb};
use super::spd;
use super::Ctx;
use crate::lang::params::{Param, ParamList, ParamType};
use crate::lang::Loc;
use glam::Vec3;
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
