//! Objects made from one directive's parameters, with pbrt-v3's defaults:
//! cameras, film, filters, samplers, integrators, materials, textures, lights and
//! shapes. Every lookup marks its parameter used.

use super::color::{blackbody_to_rgb, repeated_wavelength, sampled_to_rgb, xyz_to_rgb};
use super::kinds::{self, Family, Unknown};
use super::spd;
use super::Ctx;
use crate::lang::params::{Param, ParamList, ParamType};
use crate::lang::parser::Name;
use crate::lang::Loc;
use crate::render::filters::{Filter, FILTERS};
use crate::render::samplers::SAMPLERS;
use crate::scene::*;
use glam::{DMat4, DVec3, Vec3};
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

pub(super) fn point3(p: &ParamList, name: &str, def: DVec3) -> DVec3 {
    one(p, name, |t| t == ParamType::Point3)
        .map(|q| DVec3::new(q.nums()[0], q.nums()[1], q.nums()[2]))
        .unwrap_or(def)
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

/// Light `scale`: a spectrum in pbrt-v3; a plain float is accepted too.
fn light_scale(ctx: &mut Ctx, p: &ParamList) -> Vec3 {
    if let Some((f, _)) = float_opt(p, "scale") {
        return Vec3::splat(f as f32);
    }
    spectrum(ctx, p, "scale", Vec3::ONE)
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

pub fn area_light(ctx: &mut Ctx, p: &ParamList) -> AreaLightDesc {
    let l = spectrum(ctx, p, "L", Vec3::ONE) * light_scale(ctx, p);
    let (ns, _) = int(p, "nsamples", 1);
    let (n, _) = int(p, "samples", ns);
    let two_sided = boolean(p, "twosided", false);
    AreaLightDesc {
        l,
        two_sided,
        n_samples: n.clamp(1, MAX_SAMPLES) as u32,
    }
}

/// `LightSource`: point, spot, distant, infinite; others are warned about and skipped.
pub fn light(ctx: &mut Ctx, name: &Name, p: &ParamList, ctm: DMat4) -> Option<LightDesc> {
    match name.value.as_str() {
        "point" => {
            let i = spectrum(ctx, p, "I", Vec3::ONE) * light_scale(ctx, p);
            let from = point3(p, "from", DVec3::ZERO);
            // pbrt-v3 point.cpp: light-to-world = Translate(from) · CTM, so the light
            // sits at CTM·origin + from (not CTM·from when the CTM scales or rotates).
            Some(LightDesc::Point {
                position: ctm.transform_point3(DVec3::ZERO) + from,
                intensity: i,
            })
        }
        "spot" => {
            let i = spectrum(ctx, p, "I", Vec3::ONE) * light_scale(ctx, p);
            let cone = float(p, "coneangle", 30.0);
            let delta = float(p, "conedeltaangle", 5.0);
            let from = point3(p, "from", DVec3::ZERO);
            let to = point3(p, "to", DVec3::Z);
            let dir = to - from;
            if dir.length_squared() == 0.0 {
                ctx.warn(
                    name.loc,
                    "spot light with \"from\" equal to \"to\" has no direction: skipped",
                    "degenerate spot light",
                );
                return None;
            }
            let dir = dir.normalize();
            // pbrt-v3 CoordinateSystem(dir, &du, &dv); light2world = CTM · Translate(from) · Inverse(dirToZ).
            let du = if dir.x.abs() > dir.y.abs() {
                DVec3::new(-dir.z, 0.0, dir.x) / (dir.x * dir.x + dir.z * dir.z).sqrt()
            } else {
                DVec3::new(0.0, dir.z, -dir.y) / (dir.y * dir.y + dir.z * dir.z).sqrt()
            };
            let dv = dir.cross(du);
            let frame = DMat4::from_cols(
                du.extend(0.0),
                dv.extend(0.0),
                dir.extend(0.0),
                glam::DVec4::W,
            );
            let light_to_world = ctm * DMat4::from_translation(from) * frame;
            if !light_to_world.is_finite() {
                ctx.warn(
                    name.loc,
                    "spot light transform is not finite (from/to too large): skipped",
                    "degenerate spot light",
                );
                return None;
            }
            Some(LightDesc::Spot {
                light_to_world,
                intensity: i,
                cone_angle: cone as f32,
                cone_delta_angle: delta as f32,
            })
        }
        "distant" => {
            let l = spectrum(ctx, p, "L", Vec3::ONE) * light_scale(ctx, p);
            let from = point3(p, "from", DVec3::ZERO);
            let to = point3(p, "to", DVec3::Z);
            let d = ctm.transform_vector3(from - to);
            if d.length_squared() == 0.0 || !d.is_finite() {
                ctx.warn(
                    name.loc,
                    "distant light with \"from\" equal to \"to\" has no direction: skipped",
                    "degenerate distant light",
                );
                return None;
            }
            Some(LightDesc::Distant {
                radiance: l,
                direction: d.normalize(),
            })
        }
        "infinite" | "exinfinite" => {
            // pbrt-v3 reads `scale` as a spectrum only: "float scale" stays unused.
            let l = spectrum(ctx, p, "L", Vec3::ONE) * spectrum(ctx, p, "scale", Vec3::ONE);
            let (ns, _) = int(p, "nsamples", 1);
            let (n, _) = int(p, "samples", ns);
            let image = match string(p, "mapname") {
                Some((map, loc)) if !map.is_empty() => {
                    // Raw values: pbrt-v3's infinite light does not sRGB-decode.
                    Some(super::image::load_image(ctx, loc, map, Decode::Raw)?)
                }
                _ => None,
            };
            let sampling = match string(p, "sampling") {
                None | Some(("map", _)) => EnvSampling::Map,
                Some(("uniform", _)) => EnvSampling::Uniform,
                Some((other, loc)) => {
                    ctx.warn(
                        loc,
                        format!("unknown infinite light sampling \"{other}\" (pbrs has \"map\" and \"uniform\"): \"map\" is used"),
                        "unknown sampling",
                    );
                    EnvSampling::Map
                }
            };
            Some(LightDesc::Infinite {
                radiance: l,
                image,
                light_to_world: ctm,
                n_samples: n.clamp(1, MAX_SAMPLES) as u32,
                sampling,
            })
        }
        other => {
            p.mark_all_used();
            if matches!(other, "goniometric" | "projection") {
                ctx.warn(
                    name.loc,
                    format!("light \"{other}\" is not supported by pbrs: ignored"),
                    "light ignored",
                );
            } else {
                ctx.warn(name.loc, format!("unknown light type \"{other}\": ignored (pbrt-v3 has point, spot, goniometric, projection, distant, infinite)"), "unknown light");
            }
            None
        }
    }
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

pub fn default_camera() -> CameraDesc {
    CameraDesc {
        camera_to_world: DMat4::IDENTITY,
        motion: None,
        kind: CameraKind::Perspective {
            fov: 90.0,
            lens_radius: 0.0,
            focal_distance: 1e6,
            frame_aspect_ratio: None,
            screen_window: None,
        },
        shutter_open: 0.0,
        shutter_close: 1.0,
    }
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

pub fn integrator(ctx: &mut Ctx, s: Ent) -> IntegratorDesc {
    let path = |d| IntegratorDesc::Path {
        max_depth: d,
        rr_threshold: 1.0,
        light_sample_strategy: LightSampleStrategy::Spatial,
    };
    let Some((name, p)) = s else { return path(5) };
    let (md, loc) = int(p, "maxdepth", 5);
    let max_depth = if md < 0 {
        ctx.error(
            loc.unwrap_or(name.loc),
            format!("\"maxdepth\" is {md}: it must be ≥ 0"),
            "negative depth",
            None,
        );
        5
    } else {
        md as u32
    };
    if let Some(q) = p.items.iter().find(|q| q.name == "pixelbounds") {
        q.used.set(true);
        ctx.warn(q.loc, "\"pixelbounds\" is not supported by pbrs: the whole film is rendered (use --cropwindow)", "ignored");
    }
    let d = match name.value.as_str() {
        "path" | "volpath" => {
            let rr = float(p, "rrthreshold", 1.0) as f32;
            let strategy = match string(p, "lightsamplestrategy") {
                None | Some(("spatial", _)) => LightSampleStrategy::Spatial,
                Some(("uniform", _)) => LightSampleStrategy::Uniform,
                Some(("power", _)) => LightSampleStrategy::Power,
                Some(("bvh", _)) => LightSampleStrategy::Bvh,
                Some((other, loc)) => {
                    ctx.warn(loc, format!("unknown light sample strategy \"{other}\": \"spatial\" is used (as pbrt-v3)"), "expected uniform, power, spatial or bvh");
                    LightSampleStrategy::Spatial
                }
            };
            if name.value == "volpath" {
                IntegratorDesc::VolPath {
                    max_depth,
                    rr_threshold: rr,
                    light_sample_strategy: strategy,
                }
            } else {
                IntegratorDesc::Path {
                    max_depth,
                    rr_threshold: rr,
                    light_sample_strategy: strategy,
                }
            }
        }
        "directlighting" => {
            let strategy = match string(p, "strategy") {
                None | Some(("all", _)) => DirectStrategy::All,
                Some(("one", _)) => DirectStrategy::One,
                Some((other, loc)) => {
                    ctx.warn(
                        loc,
                        format!("unknown strategy \"{other}\": \"all\" is used (as pbrt-v3)"),
                        "expected all or one",
                    );
                    DirectStrategy::All
                }
            };
            IntegratorDesc::DirectLighting {
                max_depth,
                strategy,
            }
        }
        "whitted" => IntegratorDesc::Whitted { max_depth },
        "bdpt" | "mlt" | "sppm" | "ambientocclusion" => {
            p.mark_all_used();
            ctx.warn(name.loc, format!("integrator \"{}\" is not supported by pbrs: substituted by \"path\" with maxdepth {max_depth}", name.value), "substituted by path");
            path(max_depth)
        }
        other => {
            p.mark_all_used();
            ctx.error(name.loc, format!("unknown integrator \"{other}\" (pbrt-v3 has whitted, directlighting, path, volpath, bdpt, mlt, ambientocclusion, sppm)"), "unknown integrator", None);
            path(max_depth)
        }
    };
    ctx.report_unused(p, &format!("Integrator \"{}\"", name.value));
    d
}
