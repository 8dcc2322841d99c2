//! `projection`: a point light projecting an image through a frustum, as a
//! slide projector (pbrt-v3's `ProjectionLight`, lights/projection.cpp).
//!
//! | parameter | type | pbrt-v3 default | |
//! |---|---|---|---|
//! | `I` | spectrum | 1 | radiant intensity |
//! | `scale` | spectrum or float | 1 | multiplies `I` (pbrt-v3 reads a spectrum; pbrs also takes a float) |
//! | `fov` | float | 45 | field of view of the frustum's shorter side, degrees |
//! | `mapname` | string (image file) | none: 1 inside the frustum | the projected image |
//!
//! Light-to-world is the CTM; the light sits at its origin and projects
//! along light-space +z. pbrt-v3's conventions: the screen window is
//! [−a, a] × [−1, 1] for an image of aspect a = width/height > 1 and
//! [−1, 1] × [−1/a, 1/a] otherwise (a = 1 without an image), so `fov`
//! spans the shorter side; a direction is projected by pbrt-v3's
//! `Perspective(fov, 10⁻³, 10³⁰)` (directions with light-space z below
//! 10⁻³ get nothing), and the image is looked up at the point's offset in
//! the screen window, so its first row (t = 0) falls on light-space −y
//! (pbrt-v3 does not flip it). The image is read as pbrt-v3's `ReadImage`
//! returns it and looked up bilinearly at the finest level of pbrt-v3's
//! MIP map (wrap mode repeat). Power, for light selection: I times the
//! image's average (its MIP lookup at (½, ½) with width ½) times the solid
//! angle 2π(1 − cos θ) of the cone around the frustum's diagonal.

use super::bvh::LightBounds;
use super::goniometric::{light_frame, LightMap};
use super::{sample_at_point, EmittedRay, LightKind, LightModel, LightSample};
use crate::accel::Aggregate;
use crate::geometry::{luminance, Bounds3, Frame, Ray};
use crate::sampling::{uniform_cone_pdf, uniform_sample_cone};
use crate::scene::{Decode, ParamSpec, ParamValues, Report, Support};
use crate::shapes::SurfacePoint;
use glam::{DMat4, DVec3, Mat3, Vec2, Vec3};
use std::f32::consts::PI;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_any("I", [1.0; 3], "radiant intensity"),
    ParamSpec::spectrum_or_float(
        "scale",
        [1.0; 3],
        "multiplies I (a spectrum in pbrt-v3; pbrs also takes a float)",
    ),
    ParamSpec::float(
        "fov",
        45.0,
        "field of view of the frustum's shorter side, in degrees",
    ),
    ParamSpec::image(
        "mapname",
        Decode::Raw,
        "the projected image (first row towards light-space −y, as pbrt-v3); none: 1 inside the frustum",
    ),
];

pub const KIND: LightKind = LightKind {
    name: "projection",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a point light at the CTM's origin projecting an image (intensity I·scale) along light-space +z through a frustum of fov degrees across its shorter side",
    build: |p, ctm, report| ProjectionLight::new(p, ctm, report).map(Into::into),
};

/// pbrt-v3's near plane: directions closer to the light's xy plane get no
/// light.
const HITHER: f32 = 1e-3;

#[derive(Clone, Debug)]
pub struct ProjectionLight {
    /// World-space position.
    pub p: Vec3,
    /// `I`·`scale`.
    pub intensity: Vec3,
    /// World-to-light, for directions.
    pub world_to_light: Mat3,
    /// The frustum's axis in world space.
    pub axis: Vec3,
    pub map: Option<LightMap>,
    /// 1 / tan(fov / 2).
    pub inv_tan: f32,
    /// The screen window: x from `screen[0]` to `screen[1]`, y from
    /// `screen[2]` to `screen[3]`.
    pub screen: [f32; 4],
    /// Cosine of the cone around the frustum's corners.
    pub cos_total_width: f32,
}

impl ProjectionLight {
    pub fn new(p: &ParamValues, ctm: DMat4, report: &mut dyn Report) -> Option<ProjectionLight> {
        let intensity = p.spectrum("I") * p.spectrum("scale");
        let fov = p.float("fov");
        let (pos, world_to_light) = light_frame(ctm, "projection", report)?;
        let map = p
            .image("mapname")
            .and_then(|img| LightMap::new(&img, report));
        let aspect = map
            .as_ref()
            .map_or(1.0, |m| m.width as f32 / m.height as f32);
        let screen = if aspect > 1.0 {
            [-aspect, aspect, -1.0, 1.0]
        } else {
            [-1.0, 1.0, -1.0 / aspect, 1.0 / aspect]
        };
        let half = fov.to_radians() / 2.0;
        let opposite = half.tan();
        let tan_diag = opposite * (1.0 + 1.0 / (aspect * aspect)).sqrt();
        let axis = ctm.transform_vector3(DVec3::Z).normalize().as_vec3();
        Some(ProjectionLight {
            p: pos,
            intensity,
            world_to_light,
            axis,
            map,
            inv_tan: 1.0 / opposite,
            screen,
            cos_total_width: tan_diag.atan().cos(),
        })
    }

    /// pbrt-v3's `Projection(w)` for a world direction `w` leaving the
    /// light.
    #[inline]
    pub fn projection(&self, w: Vec3) -> Vec3 {
        let wl = self.world_to_light * w;
        if wl.z < HITHER {
            return Vec3::ZERO;
        }
        let inv_z = 1.0 / wl.z;
        let x = self.inv_tan * wl.x * inv_z;
        let y = self.inv_tan * wl.y * inv_z;
        let [x0, x1, y0, y1] = self.screen;
        if !(x0 <= x && x <= x1 && y0 <= y && y <= y1) {
            return Vec3::ZERO;
        }
        match &self.map {
            None => Vec3::ONE,
            Some(map) => map.at(Vec2::new((x - x0) / (x1 - x0), (y - y0) / (y1 - y0))),
        }
    }
}

impl LightModel for ProjectionLight {
    #[inline]
    fn is_delta(&self) -> bool {
        true
    }

    fn power(&self) -> Vec3 {
        let average = self.map.as_ref().map_or(Vec3::ONE, LightMap::average);
        average * self.intensity * 2.0 * PI * (1.0 - self.cos_total_width)
    }

    #[inline]
    fn sample_li(&self, r: &SurfacePoint, _u: Vec2, _geom: &Aggregate) -> Option<LightSample> {
        sample_at_point(self.p, r, |w| self.intensity * self.projection(w))
    }

    /// pbrt-v3's: no density by area (a point), uniform over the cone
    /// around the frustum.
    fn pdf_le(&self, d: Vec3, _n: Vec3) -> (f32, f32) {
        let inside = d.dot(self.axis) >= self.cos_total_width;
        (
            0.0,
            if inside {
                uniform_cone_pdf(self.cos_total_width)
            } else {
                0.0
            },
        )
    }

    /// A direction uniform over the cone around the frustum (directions
    /// outside the frustum carry no intensity). pbrt-v3 samples the cone of
    /// `cos_total_width`, whose tangent is tan(fov/2)·√(1 + 1/aspect²):
    /// when the map is wider than tall that cone misses the frustum's
    /// corners (its half-diagonal has tangent tan(fov/2)·√(aspect² + 1)),
    /// and their light would never be emitted; this cone is the frustum's.
    fn sample_le(&self, u1: Vec2, _u2: Vec2, _geom: &Aggregate) -> Option<EmittedRay> {
        let tan_diag = self.screen[1].hypot(self.screen[3]) / self.inv_tan;
        let cos_max = 1.0 / (1.0 + tan_diag * tan_diag).sqrt();
        let d = Frame::from_normal(self.axis).from_local(uniform_sample_cone(u1, cos_max));
        Some(EmittedRay {
            le: self.intensity * self.projection(d),
            ray: Ray::new(self.p, d),
            n: d,
            pdf_pos: 1.0,
            pdf_dir: uniform_cone_pdf(cos_max),
        })
    }

    /// A point emitting into the cone around the frustum, φ its power.
    fn bounds(&self, _geom: &Aggregate) -> Option<LightBounds> {
        Some(LightBounds {
            bounds: Bounds3::from_point(self.p),
            w: self.axis,
            phi: luminance(self.power()).max(0.0),
            cos_theta_o: self.cos_total_width,
            cos_theta_e: 1.0,
            two_sided: false,
        })
    }
}
