//! Cameras: pbrt-v3's four, one file each, opening with its parameters,
//! and one table, [`CAMERAS`], that the loader (parsing, "did you mean"),
//! `--check`, `grammar/REFERENCE.md` and the tests read. [`Projection`] is
//! the closed set; it only delegates (one `match` per camera ray, no
//! dynamic dispatch). A kind's builder checks its parameters as pbrt-v3
//! does and keeps them; [`Projection::prepare`] derives what depends on the
//! film and the camera transform when the scene is compiled (after the
//! command line has had its say on the film).
//!
//! [`Camera`] is the projection with the shutter: [`Camera::time`] is a
//! sample's ray time (pbrt-v3's `Lerp(sample.time, shutterOpen,
//! shutterClose)`, which the integrators keep for the whole path), and
//! a camera with an animated camera-to-world (pbrt-v3's `CameraToWorld(ray)`
//! with an `AnimatedTransform`) builds its projection in camera space and
//! moves each ray and its differentials by the transform at the ray's time.
//! A still camera keeps the world transform inside the projection, as
//! before: no per-ray transform work. (The identity mapping of a moving
//! camera's projection takes [`world_ray`]'s rounding-bound step too, which
//! moves a lens ray's camera-space origin by γ₃|o| along the ray before the
//! real transform: a few ulps that pbrt-v3, transforming once, does not take;
//! pinhole rays start at the origin and are not moved.)
//!
//! Every camera returns its ray with a weight that the film multiplies the
//! radiance by (pbrt-v3's `GenerateRay` return value): 1 for the projective
//! and environment cameras, the lens weighting for the realistic one, 0 for
//! a sample the lens blocks (its radiance is not computed, but its filter
//! weight still counts, as pbrt-v3).

mod environment;
mod importance;
mod orthographic;
mod perspective;
pub mod realistic;

pub use environment::EnvironmentCamera;
pub use importance::{CameraImportance, ImportanceSample};
pub use orthographic::OrthographicCamera;
pub use perspective::PerspectiveCamera;
pub use realistic::RealisticCamera;

use crate::geometry::{Ray, RayDiff};
use crate::samplers::CameraSample;
use crate::scene::{
    AnimatedTransform, CameraDesc, FilmDesc, Kind, ParamKind, ParamSpec, ParamValues, Range, Report,
};
use glam::{Affine3A, DMat4, Vec2, Vec3};
use std::path::PathBuf;
use std::sync::Arc;

/// Where a camera's builder reads the files its parameters name (the
/// realistic camera's lens file): the loader, which resolves names as
/// pbrt-v3 does and reads each file through its file loader.
pub trait FileSource {
    /// The resolved path of `name` (a value of parameter `param`) and the
    /// file's bytes, or why it cannot be read.
    fn read(&mut self, param: &str, name: &str) -> (PathBuf, Result<Vec<u8>, String>);
}

/// What a camera's builder gets besides its parameters.
pub struct CameraInput<'a> {
    pub film: &'a FilmDesc,
    pub files: &'a mut dyn FileSource,
}

/// What a camera kind builds: its projection, unprepared, or `None` after
/// an error it reported.
pub type CameraBuild = fn(&ParamValues, &mut CameraInput, &mut dyn Report) -> Option<Projection>;

/// One camera kind: its pbrt-v3 name, its parameters, its builder.
pub type CameraKind = Kind<CameraBuild>;

/// Every camera pbrt-v3's `MakeCamera` knows (an unknown one is an error).
pub static CAMERAS: &[CameraKind] = &[
    perspective::KIND,
    orthographic::KIND,
    realistic::KIND,
    environment::KIND,
];

/// Every camera's shutter (read by the loader for all kinds).
pub const SHUTTER: [ParamSpec; 2] = [
    ParamSpec::float(
        "shutteropen",
        0.0,
        "time the shutter opens (the ray time, see `Camera`)",
    ),
    ParamSpec::float("shutterclose", 1.0, "time the shutter closes"),
];

/// The projective cameras' lens and frame parameters.
pub const THIN_LENS: [ParamSpec; 4] = [
    ParamSpec::float(
        "lensradius",
        0.0,
        "thin-lens radius (0: pinhole; negative: warning, pinhole)",
    ),
    ParamSpec::float(
        "focaldistance",
        1e6,
        "distance to the plane in focus (> 0 with a lens)",
    ),
    ParamSpec::float_opt(
        "frameaspectratio",
        "x/y of the screen window (default: the film's; > 0)",
    ),
    ParamSpec {
        name: "screenwindow",
        kind: ParamKind::Floats,
        range: Range::Any,
        doc: "xmin xmax ymin ymax of the screen window (default: the shorter axis spans [-1, 1])",
    },
];

/// `lensradius` and `focaldistance`. A negative radius is a pinhole (pbrt-v3
/// tests `lensRadius > 0`), with a warning; a lens focused at a distance
/// that is not positive is an error (its rays would run backwards or be
/// NaN).
fn thin_lens(p: &ParamValues, r: &mut dyn Report) -> (f32, f32) {
    let default_focus = 1e6;
    let mut lens_radius = p.float("lensradius");
    let mut focal_distance = p.float("focaldistance");
    if !lens_radius.is_finite() || lens_radius < 0.0 {
        r.warn(
            Some("lensradius"),
            format!("\"lensradius\" {lens_radius} is not a radius ≥ 0: a pinhole camera is used"),
            "bad lens radius",
        );
        lens_radius = 0.0;
    }
    if lens_radius > 0.0 && !(focal_distance > 0.0 && focal_distance.is_finite()) {
        r.error(
            Some("focaldistance"),
            format!("\"focaldistance\" {focal_distance} must be > 0 for a lens (\"lensradius\" {lens_radius})"),
            "bad focal distance",
        );
        focal_distance = default_focus;
    }
    (lens_radius, focal_distance)
}

/// `frameaspectratio`, if given and positive (else an error).
fn frame_aspect_ratio(p: &ParamValues, r: &mut dyn Report) -> Option<f32> {
    let v = p.float_opt("frameaspectratio")?;
    if v > 0.0 && v.is_finite() {
        Some(v)
    } else {
        r.error(
            Some("frameaspectratio"),
            format!("\"frameaspectratio\" {v} must be > 0"),
            "bad aspect ratio",
        );
        None
    }
}

/// `screenwindow`, if given as four finite numbers spanning an area (a
/// wrong count is a warning and ignored; an empty window an error).
fn screen_window_param(p: &ParamValues, r: &mut dyn Report) -> Option<[f32; 4]> {
    let v = p.floats("screenwindow");
    if v.is_empty() && !p.has("screenwindow") {
        return None;
    }
    if v.len() != 4 {
        r.warn(
            Some("screenwindow"),
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
        r.error(
            Some("screenwindow"),
            format!("\"screenwindow\" {w:?} is empty or not finite"),
            "bad screen window",
        );
        return None;
    }
    Some(w)
}

/// A camera-space ray (origin `o`, direction `d`) in world space as pbrt-v3's
/// `CameraToWorld(ray)` gives it: the origin transformed, then moved along
/// the direction to the far edge of that transform's rounding bound
/// (γ₃·(|M||o| + |t|), pbrt-v3's `Transform::operator()(Ray)`); the direction
/// transformed and normalised. The move is a few ulps, but the error bounds of
/// the first hit, and so which continuation and shadow rays re-hit a surface
/// computed in f32 (cones, paraboloids, hyperboloids), follow from the
/// origin's bits: without it a quadric scene's shading differed from
/// pbrt-v3's by several per cent near grazing light.
#[inline]
pub fn world_ray(m: &Affine3A, o: Vec3, d: Vec3) -> Ray {
    let wo = m.transform_point3(o);
    let wd = m.transform_vector3(d).normalize();
    let err = Vec3::from(
        (m.matrix3.x_axis * o.x).abs()
            + (m.matrix3.y_axis * o.y).abs()
            + (m.matrix3.z_axis * o.z).abs()
            + m.translation.abs(),
    ) * crate::geometry::gamma(3);
    let dt = wd.abs().dot(err) / wd.length_squared();
    let wo = if dt.is_finite() { wo + wd * dt } else { wo };
    Ray::new(wo, wd)
}

/// A projection with its shutter and, if the camera moves, its motion.
#[derive(Clone, Debug)]
pub struct Camera {
    pub projection: Projection,
    shutter_open: f32,
    shutter_close: f32,
    /// Camera-to-world over time; `projection` is then in camera space.
    motion: Option<Arc<AnimatedTransform>>,
}

/// What a projection derives its mapping from when the scene is compiled.
pub struct Frame {
    /// Camera-to-world (the identity for a moving camera, whose rays are
    /// moved by [`Camera`]).
    pub to_world: Affine3A,
    /// The full film resolution (the crop window does not change the mapping).
    pub resolution: Vec2,
    /// The Film's `diagonal` in millimetres (the realistic camera's sensor).
    pub diagonal_mm: f32,
    pub shutter: (f32, f32),
}

macro_rules! projections {
    ($($variant:ident($ty:ty),)*) => {
        /// A camera's projection; each variant is one file of this module.
        #[derive(Clone, Debug)]
        pub enum Projection {
            $($variant($ty),)*
        }
        impl Projection {
            /// Derives the mapping from the film and the transform.
            pub fn prepare(&mut self, frame: &Frame) {
                match self { $(Projection::$variant(c) => c.prepare(frame),)* }
            }
            /// True if the projection reads the sample's lens position.
            #[inline]
            pub fn uses_lens(&self) -> bool {
                match self { $(Projection::$variant(c) => c.uses_lens(),)* }
            }
            /// The camera ray for a film position (raster coordinates) and
            /// lens sample, and its weight.
            #[inline(always)]
            pub fn generate_ray(&self, cs: &CameraSample) -> (Ray, f32) {
                match self { $(Projection::$variant(c) => c.ray(cs),)* }
            }
            /// `generate_ray` (the same ray and weight) with the
            /// differentials of a one-pixel step in x and y scaled by
            /// `scale` (pbrt-v3 renders with `ScaleDifferentials(1 / √spp)`).
            #[inline]
            pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff, f32) {
                match self { $(Projection::$variant(c) => c.ray_differential(cs, scale),)* }
            }
            /// Its kind and settings, for `--check` and `--stats`.
            pub fn describe(&self) -> String {
                match self { $(Projection::$variant(c) => c.describe(),)* }
            }
        }
    };
}

projections! {
    Perspective(PerspectiveCamera),
    Orthographic(OrthographicCamera),
    Environment(EnvironmentCamera),
    Realistic(RealisticCamera),
}

impl Projection {
    /// pbrt-v3's name of its kind.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Projection::Perspective(_) => perspective::KIND.name,
            Projection::Orthographic(_) => orthographic::KIND.name,
            Projection::Environment(_) => environment::KIND.name,
            Projection::Realistic(_) => realistic::KIND.name,
        }
    }
}

impl Default for Projection {
    /// pbrt-v3's camera when the scene names none: a perspective pinhole
    /// with a 90° field of view.
    fn default() -> Projection {
        Projection::Perspective(PerspectiveCamera::with(90.0, 0.0, 1e6, None, None))
    }
}

/// pbrt-v3's default screen window for a frame aspect ratio: the shorter
/// image axis spans [-1, 1].
fn screen_window(window: Option<[f32; 4]>, frame: Option<f32>, resolution: Vec2) -> [f32; 4] {
    let frame = frame.unwrap_or(resolution.x / resolution.y);
    window.unwrap_or(if frame > 1.0 {
        [-frame, frame, -1.0, 1.0]
    } else {
        [-1.0, 1.0, -1.0 / frame, 1.0 / frame]
    })
}

impl Camera {
    /// The camera for `desc` on `film` (the full resolution: the crop window
    /// does not change the mapping).
    pub fn new(desc: &CameraDesc, film: &FilmDesc) -> Camera {
        let motion = desc.motion.clone();
        let to_world = match motion {
            Some(_) => DMat4::IDENTITY,
            None => desc.camera_to_world,
        };
        let mut projection = desc.projection.clone();
        projection.prepare(&Frame {
            to_world: Affine3A::from_mat4(to_world.as_mat4()),
            resolution: Vec2::new(film.xresolution as f32, film.yresolution as f32),
            diagonal_mm: film.diagonal,
            shutter: (desc.shutter_open, desc.shutter_close),
        });
        Camera {
            projection,
            shutter_open: desc.shutter_open,
            shutter_close: desc.shutter_close,
            motion,
        }
    }

    /// A still camera with the shutter open over [0, 1].
    pub fn still(projection: Projection) -> Camera {
        Camera {
            projection,
            shutter_open: 0.0,
            shutter_close: 1.0,
            motion: None,
        }
    }

    /// True if the camera-to-world transform is animated.
    pub fn is_moving(&self) -> bool {
        self.motion.is_some()
    }

    /// True if the camera reads the sample's lens position.
    #[inline]
    pub fn uses_lens(&self) -> bool {
        self.projection.uses_lens()
    }

    /// pbrt-v3's ray time: the sample's time in [0, 1) mapped to the shutter.
    #[inline(always)]
    pub fn time(&self, cs: &CameraSample) -> f32 {
        let (a, b) = (self.shutter_open, self.shutter_close);
        (1.0 - cs.time) * a + cs.time * b
    }

    /// The camera ray for a film position (raster coordinates), lens sample
    /// and time sample (at [`Camera::time`]), and its weight.
    #[inline(always)]
    pub fn generate_ray(&self, cs: &CameraSample) -> (Ray, f32) {
        let (ray, w) = self.projection.generate_ray(cs);
        match &self.motion {
            None => (ray, w),
            Some(m) => (move_ray(&at(m, self.time(cs)), &ray), w),
        }
    }

    /// `generate_ray` (the same ray and weight) with the differentials of a
    /// one-pixel step in x and y scaled by `scale`.
    #[inline]
    pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff, f32) {
        let (ray, d, w) = self.projection.generate_ray_differential(cs, scale);
        match &self.motion {
            None => (ray, d, w),
            Some(m) => {
                let to_world = at(m, self.time(cs));
                let o = |p: Vec3| to_world.transform_point3(p);
                let v = |v: Vec3| to_world.transform_vector3(v);
                let diff = RayDiff {
                    rx_o: o(d.rx_o),
                    rx_d: v(d.rx_d).normalize(),
                    ry_o: o(d.ry_o),
                    ry_d: v(d.ry_d).normalize(),
                };
                (move_ray(&to_world, &ray), diff, w)
            }
        }
    }
}

/// The camera-to-world transform at `time`, in f32 as a still camera's.
#[inline]
fn at(m: &AnimatedTransform, time: f32) -> Affine3A {
    Affine3A::from_mat4(m.interpolate(time as f64).as_mat4())
}

/// A camera-space ray in world space by the camera-to-world transform at
/// its time, as [`world_ray`] maps a still camera's (pbrt-v3's
/// `AnimatedTransform::operator()(Ray)`: interpolate, then transform).
#[inline]
fn move_ray(to_world: &Affine3A, r: &Ray) -> Ray {
    Ray {
        t_max: r.t_max,
        ..world_ray(to_world, r.o, r.d)
    }
}

/// pbrt-v3's base `Camera::GenerateRayDifferential`: each offset ray is the
/// ray of the film position shifted by 0.05 pixel (or by −0.05 if that one
/// is blocked), extrapolated to a whole pixel. `None` if both shifts of an
/// axis are blocked.
#[inline]
fn finite_differences(
    cs: &CameraSample,
    ray: &Ray,
    gen: impl Fn(&CameraSample) -> Option<Ray>,
) -> Option<RayDiff> {
    let shifted = |step: Vec2| {
        [0.05f32, -0.05].into_iter().find_map(|eps| {
            let s = CameraSample {
                p_film: cs.p_film + step * eps,
                ..*cs
            };
            gen(&s).map(|r| (ray.o + (r.o - ray.o) / eps, ray.d + (r.d - ray.d) / eps))
        })
    };
    let (rx_o, rx_d) = shifted(Vec2::X)?;
    let (ry_o, ry_d) = shifted(Vec2::Y)?;
    Some(RayDiff {
        rx_o,
        rx_d,
        ry_o,
        ry_d,
    })
}
