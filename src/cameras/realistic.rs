//! The realistic camera (pbrt-v3's `RealisticCamera`): rays from the film
//! traced through a system of spherical lens interfaces and an aperture stop,
//! read from a lens file. The film (size from the Film's `diagonal`, in mm)
//! sits at camera-space z = 0 and the lens system in front of it along +z;
//! a film position maps to the physical film point mirrored in x (the lens
//! flips the image back). A lens point is sampled in the exit pupil's
//! bounds for the film point's distance from the centre (64 radial bounds,
//! found as pbrt-v3 does by tracing 2²⁰ rays per bound), rotated to the film
//! point's angle. A ray the lens blocks is a zero-weight sample. The sample
//! weight is cos⁴θ of the film-to-lens direction times the pupil bounds'
//! area, over the centre bounds' area (`simpleweighting`, pbrt-v3's default)
//! or over the squared rear-element distance times the shutter interval.
//! Ray differentials as pbrt-v3's base `Camera::GenerateRayDifferential`:
//! finite differences over ±0.05 pixel, and a sample whose shifted rays
//! are all blocked gets weight zero.
//!
//! Focusing is pbrt-v3's thick-lens approximation: the focal and principal
//! planes found by tracing one paraxial ray each way, then the rear
//! thickness moved so that `focusdistance` (from the film) is in focus.
//! pbrt-v3 also runs a binary search on the traced focus but only logs its
//! result; pbrs does not run it.
//!
//! Parameters: [`PARAMS`] (shown in `grammar/REFERENCE.md`).
//!
//! Lens file: rows of curvature radius (0 for the aperture stop), thickness
//! to the next interface, index of refraction behind the interface (0 or 1
//! for air) and aperture diameter, all lengths in millimetres, from the
//! scene side to the film side; `#` starts a comment.

use super::{finite_differences, CameraInput, CameraKind, Frame, Projection, SHUTTER};
use crate::geometry::{Ray, RayDiff};
use crate::samplers::lowdiscrepancy::{radical_inverse, radical_inverse_base2, DigitBase};
use crate::samplers::CameraSample;
use crate::scene::{ParamSpec, ParamValues, Report, Support};
use glam::{Affine3A, Vec2, Vec3};
use rayon::prelude::*;
use std::path::PathBuf;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::filename(
        "lensfile",
        "the lens description (required; relative to the top-level scene file)",
    ),
    ParamSpec::float(
        "aperturediameter",
        1.0,
        "aperture stop diameter in mm (clamped to the stop's diameter in the file)",
    ),
    ParamSpec::float(
        "focusdistance",
        10.0,
        "distance from the film in focus, scene units",
    ),
    ParamSpec::boolean(
        "simpleweighting",
        true,
        "cos⁴ weighting over the centre's pupil area (false: the physical weight)",
    ),
    SHUTTER[0],
    SHUTTER[1],
];

pub const KIND: CameraKind = CameraKind {
    name: "realistic",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "rays traced through the spherical lens interfaces and aperture stop of a lens file, focused by the thick-lens approximation",
    build: |p, input, r| build(p, input, r).map(Projection::Realistic),
};

/// More rows than any real lens system has; bounds the per-ray tracing cost.
pub const MAX_LENS_INTERFACES: usize = 256;

/// One row of a lens file in pbrt-v3's lens-system space (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensInterface {
    /// Signed radius of the spherical interface; 0 for the aperture stop.
    pub curvature_radius: f32,
    /// Distance along the axis to the next interface (to the film for the
    /// last one).
    pub thickness: f32,
    /// Index of refraction of the medium behind this interface (towards the
    /// film); 0 (the stop) and 1 are air.
    pub eta: f32,
    pub aperture_radius: f32,
}

/// The lens system of the `lensfile`, focused at `focusdistance` for the
/// Film's `diagonal` (pbrt-v3 focuses when the camera is created), with
/// pbrt-v3's checks as located errors.
fn build(p: &ParamValues, input: &mut CameraInput, r: &mut dyn Report) -> Option<RealisticCamera> {
    let aperture = p.float("aperturediameter");
    let focus = p.float("focusdistance");
    let simple_weighting = p.boolean("simpleweighting");
    let file = p.string("lensfile");
    if file.is_empty() {
        r.error(
            None,
            "the realistic camera needs a \"string lensfile\" parameter (pbrt-v3: \"No lens description file supplied!\")".into(),
            "no lens file",
        );
        return None;
    }
    let (path, bytes) = input.files.read("lensfile", file);
    let shown = path.display().to_string();
    let mut ok = true;
    if !(aperture > 0.0 && aperture.is_finite()) {
        r.error(Some("aperturediameter"), format!("\"aperturediameter\" {aperture} mm must be > 0: no ray could pass the aperture stop"), "bad aperture");
        ok = false;
    }
    if !(focus > 0.0 && focus.is_finite()) {
        r.error(
            Some("focusdistance"),
            format!("\"focusdistance\" {focus} must be > 0"),
            "bad focus distance",
        );
        ok = false;
    }
    let diagonal = input.film.diagonal;
    if !(diagonal > 0.0 && diagonal.is_finite()) {
        r.error(
            None,
            format!("the Film's \"diagonal\" {diagonal} mm must be > 0 for the realistic camera"),
            "film size",
        );
        ok = false;
    }
    let rows = match bytes {
        Err(e) => {
            r.error(
                Some("lensfile"),
                format!("cannot read lens file \"{shown}\": {e}"),
                "lens file not read",
            );
            return None;
        }
        Ok(bytes) => match parse_lens_file(&String::from_utf8_lossy(&bytes)) {
            Ok(rows) => rows,
            Err(e) => {
                r.error(
                    Some("lensfile"),
                    format!("lens file \"{shown}\": {e}"),
                    "bad lens file",
                );
                return None;
            }
        },
    };
    if !ok {
        return None;
    }
    if !rows.iter().any(|r| r[0] == 0.0) {
        r.warn(
            Some("aperturediameter"),
            format!("lens file \"{shown}\" has no aperture stop (a row with radius 0): \"aperturediameter\" has no effect"),
            "no aperture stop",
        );
    }
    match focus_lens(&rows, aperture, focus, diagonal) {
        Ok(f) => {
            for w in f.warnings {
                r.warn(Some("aperturediameter"), w, "aperture clamped");
            }
            Some(RealisticCamera::with(
                path,
                f.interfaces,
                simple_weighting,
                f.focal_length,
            ))
        }
        Err(e) => {
            r.error(
                None,
                format!("realistic camera with lens file \"{shown}\": {e}"),
                "lens cannot be used",
            );
            None
        }
    }
}

/// Radial exit-pupil bounds over the film's half diagonal (pbrt-v3's count).
pub const EXIT_PUPIL_BOUNDS: usize = 64;
/// Rays traced per bound (pbrt-v3's count).
const PUPIL_SAMPLES: u32 = 1 << 20;

/// An axis-aligned rectangle on the rear-element plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds2 {
    pub min: Vec2,
    pub max: Vec2,
}

impl Bounds2 {
    const EMPTY: Bounds2 = Bounds2 {
        min: Vec2::splat(f32::MAX),
        max: Vec2::splat(f32::MIN),
    };

    pub fn area(&self) -> f32 {
        let d = self.max - self.min;
        d.x * d.y
    }

    pub fn contains(&self, p: Vec2) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    fn lerp(&self, t: Vec2) -> Vec2 {
        (Vec2::ONE - t) * self.min + t * self.max
    }
}

/// A ray in lens or camera space during tracing (direction not normalised).
#[derive(Clone, Copy, Debug)]
pub struct LensRay {
    pub o: Vec3,
    pub d: Vec3,
}

impl LensRay {
    fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
    /// Camera space ↔ lens-system space (the lens system looks along −z).
    fn flip_z(self) -> LensRay {
        LensRay {
            o: self.o * Vec3::new(1.0, 1.0, -1.0),
            d: self.d * Vec3::new(1.0, 1.0, -1.0),
        }
    }
}

/// The lens interfaces and the operations on them (no film, no transform).
#[derive(Clone, Debug)]
pub struct LensSystem {
    pub interfaces: Vec<LensInterface>,
}

/// The outcome of [`focus_lens`].
#[derive(Clone, Debug)]
pub struct FocusedLens {
    pub interfaces: Vec<LensInterface>,
    /// Effective focal length (thick-lens approximation), metres.
    pub focal_length: f32,
    pub warnings: Vec<String>,
}

/// pbrt-v3's `Quadratic`: discriminant in f64, roots in the stable form.
fn quadratic(a: f32, b: f32, c: f32) -> Option<(f32, f32)> {
    let discrim = b as f64 * b as f64 - 4.0 * a as f64 * c as f64;
    if discrim < 0.0 {
        return None;
    }
    let root = discrim.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b as f64 - root)
    } else {
        -0.5 * (b as f64 + root)
    };
    let t0 = (q / a as f64) as f32;
    let t1 = (c as f64 / q) as f32;
    Some(if t0 > t1 { (t1, t0) } else { (t0, t1) })
}

/// Refraction of the unit direction `wi` (pointing away from the surface)
/// about `n` (on the side of `wi`), `eta` = ηi/ηt; `None` on total internal
/// reflection.
fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = n.dot(wi);
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = eta * eta * sin2_i;
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(eta * -wi + (eta * cos_i - cos_t) * n)
}

/// Hit of a ray with a spherical interface of signed `radius` centred on
/// the axis at `z_center`: the distance and the normal facing the ray.
fn intersect_spherical(radius: f32, z_center: f32, r: &LensRay) -> Option<(f32, Vec3)> {
    let o = r.o - Vec3::new(0.0, 0.0, z_center);
    let a = r.d.length_squared();
    let b = 2.0 * r.d.dot(o);
    let c = o.length_squared() - radius * radius;
    let (t0, t1) = quadratic(a, b, c)?;
    // The interface is the half of the sphere facing the film or the scene,
    // by the sign of the radius; which root that is depends on the ray.
    let closer = (r.d.z > 0.0) ^ (radius < 0.0);
    let t = if closer { t0.min(t1) } else { t0.max(t1) };
    if !(t.is_finite() && t >= 0.0) {
        return None;
    }
    let n = (o + t * r.d).normalize();
    let n = if n.dot(-r.d) < 0.0 { -n } else { n };
    Some((t, n))
}

/// True if `p` is outside the interface's aperture (or NaN).
#[inline]
fn blocked_by_aperture(p: Vec3, radius: f32) -> bool {
    let r2 = p.x * p.x + p.y * p.y;
    r2.is_nan() || r2 > radius * radius
}

impl LensSystem {
    /// Distance from the film to the rear interface.
    pub fn rear_z(&self) -> f32 {
        self.interfaces.last().map_or(0.0, |e| e.thickness)
    }

    /// Distance from the film to the front interface.
    pub fn front_z(&self) -> f32 {
        self.interfaces.iter().map(|e| e.thickness).sum()
    }

    pub fn rear_radius(&self) -> f32 {
        self.interfaces.last().map_or(0.0, |e| e.aperture_radius)
    }

    /// A camera-space ray from the film side traced out of the front
    /// element, or `None` if an interface or the stop blocks it.
    pub fn trace_from_film(&self, r: LensRay) -> Option<LensRay> {
        let mut ray = r.flip_z();
        let mut z = 0.0;
        for i in (0..self.interfaces.len()).rev() {
            let e = &self.interfaces[i];
            z -= e.thickness;
            let stop = e.curvature_radius == 0.0;
            let (t, n) = if stop {
                // A ray turned back towards the film by an earlier interface
                // never reaches the stop.
                if ray.d.z >= 0.0 {
                    return None;
                }
                ((z - ray.o.z) / ray.d.z, Vec3::ZERO)
            } else {
                intersect_spherical(e.curvature_radius, z + e.curvature_radius, &ray)?
            };
            let p = ray.at(t);
            if blocked_by_aperture(p, e.aperture_radius) {
                return None;
            }
            ray.o = p;
            if !stop {
                let eta_t = match i.checked_sub(1).map(|j| self.interfaces[j].eta) {
                    Some(eta) if eta != 0.0 => eta,
                    _ => 1.0,
                };
                ray.d = refract((-ray.d).normalize(), n, e.eta / eta_t)?;
            }
        }
        Some(ray.flip_z())
    }

    /// A camera-space ray from the scene side traced out of the rear
    /// element, or `None` if blocked.
    pub fn trace_from_scene(&self, r: LensRay) -> Option<LensRay> {
        let mut ray = r.flip_z();
        let mut z = -self.front_z();
        for (i, e) in self.interfaces.iter().enumerate() {
            let stop = e.curvature_radius == 0.0;
            let (t, n) = if stop {
                let t = (z - ray.o.z) / ray.d.z;
                // pbrt-v3 asserts here; a ray that does not reach the stop
                // is blocked.
                if !(t.is_finite() && t >= 0.0) {
                    return None;
                }
                (t, Vec3::ZERO)
            } else {
                intersect_spherical(e.curvature_radius, z + e.curvature_radius, &ray)?
            };
            let p = ray.at(t);
            if blocked_by_aperture(p, e.aperture_radius) {
                return None;
            }
            ray.o = p;
            if !stop {
                let eta_i = match i.checked_sub(1).map(|j| self.interfaces[j].eta) {
                    Some(eta) if eta != 0.0 => eta,
                    _ => 1.0,
                };
                let eta_t = if e.eta != 0.0 { e.eta } else { 1.0 };
                ray.d = refract((-ray.d).normalize(), n, eta_i / eta_t)?;
            }
            z += e.thickness;
        }
        Some(ray.flip_z())
    }

    /// pbrt-v3's thick-lens approximation: the principal planes `pz` and
    /// focal points `fz` (z from the film) for the film side ([0]) and the
    /// scene side ([1]), from rays parallel to the axis at height `x`.
    pub fn thick_lens(&self, x: f32) -> Option<([f32; 2], [f32; 2])> {
        let cardinal = |r_in: LensRay, r_out: LensRay| {
            let tf = -r_out.o.x / r_out.d.x;
            let fz = -r_out.at(tf).z;
            let tp = (r_in.o.x - r_out.o.x) / r_out.d.x;
            let pz = -r_out.at(tp).z;
            (pz, fz)
        };
        let from_scene = LensRay {
            o: Vec3::new(x, 0.0, self.front_z() + 1.0),
            d: Vec3::new(0.0, 0.0, -1.0),
        };
        let (p0, f0) = cardinal(from_scene, self.trace_from_scene(from_scene)?);
        let from_film = LensRay {
            o: Vec3::new(x, 0.0, self.rear_z() - 1.0),
            d: Vec3::Z,
        };
        let (p1, f1) = cardinal(from_film, self.trace_from_film(from_film)?);
        let all = [p0, f0, p1, f1];
        all.iter()
            .all(|v| v.is_finite())
            .then_some(([p0, p1], [f0, f1]))
    }

    /// pbrt-v3's `BoundExitPupil`: the bounds on the rear-element plane of
    /// the points through which rays from the film segment [x0, x1] on the
    /// x axis get through the lens, grown by the sample spacing; the rear
    /// element's bounds if none does.
    pub fn bound_exit_pupil(&self, x0: f32, x1: f32) -> Bounds2 {
        let r = 1.5 * self.rear_radius();
        let rear = Bounds2 {
            min: Vec2::splat(-r),
            max: Vec2::splat(r),
        };
        let rear_z = self.rear_z();
        let base3 = DigitBase::new(3);
        let mut b = Bounds2::EMPTY;
        let mut exiting = false;
        for i in 0..PUPIL_SAMPLES {
            let t = (i as f32 + 0.5) / PUPIL_SAMPLES as f32;
            let p_film = Vec3::new((1.0 - t) * x0 + t * x1, 0.0, 0.0);
            let u = Vec2::new(
                radical_inverse_base2(i as u64),
                radical_inverse(&base3, i as u64),
            );
            let p = rear.lerp(u);
            // Points inside the bounds so far cannot grow them: not traced.
            if b.contains(p)
                || self
                    .trace_from_film(LensRay {
                        o: p_film,
                        d: Vec3::new(p.x, p.y, rear_z) - p_film,
                    })
                    .is_some()
            {
                b.min = b.min.min(p);
                b.max = b.max.max(p);
                exiting = true;
            }
        }
        if !exiting {
            return rear;
        }
        let grow = 2.0 * (rear.max - rear.min).length() / (PUPIL_SAMPLES as f32).sqrt();
        Bounds2 {
            min: b.min - Vec2::splat(grow),
            max: b.max + Vec2::splat(grow),
        }
    }
}

/// Builds the lens system of a lens file's rows (millimetres) as pbrt-v3's
/// `RealisticCamera` constructor does: the stop's diameter becomes
/// `aperture_diameter` (clamped, with a warning, to the file's), then the
/// rear thickness is set so that `focus_distance` is in focus. Errors are
/// the cases where pbrt-v3 stops on a failed check: no paraxial ray gets
/// through, or the lens cannot focus that close.
pub fn focus_lens(
    rows: &[[f32; 4]],
    aperture_diameter: f32,
    focus_distance: f32,
    film_diagonal_mm: f32,
) -> Result<FocusedLens, String> {
    let mut warnings = Vec::new();
    let mut interfaces = Vec::with_capacity(rows.len());
    for row in rows {
        let mut ap = row[3];
        if row[0] == 0.0 {
            if aperture_diameter > row[3] {
                warnings.push(format!("\"aperturediameter\" {aperture_diameter} mm is larger than the lens file's aperture stop ({} mm): clamped (as pbrt-v3)", row[3]));
            } else {
                ap = aperture_diameter;
            }
        }
        interfaces.push(LensInterface {
            curvature_radius: row[0] * 0.001,
            thickness: row[1] * 0.001,
            eta: row[2],
            aperture_radius: ap * 0.001 / 2.0,
        });
    }
    let mut lens = LensSystem { interfaces };
    let x = 0.001 * film_diagonal_mm * 0.001;
    let Some((pz, fz)) = lens.thick_lens(x) else {
        return Err("no ray parallel to the axis gets through the lens system (is the aperture stop too small?), so it cannot be focused".into());
    };
    let f = fz[0] - pz[0];
    let z = -focus_distance;
    let c = (pz[1] - z - pz[0]) * (pz[1] - z - 4.0 * f - pz[0]);
    let delta = 0.5 * (pz[1] - z + pz[0] - c.sqrt());
    let rear = lens.rear_z() + delta;
    if !(c > 0.0 && rear > 0.0 && rear.is_finite()) {
        return Err(format!(
            "the lens system (focal length {:.2} mm) cannot focus at \"focusdistance\" {focus_distance}: it is too close",
            f * 1000.0
        ));
    }
    if let Some(last) = lens.interfaces.last_mut() {
        last.thickness = rear;
    }
    Ok(FocusedLens {
        interfaces: lens.interfaces,
        focal_length: f,
        warnings,
    })
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

#[derive(Clone, Debug)]
pub struct RealisticCamera {
    /// The lens file as resolved (for messages and `--check`).
    pub lens_file: PathBuf,
    pub simple_weighting: bool,
    /// Effective focal length of the lens system (thick-lens approximation),
    /// in metres.
    pub focal_length: f32,
    camera_to_world: Affine3A,
    pub lens: LensSystem,
    /// Exit-pupil bounds for film radii [i, i+1)·(diagonal/2)/64.
    pub exit_pupil: Vec<Bounds2>,
    resolution: Vec2,
    /// Half the physical film size (metres).
    half_extent: Vec2,
    /// Half the film diagonal (metres).
    half_diagonal: f32,
    /// The weight's constant factor: 1 / (centre bounds' area) for simple
    /// weighting, shutter interval / rear distance² otherwise.
    weight_scale: f32,
}

impl RealisticCamera {
    /// The focused lens system as the builder made it;
    /// [`RealisticCamera::prepare`] bounds its exit pupil for the film.
    pub fn with(
        lens_file: PathBuf,
        interfaces: Vec<LensInterface>,
        simple_weighting: bool,
        focal_length: f32,
    ) -> RealisticCamera {
        RealisticCamera {
            lens_file,
            simple_weighting,
            focal_length,
            camera_to_world: Affine3A::IDENTITY,
            lens: LensSystem { interfaces },
            exit_pupil: Vec::new(),
            resolution: Vec2::ONE,
            half_extent: Vec2::ZERO,
            half_diagonal: 0.0,
            weight_scale: 0.0,
        }
    }

    pub fn prepare(&mut self, f: &Frame) {
        *self = RealisticCamera::new(self, f.to_world, f.resolution, f.diagonal_mm, f.shutter);
    }

    pub fn describe(&self) -> String {
        format!(
            "realistic, lens \"{}\" ({} interfaces, focal length {:.1} mm)",
            self.lens_file.display(),
            self.lens.interfaces.len(),
            self.focal_length * 1000.0
        )
    }

    pub fn uses_lens(&self) -> bool {
        true
    }

    /// The ray and its weight (which depends on the shifted rays too).
    #[inline(always)]
    pub fn ray(&self, cs: &CameraSample) -> (Ray, f32) {
        let (ray, _, w) = self.generate_ray_differential(cs, 1.0);
        (ray, w)
    }

    #[inline]
    pub fn ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff, f32) {
        self.generate_ray_differential(cs, scale)
    }

    fn new(
        unprepared: &RealisticCamera,
        camera_to_world: Affine3A,
        resolution: Vec2,
        film_diagonal_mm: f32,
        shutter: (f32, f32),
    ) -> RealisticCamera {
        let lens = unprepared.lens.clone();
        let diagonal = film_diagonal_mm * 0.001;
        let n = EXIT_PUPIL_BOUNDS;
        let exit_pupil: Vec<Bounds2> = (0..n)
            .into_par_iter()
            .map(|i| {
                let r0 = i as f32 / n as f32 * diagonal / 2.0;
                let r1 = (i + 1) as f32 / n as f32 * diagonal / 2.0;
                lens.bound_exit_pupil(r0, r1)
            })
            .collect();
        let aspect = resolution.y / resolution.x;
        let x = (diagonal * diagonal / (1.0 + aspect * aspect)).sqrt();
        let rear = lens.rear_z();
        let weight_scale = if unprepared.simple_weighting {
            1.0 / exit_pupil[0].area()
        } else {
            (shutter.1 - shutter.0) / (rear * rear)
        };
        RealisticCamera {
            lens_file: unprepared.lens_file.clone(),
            simple_weighting: unprepared.simple_weighting,
            focal_length: unprepared.focal_length,
            camera_to_world,
            lens,
            exit_pupil,
            resolution,
            half_extent: Vec2::new(x / 2.0, aspect * x / 2.0),
            half_diagonal: diagonal / 2.0,
            weight_scale,
        }
    }

    /// The camera-space film point of a raster position (mirrored in x).
    #[inline]
    pub fn film_point(&self, p_raster: Vec2) -> Vec3 {
        let s = p_raster / self.resolution;
        let p = (Vec2::ONE - s) * -self.half_extent + s * self.half_extent;
        Vec3::new(-p.x, p.y, 0.0)
    }

    /// The exit-pupil bounds used for a film point.
    #[inline]
    pub fn pupil_bounds(&self, p_film: Vec2) -> &Bounds2 {
        let r = p_film.length();
        let i = ((r / self.half_diagonal * self.exit_pupil.len() as f32) as usize)
            .min(self.exit_pupil.len() - 1);
        &self.exit_pupil[i]
    }

    /// A point on the rear plane in the film point's pupil bounds, rotated
    /// from the +x axis to the film point's angle, and the bounds' area.
    #[inline]
    fn sample_exit_pupil(&self, p_film: Vec2, u: Vec2) -> (Vec3, f32) {
        let b = self.pupil_bounds(p_film);
        let p = b.lerp(u);
        let r = p_film.length();
        let (sin, cos) = if r != 0.0 {
            (p_film.y / r, p_film.x / r)
        } else {
            (0.0, 1.0)
        };
        (
            Vec3::new(
                cos * p.x - sin * p.y,
                sin * p.x + cos * p.y,
                self.lens.rear_z(),
            ),
            b.area(),
        )
    }

    /// The world-space ray and its weight, or `None` if the lens blocks it.
    #[inline]
    fn traced_ray(&self, cs: &CameraSample) -> Option<(Ray, f32)> {
        let p_film = self.film_point(cs.p_film);
        let (p_rear, area) = self.sample_exit_pupil(p_film.truncate(), cs.p_lens);
        let r_film = LensRay {
            o: p_film,
            d: p_rear - p_film,
        };
        let out = self.lens.trace_from_film(r_film)?;
        let ray = super::world_ray(&self.camera_to_world, out.o, out.d);
        if !ray.o.is_finite() || !ray.d.is_finite() {
            return None;
        }
        let cos = r_film.d.normalize().z;
        let cos4 = (cos * cos) * (cos * cos);
        Some((ray, cos4 * area * self.weight_scale))
    }

    /// The ray, its differentials (scaled by `scale`) and its weight; weight
    /// zero if the lens blocks the ray or every shifted ray of an axis (as
    /// pbrt-v3, whose integrators always ask for differentials).
    #[inline]
    pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff, f32) {
        // A placeholder ray for a zero-weight sample (never traced).
        let blocked = || {
            let r = Ray::new(self.camera_to_world.transform_point3(Vec3::ZERO), Vec3::Z);
            (r, RayDiff::none(&r), 0.0)
        };
        let Some((ray, w)) = self.traced_ray(cs) else {
            return blocked();
        };
        match finite_differences(cs, &ray, |s| self.traced_ray(s).map(|(r, _)| r)) {
            Some(d) => (ray, d.scaled(&ray, scale), w),
            None => blocked(),
        }
    }
}
