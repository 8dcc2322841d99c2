//! The perspective camera (pbrt-v3's `PerspectiveCamera`): a pinhole, or a
//! thin lens when `lensradius` > 0. Raster conventions as pbrt-v3: `fov`
//! spans the shorter image axis, raster y runs down, pixel (x, y) covers
//! [x, x+1)×[y, y+1). Ray differentials as pbrt-v3's
//! `PerspectiveCamera::GenerateRayDifferential`.
//!
//! Parameters: [`PARAMS`] (shown in `grammar/REFERENCE.md`); `fov` spans
//! the shorter image axis, and the screen window defaults to
//! [-frame, frame] × [-1, 1] if frame > 1, else [-1, 1] × [-1/frame, 1/frame].

use super::{
    frame_aspect_ratio, screen_window, screen_window_param, thin_lens, world_ray, CameraKind,
    Frame, Projection, SHUTTER, THIN_LENS,
};
use crate::geometry::{Ray, RayDiff};
use crate::samplers::CameraSample;
use crate::sampling::concentric_sample_disk;
use crate::scene::{ParamSpec, ParamValues, Report, Support};
use glam::{Affine3A, Vec2, Vec3};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::float(
        "fov",
        90.0,
        "field of view in degrees across the shorter image axis, in (0, 180)",
    ),
    ParamSpec::float(
        "halffov",
        -1.0,
        "half the field of view (when > 0, fov = 2·halffov)",
    ),
    THIN_LENS[0],
    THIN_LENS[1],
    THIN_LENS[2],
    THIN_LENS[3],
    SHUTTER[0],
    SHUTTER[1],
];

pub const KIND: CameraKind = CameraKind {
    name: "perspective",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a pinhole, or a thin lens when lensradius > 0",
    build: |p, _, r| Some(Projection::Perspective(build(p, r))),
};

fn build(p: &ParamValues, r: &mut dyn Report) -> PerspectiveCamera {
    let mut fov = p.float("fov") as f64;
    let half = p.float("halffov") as f64;
    if half > 0.0 {
        fov = 2.0 * half;
    }
    if !(fov > 0.0 && fov < 180.0) {
        r.error(
            Some("fov"),
            format!("field of view {} is outside (0, 180) degrees", fov as f32),
            "bad fov",
        );
        fov = 90.0;
    }
    let (lens_radius, focal_distance) = thin_lens(p, r);
    PerspectiveCamera::with(
        fov as f32,
        lens_radius,
        focal_distance,
        frame_aspect_ratio(p, r),
        screen_window_param(p, r),
    )
}

#[derive(Clone, Debug)]
pub struct PerspectiveCamera {
    /// Full field of view in degrees, spanning the shorter image axis
    /// (after `halffov` was folded in).
    pub fov: f32,
    /// `frameaspectratio` and `screenwindow` as given.
    pub frame_aspect_ratio: Option<f32>,
    pub screen_window: Option<[f32; 4]>,
    camera_to_world: Affine3A,
    /// Screen window [xmin, xmax, ymin, ymax].
    screen: [f32; 4],
    /// Full film resolution (the crop window does not change the mapping).
    resolution: Vec2,
    tan_half_fov: f32,
    lens_radius: f32,
    focal_distance: f32,
}

impl PerspectiveCamera {
    /// The camera as its parameters give it; [`PerspectiveCamera::prepare`]
    /// derives the mapping.
    pub fn with(
        fov: f32,
        lens_radius: f32,
        focal_distance: f32,
        frame_aspect_ratio: Option<f32>,
        screen_window: Option<[f32; 4]>,
    ) -> PerspectiveCamera {
        PerspectiveCamera {
            fov,
            frame_aspect_ratio,
            screen_window,
            ..PerspectiveCamera::new(
                Affine3A::IDENTITY,
                fov,
                lens_radius,
                focal_distance,
                [-1.0, 1.0, -1.0, 1.0],
                Vec2::ONE,
            )
        }
    }

    pub fn prepare(&mut self, f: &Frame) {
        let screen = screen_window(self.screen_window, self.frame_aspect_ratio, f.resolution);
        *self = PerspectiveCamera {
            fov: self.fov,
            frame_aspect_ratio: self.frame_aspect_ratio,
            screen_window: self.screen_window,
            ..PerspectiveCamera::new(
                f.to_world,
                self.fov,
                self.lens_radius,
                self.focal_distance,
                screen,
                f.resolution,
            )
        };
    }

    pub fn describe(&self) -> String {
        if self.lens_radius > 0.0 {
            format!(
                "perspective, fov {}°, lens radius {}",
                self.fov, self.lens_radius
            )
        } else {
            format!("perspective, fov {}°", self.fov)
        }
    }

    pub fn lens_radius(&self) -> f32 {
        self.lens_radius
    }

    pub fn focal_distance(&self) -> f32 {
        self.focal_distance
    }

    /// Camera-to-world as prepared (the identity for a moving camera).
    pub fn camera_to_world(&self) -> Affine3A {
        self.camera_to_world
    }

    /// The screen window [xmin, xmax, ymin, ymax].
    pub fn screen(&self) -> [f32; 4] {
        self.screen
    }

    /// The full film resolution the mapping was prepared for.
    pub fn resolution(&self) -> Vec2 {
        self.resolution
    }

    /// tan(fov/2).
    pub fn tan_half_fov(&self) -> f32 {
        self.tan_half_fov
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
        fov: f32,
        lens_radius: f32,
        focal_distance: f32,
        screen: [f32; 4],
        resolution: Vec2,
    ) -> PerspectiveCamera {
        PerspectiveCamera {
            fov,
            frame_aspect_ratio: None,
            screen_window: None,
            camera_to_world,
            screen,
            resolution,
            tan_half_fov: (fov.clamp(1e-6, 179.99).to_radians() * 0.5).tan(),
            lens_radius,
            focal_distance,
        }
    }

    /// True if `generate_ray` reads the sample's lens position (a thin lens;
    /// the time is read by `Camera`, not here).
    #[inline]
    pub fn uses_lens(&self) -> bool {
        self.lens_radius > 0.0
    }

    /// Camera-space direction (z = 1) through a film position.
    #[inline]
    fn film_dir(&self, cs: &CameraSample) -> Vec3 {
        let [x0, x1, y0, y1] = self.screen;
        let sx = x0 + cs.p_film.x / self.resolution.x * (x1 - x0);
        let sy = y1 - cs.p_film.y / self.resolution.y * (y1 - y0);
        Vec3::new(sx * self.tan_half_fov, sy * self.tan_half_fov, 1.0)
    }

    /// The thin-lens ray from lens point `lens` through the point of the
    /// plane of focus that direction `dir` reaches, in world space.
    #[inline]
    fn lens_ray(&self, dir: Vec3, lens: Vec3) -> Ray {
        let d = dir.normalize();
        let ft = self.focal_distance / d.z;
        let focus = d * ft;
        let d = (focus - lens).normalize();
        world_ray(&self.camera_to_world, lens, d)
    }

    /// The camera ray for a film position (raster coordinates) and lens
    /// sample. Inlined into the render loop, which stores the ray: returned
    /// through memory, its copy stalled on the stores that had just made it.
    #[inline(always)]
    pub fn generate_ray(&self, cs: &CameraSample) -> Ray {
        let dir = self.film_dir(cs);
        if self.lens_radius > 0.0 {
            let lens = self.lens_radius * concentric_sample_disk(cs.p_lens);
            return self.lens_ray(dir, Vec3::new(lens.x, lens.y, 0.0));
        }
        // Pinhole: one normalisation, after the transform (which may scale).
        world_ray(&self.camera_to_world, Vec3::ZERO, dir)
    }

    /// `generate_ray` (the same ray, bit for bit) with the differentials of
    /// a one-pixel step in x and y, scaled by `scale` (pbrt-v3 renders with
    /// `ScaleDifferentials(1 / √spp)`). With a lens the offset rays start at
    /// the same lens point and meet the plane of focus where the shifted
    /// film positions do.
    #[inline]
    pub fn generate_ray_differential(&self, cs: &CameraSample, scale: f32) -> (Ray, RayDiff) {
        let ray = self.generate_ray(cs);
        let dir = self.film_dir(cs);
        let [x0, x1, y0, y1] = self.screen;
        let dx = Vec3::new((x1 - x0) / self.resolution.x * self.tan_half_fov, 0.0, 0.0);
        let dy = Vec3::new(0.0, -(y1 - y0) / self.resolution.y * self.tan_half_fov, 0.0);
        let (rx, ry) = if self.lens_radius > 0.0 {
            let lens = self.lens_radius * concentric_sample_disk(cs.p_lens);
            let lens = Vec3::new(lens.x, lens.y, 0.0);
            (self.lens_ray(dir + dx, lens), self.lens_ray(dir + dy, lens))
        } else {
            let offset = |d: Vec3| Ray {
                d: self.camera_to_world.transform_vector3(d).normalize(),
                ..ray
            };
            (offset(dir + dx), offset(dir + dy))
        };
        let diff = RayDiff {
            rx_o: rx.o,
            rx_d: rx.d,
            ry_o: ry.o,
            ry_d: ry.d,
        };
        (ray, diff.scaled(&ray, scale))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat4;

    fn camera(lens_radius: f32) -> PerspectiveCamera {
        let m = DMat4::from_translation(glam::DVec3::new(0.0, 1.0, -5.0))
            * DMat4::from_rotation_x(0.2)
            * DMat4::from_scale(glam::DVec3::new(-1.0, 1.0, 1.0));
        let frame = 64.0 / 48.0;
        PerspectiveCamera::new(
            Affine3A::from_mat4(m.as_mat4()),
            40.0,
            lens_radius,
            4.0,
            [-frame, frame, -1.0, 1.0],
            Vec2::new(64.0, 48.0),
        )
    }

    /// The differentials at scale 1 are the rays of the film positions one
    /// pixel over; at scale s their offsets are s times as large.
    #[test]
    fn differentials_are_the_neighbouring_pixels_rays() {
        for lens in [0.0, 0.3] {
            let cam = camera(lens);
            let cs = CameraSample {
                p_film: Vec2::new(10.3, 30.7),
                p_lens: Vec2::new(0.2, 0.9),
                time: 0.0,
            };
            let (ray, d) = cam.generate_ray_differential(&cs, 1.0);
            let plain = cam.generate_ray(&cs);
            assert_eq!((ray.o, ray.d), (plain.o, plain.d));
            let shifted = |dx: f32, dy: f32| {
                cam.generate_ray(&CameraSample {
                    p_film: cs.p_film + Vec2::new(dx, dy),
                    ..cs
                })
            };
            let (rx, ry) = (shifted(1.0, 0.0), shifted(0.0, 1.0));
            assert!(
                (d.rx_o - rx.o).length() < 1e-5 && (d.rx_d - rx.d).length() < 1e-5,
                "{lens}"
            );
            assert!(
                (d.ry_o - ry.o).length() < 1e-5 && (d.ry_d - ry.d).length() < 1e-5,
                "{lens}"
            );
            let (_, half) = cam.generate_ray_differential(&cs, 0.125);
            let want = ray.d + (rx.d - ray.d) * 0.125;
            assert!((half.rx_d - want).length() < 1e-6);
        }
    }
}
