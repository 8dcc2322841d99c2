//! pbrt-v3's render options: the `Camera`, `Film`, `PixelFilter`, `Sampler`
//! and `Integrator` statements (the last of each before `WorldBegin`), with
//! pbrt-v3's defaults when a statement is missing.

use super::kinds::{self, Family, Unknown};
use super::lookup::{float, int, string};
use super::Ctx;
use crate::filters::{Filter, FILTERS};
use crate::lang::params::{ParamList, ParamType};
use crate::lang::parser::Name;
use crate::samplers::SAMPLERS;
use crate::scene::*;
use glam::DMat4;
use std::path::PathBuf;

pub const MAX_RESOLUTION: i64 = 32768;
pub const MAX_SAMPLES: i64 = 1 << 24;

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
        let depth = match &settings {
            IntegratorSettings::Path(p) => p.max_depth,
            _ => unreachable!("pbrs substitutes path for the integrators it does not render"),
        };
        ctx.warn(name.loc, format!("integrator \"{}\" is not supported by pbrs: substituted by \"path\" with maxdepth {depth}", name.value), "substituted by path");
    }
    kinds::report_unused(ctx, &family, &read, name, p);
    settings
}
