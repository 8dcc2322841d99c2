//! Camera importance for bidirectional methods (pbrt-v3's `We`, `Pdf_We`
//! and `Sample_Wi`): the perspective camera's, as pbrt-v3 has it (a pinhole
//! or a thin lens; importance zero outside the film's sample bounds). The
//! other cameras have none in pbrt-v3 either: [`CameraImportance::new`]
//! says which camera lacks it.

use super::{at, Camera, Projection};
use crate::geometry::Bounds2i;
use crate::sampling::concentric_sample_disk;
use glam::{Affine3A, Vec2, Vec3};
use std::f32::consts::PI;

/// What the perspective camera's importance needs: its mapping, its lens
/// and the film's sample bounds.
#[derive(Clone, Debug)]
pub struct CameraImportance<'c> {
    camera: &'c Camera,
    /// Camera-to-world of a still camera (a moving one's is taken at each
    /// ray's time).
    to_world: Affine3A,
    /// A still camera's world-to-camera and viewing direction, computed
    /// once (the same values `frame` gives, inverted and normalised at each
    /// call for a moving one).
    still: Option<(Affine3A, Vec3)>,
    screen: [f32; 4],
    resolution: Vec2,
    tan_half_fov: f32,
    lens_radius: f32,
    focal_distance: f32,
    /// pbrt-v3's `A`: the area of the screen window on the plane z = 1.
    area: f32,
    /// π r² of the lens, 1 for a pinhole.
    lens_area: f32,
    sample_bounds: Bounds2i,
}

/// A point on the lens seen from a point of the scene (pbrt-v3's
/// `Sample_Wi`).
#[derive(Clone, Copy, Debug)]
pub struct ImportanceSample {
    /// Importance arriving along `wi` at the reference point.
    pub we: Vec3,
    /// Unit direction from the reference point to the lens point.
    pub wi: Vec3,
    /// Solid-angle density of `wi`.
    pub pdf: f32,
    /// Where on the film the importance comes from.
    pub p_raster: Vec2,
    /// The lens point and the camera's viewing direction (its normal).
    pub p_lens: Vec3,
    pub n: Vec3,
    /// `pdf_we(p_lens, -wi).1`: the density by solid angle of the camera
    /// ray from the lens point back along `wi` (0 where `we` is 0).
    pub pdf_dir: f32,
}

impl<'c> CameraImportance<'c> {
    /// The importance of `camera` on a film with `sample_bounds`, or why
    /// the camera has none (`who`: the integrator asking, for the message).
    pub fn new(
        camera: &'c Camera,
        sample_bounds: Bounds2i,
        who: &str,
    ) -> Result<CameraImportance<'c>, String> {
        let Projection::Perspective(p) = &camera.projection else {
            return Err(format!(
                "the \"{}\" camera has no importance function (We), which {who} needs: only the \"perspective\" camera has one (as in pbrt-v3)",
                camera.projection.kind_name()
            ));
        };
        let [x0, x1, y0, y1] = p.screen();
        let t = p.tan_half_fov();
        let lens_radius = p.lens_radius();
        let to_world = p.camera_to_world();
        Ok(CameraImportance {
            camera,
            to_world,
            still: camera
                .motion
                .is_none()
                .then(|| (to_world.inverse(), view_direction(&to_world))),
            screen: p.screen(),
            resolution: p.resolution(),
            tan_half_fov: t,
            lens_radius,
            focal_distance: p.focal_distance(),
            area: ((x1 - x0) * t * (y1 - y0) * t).abs(),
            lens_area: if lens_radius != 0.0 {
                PI * lens_radius * lens_radius
            } else {
                1.0
            },
            sample_bounds,
        })
    }

    /// Camera-to-world at scene time `time`.
    #[inline]
    fn frame(&self, time: f32) -> Affine3A {
        match &self.camera.motion {
            Some(m) => at(m, time) * self.to_world,
            None => self.to_world,
        }
    }

    /// The viewing direction in world space at `time`.
    #[inline]
    pub fn forward(&self, time: f32) -> Vec3 {
        self.forward_of(|| self.frame(time))
    }

    /// The viewing direction: a still camera's, or that of the frame
    /// `frame` gives.
    #[inline]
    fn forward_of(&self, frame: impl FnOnce() -> Affine3A) -> Vec3 {
        match &self.still {
            Some((_, forward)) => *forward,
            None => view_direction(&frame()),
        }
    }

    /// World-to-camera and the viewing direction at `time`.
    #[inline]
    fn inverse_and_forward(&self, time: f32) -> (Affine3A, Vec3) {
        match self.still {
            Some(s) => s,
            None => {
                let m = self.frame(time);
                (m.inverse(), view_direction(&m))
            }
        }
    }

    /// The film position a world ray from the lens (origin `o`, unit
    /// direction `d`) maps to and its cosine with the viewing direction;
    /// `None` if it points backwards or lands outside the sample bounds.
    #[inline]
    fn raster(&self, o: Vec3, d: Vec3, time: f32) -> Option<(Vec2, f32)> {
        let (from_world, forward) = self.inverse_and_forward(time);
        let cos = d.dot(forward);
        if cos.is_nan() || cos <= 0.0 {
            return None;
        }
        let focus = if self.lens_radius > 0.0 {
            self.focal_distance
        } else {
            1.0
        };
        let q = from_world.transform_point3(o + d * (focus / cos));
        let [x0, x1, y0, y1] = self.screen;
        let sx = q.x / q.z / self.tan_half_fov;
        let sy = q.y / q.z / self.tan_half_fov;
        let r = Vec2::new(
            (sx - x0) / (x1 - x0) * self.resolution.x,
            (y1 - sy) / (y1 - y0) * self.resolution.y,
        );
        let b = self.sample_bounds;
        let inside = r.x >= b.min.x as f32
            && r.x < b.max.x as f32
            && r.y >= b.min.y as f32
            && r.y < b.max.y as f32;
        inside.then_some((r, cos))
    }

    /// `We` of a ray at cosine `cos` with the viewing direction.
    #[inline]
    fn we_at(&self, cos: f32) -> f32 {
        let c2 = cos * cos;
        1.0 / (self.area * self.lens_area * c2 * c2)
    }

    /// `Pdf_We`'s density by solid angle of a ray at cosine `cos` with the
    /// viewing direction.
    #[inline]
    fn pdf_dir_at(&self, cos: f32) -> f32 {
        1.0 / (self.area * cos * cos * cos)
    }

    /// pbrt-v3's `We`: the importance the camera emits along the ray from
    /// `o` in direction `d`, and the film position it maps to.
    #[inline]
    pub fn we(&self, o: Vec3, d: Vec3, time: f32) -> (f32, Vec2) {
        match self.raster(o, d, time) {
            Some((r, cos)) => (self.we_at(cos), r),
            None => (0.0, Vec2::ZERO),
        }
    }

    /// pbrt-v3's `Pdf_We`: the densities of a camera ray (by area on the
    /// lens, by solid angle).
    #[inline]
    pub fn pdf_we(&self, o: Vec3, d: Vec3, time: f32) -> (f32, f32) {
        match self.raster(o, d, time) {
            Some((_, cos)) => (1.0 / self.lens_area, self.pdf_dir_at(cos)),
            None => (0.0, 0.0),
        }
    }

    /// pbrt-v3's `Sample_Wi`: a point on the lens (from `u`) seen from
    /// `p`, at scene time `time`. `None` where `p` is on the lens.
    #[inline]
    pub fn sample_wi(&self, p: Vec3, u: Vec2, time: f32) -> Option<ImportanceSample> {
        let m = self.frame(time);
        let lens = self.lens_radius * concentric_sample_disk(u);
        let p_lens = m.transform_point3(Vec3::new(lens.x, lens.y, 0.0));
        let n = self.forward_of(|| m);
        let v = p_lens - p;
        let dist = v.length();
        if dist == 0.0 || dist.is_nan() {
            return None;
        }
        // pbrt-v3 divides by multiplying by the reciprocal (as `normalize`).
        let wi = v * (1.0 / dist);
        let pdf = dist * dist / (n.dot(wi).abs() * self.lens_area);
        // `we` and `pdf_we` of the ray back from the lens from one film
        // position.
        let (we, p_raster, pdf_dir) = match self.raster(p_lens, -wi, time) {
            Some((r, cos)) => (self.we_at(cos), r, self.pdf_dir_at(cos)),
            None => (0.0, Vec2::ZERO, 0.0),
        };
        Some(ImportanceSample {
            we: Vec3::splat(we),
            wi,
            pdf,
            p_raster,
            p_lens,
            n,
            pdf_dir,
        })
    }
}

/// The camera's +z axis in world space, normalised.
#[inline]
fn view_direction(to_world: &Affine3A) -> Vec3 {
    to_world.transform_vector3(Vec3::Z).normalize()
}
