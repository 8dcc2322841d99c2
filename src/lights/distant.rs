//! `distant`: light from one direction, as from an infinitely far source
//! (pbrt-v3's `DistantLight`).
//!
//! | parameter | type | pbrt-v3 default | |
//! |---|---|---|---|
//! | `L` | spectrum | 1 | radiance |
//! | `scale` | spectrum or float | 1 | multiplies `L` (pbrt-v3 reads a spectrum; pbrs also takes a float) |
//! | `from` | point3 | 0 0 0 | with `to`: the light travels from `from` towards `to` |
//! | `to` | point3 | 0 0 1 | |
//!
//! The direction towards the light is normalise(CTM·(`from` − `to`));
//! `from` = `to`, or a direction that is not finite: warning, skipped.
//! Power is `L`·π r², r the scene's bounding radius (set when the scene is
//! built, [`LightModel::preprocess`]).

use super::{disk_ray, EmittedRay, LightKind, LightModel, LightSample};
use crate::accel::Aggregate;
use crate::geometry::spawn_ray_to_point;
use crate::scene::{ParamSpec, ParamValues, Report, Support};
use crate::shapes::SurfacePoint;
use glam::{DMat4, Vec2, Vec3};
use std::f32::consts::PI;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_any("L", [1.0; 3], "radiance"),
    ParamSpec::spectrum_or_float(
        "scale",
        [1.0; 3],
        "multiplies L (a spectrum in pbrt-v3; pbrs also takes a float)",
    ),
    ParamSpec::point3("from", [0.0; 3], "the light travels from here…"),
    ParamSpec::point3("to", [0.0, 0.0, 1.0], "…towards here"),
];

pub const KIND: LightKind = LightKind {
    name: "distant",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "radiance L·scale from the direction CTM·(from − to), as from an infinitely far source (from = to: warning, skipped)",
    build: |p, ctm, report| DistantLight::new(p, ctm, report).map(Into::into),
};

#[derive(Clone, Copy, Debug)]
pub struct DistantLight {
    /// Unit world-space direction towards the light.
    pub w: Vec3,
    /// `L`·`scale`.
    pub l: Vec3,
    /// The scene's bounding radius (0 until [`LightModel::preprocess`]).
    pub scene_radius: f32,
}

impl DistantLight {
    /// pbrt-v3's `CreateDistantLight`; `None` (after a warning) when the
    /// light has no direction.
    pub fn new(p: &ParamValues, ctm: DMat4, report: &mut dyn Report) -> Option<DistantLight> {
        let l = p.spectrum("L") * p.spectrum("scale");
        let d = ctm.transform_vector3(p.point("from") - p.point("to"));
        if d.length_squared() == 0.0 || !d.is_finite() {
            report.warn(
                None,
                "distant light with \"from\" equal to \"to\" has no direction: skipped".into(),
                "degenerate distant light",
            );
            return None;
        }
        Some(DistantLight {
            // Normalised twice in f64, as the scene description and then the
            // render scene did before lights were built at load time (the
            // second can move the last bit).
            w: d.normalize().normalize().as_vec3(),
            l,
            scene_radius: 0.0,
        })
    }
}

impl LightModel for DistantLight {
    #[inline]
    fn is_delta(&self) -> bool {
        true
    }

    fn at_infinity(&self) -> bool {
        true
    }

    fn power(&self) -> Vec3 {
        self.l * PI * self.scene_radius * self.scene_radius
    }

    #[inline]
    fn sample_li(&self, r: &SurfacePoint, _u: Vec2, _geom: &Aggregate) -> Option<LightSample> {
        let far = r.p + self.w * (2.0 * self.scene_radius);
        Some(LightSample {
            li: self.l,
            wi: self.w,
            pdf: 1.0,
            shadow: spawn_ray_to_point(r.p, r.p_error, r.n, far),
        })
    }

    /// pbrt-v3's: uniform on the disk of the scene's bounding sphere, one
    /// direction (density 0 for any other).
    fn pdf_le(&self, _d: Vec3, _n: Vec3) -> (f32, f32) {
        let r = self.scene_radius;
        (1.0 / (std::f32::consts::PI * r * r), 0.0)
    }

    /// pbrt-v3's: a ray along the light's direction from a point uniform
    /// on the disk of the scene's bounding sphere facing the light.
    fn sample_le(&self, u1: Vec2, _u2: Vec2, geom: &Aggregate) -> Option<EmittedRay> {
        let (ray, pdf_pos) = disk_ray(geom, self.scene_radius, self.w, u1)?;
        Some(EmittedRay {
            le: self.l,
            ray,
            n: ray.d,
            pdf_pos,
            pdf_dir: 1.0,
        })
    }

    fn preprocess(&mut self, geom: &Aggregate) {
        self.scene_radius = geom.bounds.bounding_sphere().1;
    }
}
