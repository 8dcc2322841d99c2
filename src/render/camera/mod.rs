//! The perspective camera with pbrt-v3's raster conventions: `fov` spans the
//! shorter image axis, raster y runs down, pixel (x, y) covers [x, x+1)×[y, y+1),
//! and a thin lens when `lensradius` > 0.

use crate::render::geometry::Ray;
use crate::render::samplers::CameraSample;
use crate::render::sampling::concentric_sample_disk;
use crate::scene::{CameraDesc, CameraKind};
use glam::{Affine3A, Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct Camera {
    camera_to_world: Affine3A,
    /// Screen window [xmin, xmax, ymin, ymax].
    screen: [f32; 4],
    /// Full film resolution (the crop window does not change the mapping).
    resolution: Vec2,
    tan_half_fov: f32,
    lens_radius: f32,
    focal_distance: f32,
}

impl Camera {
    pub fn new(desc: &CameraDesc, xres: u32, yres: u32) -> Camera {
        let CameraKind::Perspective {
            fov,
            lens_radius,
            focal_distance,
            frame_aspect_ratio,
            screen_window,
        } = desc.kind;
        let frame = frame_aspect_ratio.unwrap_or(xres as f32 / yres as f32);
        let screen = screen_window.unwrap_or(if frame > 1.0 {
            [-frame, frame, -1.0, 1.0]
        } else {
            [-1.0, 1.0, -1.0 / frame, 1.0 / frame]
        });
        let m = desc.camera_to_world.as_mat4();
        Camera {
            camera_to_world: Affine3A::from_mat4(m),
            screen,
            resolution: Vec2::new(xres as f32, yres as f32),
            tan_half_fov: (fov.clamp(1e-6, 179.99).to_radians() * 0.5).tan(),
            lens_radius,
            focal_distance,
        }
    }

    /// True if `generate_ray` reads the sample's lens position (a thin lens;
    /// time is never read: there is no motion blur).
    #[inline]
    pub fn uses_lens(&self) -> bool {
        self.lens_radius > 0.0
    }

    /// The camera ray for a film position (raster coordinates) and lens sample.
    #[inline]
    pub fn generate_ray(&self, cs: &CameraSample) -> Ray {
        let [x0, x1, y0, y1] = self.screen;
        let sx = x0 + cs.p_film.x / self.resolution.x * (x1 - x0);
        let sy = y1 - cs.p_film.y / self.resolution.y * (y1 - y0);
        let dir = Vec3::new(sx * self.tan_half_fov, sy * self.tan_half_fov, 1.0);
        if self.lens_radius > 0.0 {
            let d = dir.normalize();
            let lens = self.lens_radius * concentric_sample_disk(cs.p_lens);
            let ft = self.focal_distance / d.z;
            let focus = d * ft;
            let o = Vec3::new(lens.x, lens.y, 0.0);
            let d = (focus - o).normalize();
            let wo = self.camera_to_world.transform_point3(o);
            let wd = self.camera_to_world.transform_vector3(d).normalize();
            return Ray::new(wo, wd);
        }
        // Pinhole: one normalisation, after the transform (which may scale).
        let wo = self.camera_to_world.transform_point3(Vec3::ZERO);
        let wd = self.camera_to_world.transform_vector3(dir).normalize();
        Ray::new(wo, wd)
    }
}
