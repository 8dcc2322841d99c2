//! The orthographic camera (pbrt-v3's `OrthographicCamera`): rays parallel
//! to camera-space +z, starting on the z = 0 plane at the screen-window point
//! of their film position (camera space is screen space: pbrt-v3's
//! `Orthographic(0, 1)` is the identity in x and y), or a thin lens when
//! `lensradius` > 0 that focuses on the plane z = `focaldistance`. Raster
//! conventions as the perspective camera's (raster y runs down). Ray
//! differentials as pbrt-v3's `OrthographicCamera::GenerateRayDifferential`:
//! origins one pixel over with the same direction for the pinhole; with a
//! lens, rays from the same lens point towards the focus point of the
//! neighbouring pixel.
//!
//! Parameters: [`PARAMS`] (shown in `grammar/REFERENCE.md`); the screen
//! window is in camera-space units, by default as the perspective camera's.

use super::{
    frame_aspect_ratio, screen_window, screen_window_param, thin_lens, CameraKind, Frame,
    Projection, SHUTTER, THIN_LENS,
};
use crate::geometry::{Ray, RayDiff};
use crate::samplers::CameraSample;
use crate::sampling::concentric_sample_disk;
use crate::scene::{ParamSpec, Support};
use glam::{Affine3A, Vec2, Vec3};

pub const PARAMS: &[ParamSpec] = &[
    THIN_LENS[0],
    THIN_LENS[1],
    THIN_LENS[2],
    THIN_LENS[3],
    SHUTTER[0],
    SHUTTER[1],
];

pub const KIND: CameraKind = CameraKind {
    name: "orthographic",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "parallel rays along +z from the screen window, or a thin lens when lensradius > 0",
    build: |p, _, r| {
        let (lens_radius, focal_distance) = thin_lens(p, r);
        Some(Projection::Orthographic(OrthographicCamera::with(
            lens_radius,
            focal_distance,
            frame_aspect_ratio(p, r),
            screen_window_param(p, r),
        )))
    },
};

#[derive(Clone, Debug)]
pub struct OrthographicCamera {
    /// `frameaspectratio` and `screenwindow` as given.
    pub frame_aspect_ratio: Option<f32>,
    pub screen_window: Option<[f32; 4]>,
    camera_to_world: Affine3A,
    /// Screen window [xmin, xmax, ymin, ymax].
    screen: [f32; 4],
    resolution: Vec2,
    lens_radius: f32,
    focal_distance: f32,
    /// Camera-space offsets of a one-pixel step in raster x and y.
    dx_camera: Vec3,
    dy_camera: Vec3,
}

impl OrthographicCamera {
    /// The camera as its parameters give it; [`OrthographicCamera::prepare`]
    /// derives the mapping.
    pub fn with(
        lens_radius: f32,
        focal_distance: f32,
        frame_aspect_ratio: Option<f32>,
        screen_window: Option<[f32; 4]>,
    ) -> OrthographicCamera {
        OrthographicCamera {
            frame_aspect_ratio,
            screen_window,
            ..OrthographicCamera::new(
                Affine3A::IDENTITY,
                lens_radius,
                focal_distance,
                [-1.0, 1.0, -1.0, 1.0],
                Vec2::ONE,
            )
        }
    }

    pub fn prepare(&mut self, f: &Frame) {
        let screen = screen_window(self.screen_window, self.frame_aspect_ratio, f.resolution);
        *self = OrthographicCamera {
            frame_aspect_ratio: self.frame_aspect_ratio,
            screen_window: self.screen_window,
            ..OrthographicCamera::new(
                f.to_world,
                self.lens_radius,
                self.focal_distance,
                screen,
                f.resolution,
            )
        };
    }

    pub fn describe(&self) -> String {
        if self.lens_radius > 0.0 {
            format!("orthographic, lens radius {}", self.lens_radius)
        } else {
            "orthographic".into()
        }
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

    pub fn new(
        camera_to_world: Affine3A,
        lens_radius: f32,
        focal_distance: f32,
        screen: [f32; 4],
        resolution: Vec2,
    ) -> OrthographicCamera {
        let [x0, x1, y0, y1] = screen;
        OrthographicCamera {
            frame_aspect_ratio: None,
            screen_window: None,
            camera_to_world,
            screen,
            resolution,
            lens_radius,
            focal_distance,
            dx_camera: Vec3::new((x1 - x0) / resolution.x, 0.0, 0.0),
            dy_camera: Vec3::new(0.0, -(y1 - y0) / resolution.y, 0.0),
        }
    }

    #[inline]
    pub fn uses_lens(&self) -> bool {
        self.lens_radius > 0.0
    }

    /// The camera-space point on z = 0 of a raster position.
    #[inline]
    fn raster_to_camera(&self, p: Vec2) -> Vec3 {
        let [x0, x1, y0, y1] = self.screen;
        Vec3::new(
            x0 + p.x / self.resolution.x * (x1 - x0),
            y1 - p.y / self.resolution.y * (y1 - y0),
            0.0,
        )
    }

    #[inline]
    fn to_world(&self, o: Vec3, d: Vec3) -> Ray {
        super::world_ray(&self.camera_to_world, o, d)
    }

    /// Camera-space origin, direction and lens point of the ray.
    #[inline]
    fn camera_ray(&self, cs: &CameraSample) -> (Vec3, Vec3, Vec3) {
        let p = self.raster_to_camera(cs.p_film);
        if self.lens_radius > 0.0 {
            let l = self.lens_radius * concentric_sample_disk(cs.p_lens);
            let lens = Vec3::new(l.x, l.y, 0.0);
            let focus = p + Vec3::new(0.0, 0.0, self.focal_distance);
            (lens, (focus - lens).normalize(), p)
        } else {
            (p, Vec3::Z, p)
        }
    }

    #[inline]
    pub fn generate_ray(&self, cs: &CameraSample) -> Ray {
        let (o, d, _) = self.camera_ray(cs);
        self.to_world(o, d)
    }

    /// `generate_ray` with pbrt-v3's differentials, scaled by `scale`.
    #[inline]
    pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff) {
        let (o, d, p) = self.camera_ray(cs);
        let ray = self.to_world(o, d);
        let diff = if self.lens_radius > 0.0 {
            // pbrt-v3 divides by the z of the lens ray's direction here, not
            // of +z: the differentials' focus plane lies at
            // focaldistance / cos θ. Kept so that texture footprints match.
            let ft = self.focal_distance / d.z;
            let towards = |step: Vec3| {
                let focus = p + step + Vec3::new(0.0, 0.0, ft);
                self.to_world(o, (focus - o).normalize())
            };
            let (rx, ry) = (towards(self.dx_camera), towards(self.dy_camera));
            RayDiff {
                rx_o: rx.o,
                rx_d: rx.d,
                ry_o: ry.o,
                ry_d: ry.d,
            }
        } else {
            RayDiff {
                rx_o: self.camera_to_world.transform_point3(o + self.dx_camera),
                rx_d: ray.d,
                ry_o: self.camera_to_world.transform_point3(o + self.dy_camera),
                ry_d: ray.d,
            }
        };
        (ray, diff.scaled(&ray, scale))
    }
}
