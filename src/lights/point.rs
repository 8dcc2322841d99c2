//! `point`: an isotropic point light (pbrt-v3's `PointLight`).
//!
//! | parameter | type | pbrt-v3 default | |
//! |---|---|---|---|
//! | `I` | spectrum | 1 | radiant intensity |
//! | `scale` | spectrum or float | 1 | multiplies `I` (pbrt-v3 reads a spectrum; pbrs also takes a float) |
//! | `from` | point3 | 0 0 0 | position |
//!
//! As pbrt-v3's `CreatePointLight`, light-to-world is Translate(`from`) ·
//! CTM, so the light sits at CTM·origin + `from` (not CTM·`from` when the
//! CTM scales or rotates).

use super::bvh::LightBounds;
use super::{sample_at_point, EmittedRay, LightKind, LightModel, LightSample};
use crate::accel::Aggregate;
use crate::geometry::{luminance, Bounds3, Ray};
use crate::sampling::{uniform_sample_sphere, uniform_sphere_pdf};
use crate::scene::{ParamSpec, ParamValues, Support};
use crate::shapes::SurfacePoint;
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::f32::consts::PI;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_any("I", [1.0; 3], "radiant intensity"),
    ParamSpec::spectrum_or_float(
        "scale",
        [1.0; 3],
        "multiplies I (a spectrum in pbrt-v3; pbrs also takes a float)",
    ),
    ParamSpec::point3(
        "from",
        [0.0; 3],
        "position, added to CTM·origin (light-to-world = Translate(from)·CTM)",
    ),
];

pub const KIND: LightKind = LightKind {
    name: "point",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "an isotropic point light of intensity I·scale",
    build: |p, ctm, _| Some(PointLight::new(p, ctm).into()),
};

#[derive(Clone, Copy, Debug)]
pub struct PointLight {
    /// World-space position.
    pub p: Vec3,
    /// `I`·`scale`.
    pub intensity: Vec3,
}

impl PointLight {
    pub fn new(p: &ParamValues, ctm: DMat4) -> PointLight {
        let intensity = p.spectrum("I") * p.spectrum("scale");
        let from = p.point("from");
        PointLight {
            p: (ctm.transform_point3(DVec3::ZERO) + from).as_vec3(),
            intensity,
        }
    }
}

impl LightModel for PointLight {
    #[inline]
    fn is_delta(&self) -> bool {
        true
    }

    fn power(&self) -> Vec3 {
        4.0 * PI * self.intensity
    }

    #[inline]
    fn sample_li(&self, r: &SurfacePoint, _u: Vec2, _geom: &Aggregate) -> Option<LightSample> {
        sample_at_point(self.p, r, |_| self.intensity)
    }

    /// pbrt-v3's: no density by area (a point), uniform over the sphere.
    fn pdf_le(&self, _d: Vec3, _n: Vec3) -> (f32, f32) {
        (0.0, uniform_sphere_pdf())
    }

    /// pbrt-v3's: a direction uniform over the sphere.
    fn sample_le(&self, u1: Vec2, _u2: Vec2, _geom: &Aggregate) -> Option<EmittedRay> {
        let d = uniform_sample_sphere(u1);
        Some(EmittedRay {
            le: self.intensity,
            ray: Ray::new(self.p, d),
            n: d,
            pdf_pos: 1.0,
            pdf_dir: uniform_sphere_pdf(),
        })
    }

    /// pbrt-v4's: a point emitting in every direction, φ = 4π·I.
    fn bounds(&self, _geom: &Aggregate) -> Option<LightBounds> {
        Some(LightBounds {
            bounds: Bounds3::from_point(self.p),
            w: Vec3::Z,
            phi: 4.0 * PI * luminance(self.intensity),
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        })
    }
}
