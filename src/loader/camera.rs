//! The `Camera` directive: pbrt-v3's four cameras with their parameters and
//! defaults (`Create*Camera` in pbrt-v3's `src/cameras/`), the realistic
//! camera's lens file, and the checks pbrt-v3 leaves to failed assertions
//! (a lens that blocks every ray or cannot focus) as located errors.

use super::entities::{boolean, default_camera, float, float_opt, string};
use super::Ctx;
use crate::lang::params::{ParamList, ParamType};
use crate::lang::parser::Name;
use crate::render::camera::realistic::focus_lens;
use crate::scene::{CameraDesc, CameraKind, FilmDesc, RealisticDesc};
use glam::DMat4;

/// More rows than any real lens system has; bounds the per-ray tracing cost.
pub const MAX_LENS_INTERFACES: usize = 256;

pub fn camera(
    ctx: &mut Ctx,
    c: Option<((&Name, &ParamList), DMat4)>,
    film: &FilmDesc,
) -> CameraDesc {
    let empty = ParamList::default();
    let ((name, p), ctm) = match c {
        Some(x) => x,
        None => return default_camera(),
    };
    let mut camera_to_world = ctm.inverse();
    if !camera_to_world.is_finite() || ctm.determinant().abs() < 1e-300 {
        ctx.error(
            name.loc,
            "the camera transform (the CTM at Camera) is singular: it cannot be inverted",
            "this Camera",
            None,
        );
        camera_to_world = DMat4::IDENTITY;
    }
    let kind = match name.value.as_str() {
        "perspective" => perspective(ctx, name, p),
        "orthographic" => {
            let (lens_radius, focal_distance) = thin_lens(ctx, name, p, 1e6);
            CameraKind::Orthographic {
                lens_radius,
                focal_distance,
                frame_aspect_ratio: frame_aspect_ratio(ctx, p),
                screen_window: screen_window(ctx, p),
            }
        }
        "environment" => {
            // Read and ignored by pbrt-v3 (so never reported unused).
            for n in ["lensradius", "focaldistance", "frameaspectratio"] {
                float(p, n, 0.0);
            }
            screen_window(ctx, p);
            CameraKind::Environment
        }
        "realistic" => match realistic(ctx, name, p, film) {
            Some(r) => CameraKind::Realistic(r),
            None => {
                p.mark_all_used();
                default_camera().kind
            }
        },
        other => {
            ctx.error(name.loc, format!("unknown camera \"{other}\" (pbrt-v3 has perspective, orthographic, realistic, environment)"), "unknown camera", None);
            p.mark_all_used();
            perspective(ctx, name, &empty)
        }
    };
    let mut open = float(p, "shutteropen", 0.0) as f32;
    let mut close = float(p, "shutterclose", 1.0) as f32;
    if close < open {
        ctx.warn(
            name.loc,
            "shutterclose < shutteropen: swapped (as pbrt-v3)",
            "shutter",
        );
        std::mem::swap(&mut open, &mut close);
    }
    ctx.report_unused(p, &format!("Camera \"{}\"", name.value));
    CameraDesc {
        camera_to_world,
        motion: None,
        kind,
        shutter_open: open,
        shutter_close: close,
    }
}

fn perspective(ctx: &mut Ctx, name: &Name, p: &ParamList) -> CameraKind {
    let mut fov = float(p, "fov", 90.0);
    let half = float(p, "halffov", -1.0);
    if half > 0.0 {
        fov = 2.0 * half;
    }
    if !(fov > 0.0 && fov < 180.0) {
        let loc = p.get("fov").map(|q| q.values_loc).unwrap_or(name.loc);
        ctx.error(
            loc,
            format!("field of view {fov} is outside (0, 180) degrees"),
            "bad fov",
            None,
        );
        fov = 90.0;
    }
    let (lens_radius, focal_distance) = thin_lens(ctx, name, p, 1e6);
    CameraKind::Perspective {
        fov: fov as f32,
        lens_radius,
        focal_distance,
        frame_aspect_ratio: frame_aspect_ratio(ctx, p),
        screen_window: screen_window(ctx, p),
    }
}

/// `lensradius` and `focaldistance`. A negative radius is a pinhole (pbrt-v3
/// tests `lensRadius > 0`), with a warning; a lens focused at a distance
/// that is not positive is an error (its rays would run backwards or be
/// NaN).
fn thin_lens(ctx: &mut Ctx, name: &Name, p: &ParamList, default_focus: f64) -> (f32, f32) {
    let loc_of = |n: &str| p.get(n).map(|q| q.values_loc).unwrap_or(name.loc);
    let mut lens_radius = float(p, "lensradius", 0.0) as f32;
    let mut focal_distance = float(p, "focaldistance", default_focus) as f32;
    if !lens_radius.is_finite() || lens_radius < 0.0 {
        ctx.warn(
            loc_of("lensradius"),
            format!("\"lensradius\" {lens_radius} is not a radius ≥ 0: a pinhole camera is used"),
            "bad lens radius",
        );
        lens_radius = 0.0;
    }
    if lens_radius > 0.0 && !(focal_distance > 0.0 && focal_distance.is_finite()) {
        ctx.error(
            loc_of("focaldistance"),
            format!("\"focaldistance\" {focal_distance} must be > 0 for a lens (\"lensradius\" {lens_radius})"),
            "bad focal distance",
            None,
        );
        focal_distance = default_focus as f32;
    }
    (lens_radius, focal_distance)
}

fn frame_aspect_ratio(ctx: &mut Ctx, p: &ParamList) -> Option<f32> {
    let (v, loc) = float_opt(p, "frameaspectratio")?;
    if v > 0.0 && v.is_finite() {
        Some(v as f32)
    } else {
        ctx.error(
            loc,
            format!("\"frameaspectratio\" {v} must be > 0"),
            "bad aspect ratio",
            None,
        );
        None
    }
}

fn screen_window(ctx: &mut Ctx, p: &ParamList) -> Option<[f32; 4]> {
    let q = p
        .items
        .iter()
        .find(|q| q.name == "screenwindow" && q.ty == ParamType::Float)?;
    q.used.set(true);
    let v = q.nums();
    if v.len() != 4 {
        ctx.warn(
            q.values_loc,
            format!(
                "\"screenwindow\" needs 4 values, found {}: ignored",
                v.len()
            ),
            "expected 4 values",
        );
        return None;
    }
    let w = [v[0] as f32, v[1] as f32, v[2] as f32, v[3] as f32];
    if w.iter().any(|x| !x.is_finite()) || w[0] == w[1] || w[2] == w[3] {
        ctx.error(
            q.values_loc,
            format!("\"screenwindow\" {w:?} is empty or not finite"),
            "bad screen window",
            None,
        );
        return None;
    }
    Some(w)
}

fn realistic(ctx: &mut Ctx, name: &Name, p: &ParamList, film: &FilmDesc) -> Option<RealisticDesc> {
    let loc_of = |n: &str| p.get(n).map(|q| q.values_loc).unwrap_or(name.loc);
    let aperture = float(p, "aperturediameter", 1.0) as f32;
    let focus = float(p, "focusdistance", 10.0) as f32;
    let simple_weighting = boolean(p, "simpleweighting", true);
    let Some((file, floc)) = string(p, "lensfile") else {
        ctx.error(
            name.loc,
            "the realistic camera needs a \"string lensfile\" parameter (pbrt-v3: \"No lens description file supplied!\")",
            "no lens file",
            None,
        );
        return None;
    };
    let path = ctx.resolve(floc, file);
    let shown = path.display().to_string();
    let mut ok = true;
    if !(aperture > 0.0 && aperture.is_finite()) {
        ctx.error(loc_of("aperturediameter"), format!("\"aperturediameter\" {aperture} mm must be > 0: no ray could pass the aperture stop"), "bad aperture", None);
        ok = false;
    }
    if !(focus > 0.0 && focus.is_finite()) {
        ctx.error(
            loc_of("focusdistance"),
            format!("\"focusdistance\" {focus} must be > 0"),
            "bad focus distance",
            None,
        );
        ok = false;
    }
    if !(film.diagonal > 0.0 && film.diagonal.is_finite()) {
        ctx.error(
            name.loc,
            format!(
                "the Film's \"diagonal\" {} mm must be > 0 for the realistic camera",
                film.diagonal
            ),
            "film size",
            None,
        );
        ok = false;
    }
    let rows = match ctx.loader.load(&path) {
        Err(e) => {
            ctx.error(
                floc,
                format!("cannot read lens file \"{shown}\": {e}"),
                "lens file not read",
                None,
            );
            return None;
        }
        Ok(bytes) => match parse_lens_file(&String::from_utf8_lossy(&bytes)) {
            Ok(rows) => rows,
            Err(e) => {
                ctx.error(
                    floc,
                    format!("lens file \"{shown}\": {e}"),
                    "bad lens file",
                    None,
                );
                return None;
            }
        },
    };
    if !ok {
        return None;
    }
    if !rows.iter().any(|r| r[0] == 0.0) {
        ctx.warn(
            loc_of("aperturediameter"),
            format!("lens file \"{shown}\" has no aperture stop (a row with radius 0): \"aperturediameter\" has no effect"),
            "no aperture stop",
        );
    }
    match focus_lens(&rows, aperture, focus, film.diagonal) {
        Ok(f) => {
            for w in f.warnings {
                ctx.warn(loc_of("aperturediameter"), w, "aperture clamped");
            }
            Some(RealisticDesc {
                lens_file: path,
                interfaces: f.interfaces,
                simple_weighting,
                focal_length: f.focal_length,
            })
        }
        Err(e) => {
            ctx.error(
                name.loc,
                format!("realistic camera with lens file \"{shown}\": {e}"),
                "lens cannot be used",
                None,
            );
            None
        }
    }
}

/// A lens file in pbrt-v3's format: `#` starts a comment, and each other
/// non-blank line is one interface of four numbers (curvature radius,
/// thickness, index of refraction, aperture diameter; millimetres). pbrt-v3
/// reads the file as one stream of numbers; pbrs insists on one interface
/// per line so that a missing or extra value is caught at its line.
pub fn parse_lens_file(text: &str) -> Result<Vec<[f32; 4]>, String> {
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let data = line.split('#').next().unwrap_or("");
        let fields: Vec<&str> = data.split_whitespace().collect();
        if fields.is_empty() {
            continue;
        }
        if fields.len() != 4 {
            return Err(format!("line {line_no}: {} values, expected 4 (curvature radius, thickness, eta, aperture diameter)", fields.len()));
        }
        let mut row = [0f32; 4];
        for (v, f) in row.iter_mut().zip(&fields) {
            *v = match f.parse::<f32>() {
                Ok(x) if x.is_finite() => x,
                _ => return Err(format!("line {line_no}: \"{f}\" is not a finite number")),
            };
        }
        let [radius, thickness, eta, aperture] = row;
        if thickness < 0.0 {
            return Err(format!("line {line_no}: thickness {thickness} is negative"));
        }
        if aperture <= 0.0 {
            return Err(format!(
                "line {line_no}: aperture diameter {aperture} must be > 0"
            ));
        }
        if radius != 0.0 && eta <= 0.0 {
            return Err(format!("line {line_no}: index of refraction {eta} of a lens interface must be > 0 (only the aperture stop, radius 0, has 0)"));
        }
        if eta < 0.0 {
            return Err(format!(
                "line {line_no}: index of refraction {eta} is negative"
            ));
        }
        if rows.len() == MAX_LENS_INTERFACES {
            return Err(format!("more than {MAX_LENS_INTERFACES} interfaces"));
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err("no lens interface (an empty file, or only comments)".into());
    }
    Ok(rows)
}
