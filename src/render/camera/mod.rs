//! Cameras: pbrt-v3's four, one file each, behind a closed enum that only
//! delegates (one `match` per camera ray, no dynamic dispatch).
//!
//! [`Camera`] is the projection with the shutter: it stamps each ray with
//! its time (pbrt-v3's `Lerp(sample.time, shutterOpen, shutterClose)`), and
//! a camera with an animated camera-to-world (pbrt-v3's `CameraToWorld(ray)`
//! with an `AnimatedTransform`) builds its projection in camera space and
//! moves each ray and its differentials by the transform at the ray's time.
//! A still camera keeps the world transform inside the projection, as
//! before: no per-ray transform work.
//!
//! Every camera returns its ray with a weight that the film multiplies the
//! radiance by (pbrt-v3's `GenerateRay` return value): 1 for the projective
//! and environment cameras, the lens weighting for the realistic one, 0 for
//! a sample the lens blocks (its radiance is not computed, but its filter
//! weight still counts, as pbrt-v3).

mod environment;
mod orthographic;
mod perspective;
pub mod realistic;

pub use environment::EnvironmentCamera;
pub use orthographic::OrthographicCamera;
pub use perspective::PerspectiveCamera;
pub use realistic::RealisticCamera;

use crate::render::geometry::{Ray, RayDiff};
use crate::render::samplers::CameraSample;
use crate::scene::{AnimatedTransform, CameraDesc, CameraKind, FilmDesc};
use glam::{Affine3A, DMat4, Vec2, Vec3};
use std::sync::Arc;

/// A projection with its shutter and, if the camera moves, its motion.
#[derive(Clone, Debug)]
pub struct Camera {
    pub projection: Projection,
    shutter_open: f32,
    shutter_close: f32,
    /// Camera-to-world over time; `projection` is then in camera space.
    motion: Option<Arc<AnimatedTransform>>,
}

#[derive(Clone, Debug)]
pub enum Projection {
    Perspective(PerspectiveCamera),
    Orthographic(OrthographicCamera),
    Environment(EnvironmentCamera),
    Realistic(RealisticCamera),
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
        Camera {
            projection: Projection::new(desc, film, to_world),
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
    fn time(&self, cs: &CameraSample) -> f32 {
        let (a, b) = (self.shutter_open, self.shutter_close);
        (1.0 - cs.time) * a + cs.time * b
    }

    /// The camera ray for a film position (raster coordinates), lens sample
    /// and time sample, and its weight.
    #[inline]
    pub fn generate_ray(&self, cs: &CameraSample) -> (Ray, f32) {
        let time = self.time(cs);
        let (ray, w) = self.projection.generate_ray(cs);
        match &self.motion {
            None => (ray.with_time(time), w),
            Some(m) => (
                move_ray(&m.interpolate(time as f64), &ray).with_time(time),
                w,
            ),
        }
    }

    /// `generate_ray` (the same ray and weight) with the differentials of a
    /// one-pixel step in x and y scaled by `scale`.
    #[inline]
    pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff, f32) {
        let time = self.time(cs);
        let (ray, d, w) = self.projection.generate_ray_differential(cs, scale);
        match &self.motion {
            None => (ray.with_time(time), d, w),
            Some(m) => {
                let to_world = m.interpolate(time as f64);
                let o = |p: Vec3| to_world.transform_point3(p.as_dvec3()).as_vec3();
                let v = |v: Vec3| to_world.transform_vector3(v.as_dvec3()).as_vec3();
                let diff = RayDiff {
                    rx_o: o(d.rx_o),
                    rx_d: v(d.rx_d).normalize(),
                    ry_o: o(d.ry_o),
                    ry_d: v(d.ry_d).normalize(),
                };
                (move_ray(&to_world, &ray).with_time(time), diff, w)
            }
        }
    }
}

/// A camera-space ray in world space (the direction renormalised, as the
/// still cameras do after their transform).
#[inline]
fn move_ray(to_world: &DMat4, r: &Ray) -> Ray {
    Ray {
        o: to_world.transform_point3(r.o.as_dvec3()).as_vec3(),
        d: to_world
            .transform_vector3(r.d.as_dvec3())
            .as_vec3()
            .normalize(),
        ..*r
    }
}

impl Projection {
    fn new(desc: &CameraDesc, film: &FilmDesc, to_world: DMat4) -> Projection {
        let resolution = Vec2::new(film.xresolution as f32, film.yresolution as f32);
        let to_world = Affine3A::from_mat4(to_world.as_mat4());
        match &desc.kind {
            &CameraKind::Perspective {
                fov,
                lens_radius,
                focal_distance,
                frame_aspect_ratio,
                screen_window: window,
            } => Projection::Perspective(PerspectiveCamera::new(
                to_world,
                fov,
                lens_radius,
                focal_distance,
                screen_window(window, frame_aspect_ratio, resolution),
                resolution,
            )),
            &CameraKind::Orthographic {
                lens_radius,
                focal_distance,
                frame_aspect_ratio,
                screen_window: window,
            } => Projection::Orthographic(OrthographicCamera::new(
                to_world,
                lens_radius,
                focal_distance,
                screen_window(window, frame_aspect_ratio, resolution),
                resolution,
            )),
            CameraKind::Environment => {
                Projection::Environment(EnvironmentCamera::new(to_world, resolution))
            }
            CameraKind::Realistic(r) => Projection::Realistic(RealisticCamera::new(
                to_world,
                r,
                resolution,
                film.diagonal,
                (desc.shutter_open, desc.shutter_close),
            )),
        }
    }

    /// True if the projection reads the sample's lens position.
    #[inline]
    pub fn uses_lens(&self) -> bool {
        match self {
            Projection::Perspective(c) => c.uses_lens(),
            Projection::Orthographic(c) => c.uses_lens(),
            Projection::Environment(_) => false,
            Projection::Realistic(_) => true,
        }
    }

    /// The camera ray for a film position (raster coordinates) and lens
    /// sample, and its weight.
    #[inline]
    pub fn generate_ray(&self, cs: &CameraSample) -> (Ray, f32) {
        match self {
            Projection::Perspective(c) => (c.generate_ray(cs), 1.0),
            Projection::Orthographic(c) => (c.generate_ray(cs), 1.0),
            Projection::Environment(c) => (c.generate_ray(cs), 1.0),
            // The weight depends on the shifted rays too (see realistic.rs).
            Projection::Realistic(c) => {
                let (ray, _, w) = c.generate_ray_differential(cs, 1.0);
                (ray, w)
            }
        }
    }

    /// `generate_ray` (the same ray and weight) with the differentials of a
    /// one-pixel step in x and y scaled by `scale` (pbrt-v3 renders with
    /// `ScaleDifferentials(1 / √spp)`).
    #[inline]
    pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff, f32) {
        match self {
            Projection::Perspective(c) => {
                let (r, d) = c.generate_ray_differential(cs, scale);
                (r, d, 1.0)
            }
            Projection::Orthographic(c) => {
                let (r, d) = c.generate_ray_differential(cs, scale);
                (r, d, 1.0)
            }
            Projection::Environment(c) => {
                let (r, d) = c.generate_ray_differential(cs, scale);
                (r, d, 1.0)
            }
            Projection::Realistic(c) => c.generate_ray_differential(cs, scale),
        }
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
