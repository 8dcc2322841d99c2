//! Cameras: pbrt-v3's four, one file each, behind a closed enum that only
//! delegates (one `match` per camera ray, no dynamic dispatch).
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
    ) * crate::render::geometry::gamma(3);
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
    #[inline(always)]
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
