//! The environment camera (pbrt-v3's `EnvironmentCamera`): a latitude-
//! longitude map of every direction around the camera position. With raster
//! position (x, y) on a W×H film, θ = π·y/H from camera-space +y (raster
//! top row looks straight up, bottom row straight down) and φ = 2π·x/W
//! around +y starting at +x: direction (sin θ cos φ, cos θ, sin θ sin φ). So
//! the left edge looks along +x, a quarter across along +z (the camera's
//! forward axis), the image centre along −x. pbrt-v3 gives it no
//! differential method of its own: the base `Camera::GenerateRayDifferential`
//! estimates them by finite differences over ±0.05 pixel, as here.
//!
//! Parameters: [`PARAMS`] (shown in `grammar/REFERENCE.md`): the shutter;
//! pbrt-v3 reads the projective cameras' lens and frame parameters too and
//! ignores them (so they are never reported unused; a malformed
//! `screenwindow` is still reported).

use super::{screen_window_param, CameraKind, Frame, Projection, SHUTTER, THIN_LENS};
use crate::geometry::{Ray, RayDiff};
use crate::samplers::CameraSample;
use crate::scene::{ParamSpec, Support};
use glam::{Affine3A, Vec2, Vec3};
use std::f32::consts::PI;

pub const PARAMS: &[ParamSpec] = &[
    SHUTTER[0],
    SHUTTER[1],
    THIN_LENS[0],
    THIN_LENS[1],
    THIN_LENS[2],
    THIN_LENS[3],
];

pub const KIND: CameraKind = CameraKind {
    name: "environment",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "latitude-longitude: every direction around the camera (lensradius, focaldistance, frameaspectratio and screenwindow are read and ignored, as pbrt-v3)",
    build: |p, _, r| {
        screen_window_param(p, r);
        Some(Projection::Environment(EnvironmentCamera::new(
            Affine3A::IDENTITY,
            Vec2::ONE,
        )))
    },
};

#[derive(Clone, Debug)]
pub struct EnvironmentCamera {
    camera_to_world: Affine3A,
    resolution: Vec2,
}

impl EnvironmentCamera {
    pub fn new(camera_to_world: Affine3A, resolution: Vec2) -> EnvironmentCamera {
        EnvironmentCamera {
            camera_to_world,
            resolution,
        }
    }

    pub fn prepare(&mut self, f: &Frame) {
        *self = EnvironmentCamera::new(f.to_world, f.resolution);
    }

    pub fn describe(&self) -> String {
        "environment (latitude-longitude)".into()
    }

    pub fn uses_lens(&self) -> bool {
        false
    }

    #[inline(always)]
    pub fn ray(&self, cs: &CameraSample) -> (Ray, f32) {
        (self.generate_ray(cs), 1.0)
    }

    #[inline]
    pub fn ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff, f32) {
        let (r, d) = self.generate_ray_differential(cs, scale);
        (r, d, 1.0)
    }

    /// The camera-space direction of a raster position.
    #[inline]
    pub fn direction(&self, p_film: Vec2) -> Vec3 {
        let theta = PI * p_film.y / self.resolution.y;
        let phi = 2.0 * PI * p_film.x / self.resolution.x;
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        Vec3::new(st * cp, ct, st * sp)
    }

    #[inline]
    pub fn generate_ray(&self, cs: &CameraSample) -> Ray {
        super::world_ray(&self.camera_to_world, Vec3::ZERO, self.direction(cs.p_film))
    }

    #[inline]
    pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff) {
        let ray = self.generate_ray(cs);
        // Never `None`: every film position has a ray.
        let diff = super::finite_differences(cs, &ray, |s| Some(self.generate_ray(s)))
            .unwrap_or_else(|| RayDiff::none(&ray));
        (ray, diff.scaled(&ray, scale))
    }
}
