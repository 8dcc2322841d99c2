//! `spot`: a point light emitting in a cone (pbrt-v3's `SpotLight`), with
//! a smooth falloff towards the cone's edge.
//!
//! | parameter | type | pbrt-v3 default | |
//! |---|---|---|---|
//! | `I` | spectrum | 1 | radiant intensity on the axis |
//! | `scale` | spectrum or float | 1 | multiplies `I` (pbrt-v3 reads a spectrum; pbrs also takes a float) |
//! | `coneangle` | float | 30 | half-angle of the cone, degrees |
//! | `conedeltaangle` | float | 5 | width of the falloff inside the cone's edge, degrees |
//! | `from` | point3 | 0 0 0 | position |
//! | `to` | point3 | 0 0 1 | a point on the axis |
//!
//! As pbrt-v3's `CreateSpotLight`: light-to-world = CTM · Translate(`from`)
//! · Inverse(dirToZ), the frame of `CoordinateSystem(normalize(to − from))`.
//! `from` = `to` (no direction) and a light-to-world with non-finite
//! entries: warning, the light is skipped. Falloff: 1 inside
//! `coneangle − conedeltaangle`, 0 outside `coneangle`, and the fourth power
//! of (cos θ − cos total)/(cos falloff − cos total) between.

use super::bvh::{safe_acos, LightBounds};
use super::{sample_at_point, EmittedRay, LightKind, LightModel, LightSample};
use crate::accel::Aggregate;
use crate::geometry::{luminance, Bounds3, Frame, Ray};
use crate::sampling::{uniform_cone_pdf, uniform_sample_cone};
use crate::scene::{ParamSpec, ParamValues, Report, Support};
use crate::shapes::SurfacePoint;
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::f32::consts::PI;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_any("I", [1.0; 3], "radiant intensity on the axis"),
    ParamSpec::spectrum_or_float(
        "scale",
        [1.0; 3],
        "multiplies I (a spectrum in pbrt-v3; pbrs also takes a float)",
    ),
    ParamSpec::float("coneangle", 30.0, "half-angle of the cone, in degrees"),
    ParamSpec::float(
        "conedeltaangle",
        5.0,
        "width of the falloff inside the cone's edge, in degrees",
    ),
    ParamSpec::point3("from", [0.0; 3], "position"),
    ParamSpec::point3("to", [0.0, 0.0, 1.0], "a point on the axis"),
];

pub const KIND: LightKind = LightKind {
    name: "spot",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a point light emitting I·scale in a cone from `from` towards `to` (light-to-world = CTM · Translate(from) · frame(to − from), as pbrt-v3), falling off smoothly over conedeltaangle (from = to: warning, skipped)",
    build: |p, ctm, report| SpotLight::new(p, ctm, report).map(Into::into),
};

#[derive(Clone, Copy, Debug)]
pub struct SpotLight {
    /// World-space position.
    pub p: Vec3,
    /// Around the axis (`frame.n`, world space).
    pub frame: Frame,
    /// `I`·`scale`.
    pub intensity: Vec3,
    pub cos_total: f32,
    pub cos_falloff_start: f32,
}

impl SpotLight {
    /// pbrt-v3's `CreateSpotLight`; `None` (after a warning) when the light
    /// has no direction or no finite transform.
    pub fn new(p: &ParamValues, ctm: DMat4, report: &mut dyn Report) -> Option<SpotLight> {
        let intensity = p.spectrum("I") * p.spectrum("scale");
        let cone = p.float("coneangle");
        let delta = p.float("conedeltaangle");
        let from = p.point("from");
        let dir = p.point("to") - from;
        if dir.length_squared() == 0.0 {
            report.warn(
                None,
                "spot light with \"from\" equal to \"to\" has no direction: skipped".into(),
                "degenerate spot light",
            );
            return None;
        }
        let dir = dir.normalize();
        // pbrt-v3 CoordinateSystem(dir, &du, &dv); light2world = CTM · Translate(from) · Inverse(dirToZ).
        let du = if dir.x.abs() > dir.y.abs() {
            DVec3::new(-dir.z, 0.0, dir.x) / (dir.x * dir.x + dir.z * dir.z).sqrt()
        } else {
            DVec3::new(0.0, dir.z, -dir.y) / (dir.y * dir.y + dir.z * dir.z).sqrt()
        };
        let dv = dir.cross(du);
        let frame = DMat4::from_cols(
            du.extend(0.0),
            dv.extend(0.0),
            dir.extend(0.0),
            glam::DVec4::W,
        );
        let light_to_world = ctm * DMat4::from_translation(from) * frame;
        if !light_to_world.is_finite() {
            report.warn(
                None,
                "spot light transform is not finite (from/to too large): skipped".into(),
                "degenerate spot light",
            );
            return None;
        }
        let axis = light_to_world
            .transform_vector3(DVec3::Z)
            .normalize()
            .as_vec3();
        Some(SpotLight {
            p: light_to_world.transform_point3(DVec3::ZERO).as_vec3(),
            frame: Frame::from_normal(axis),
            intensity,
            cos_total: cone.to_radians().cos(),
            cos_falloff_start: (cone - delta).to_radians().cos(),
        })
    }
}

impl SpotLight {
    /// pbrt-v3's `Falloff` at the cosine `cos` of a direction leaving the
    /// light with the axis.
    #[inline]
    fn falloff(&self, cos: f32) -> f32 {
        if cos < self.cos_total {
            0.0
        } else if cos > self.cos_falloff_start {
            1.0
        } else {
            let delta = (cos - self.cos_total) / (self.cos_falloff_start - self.cos_total);
            (delta * delta) * (delta * delta)
        }
    }
}

impl LightModel for SpotLight {
    #[inline]
    fn is_delta(&self) -> bool {
        true
    }

    fn power(&self) -> Vec3 {
        self.intensity * 2.0 * PI * (1.0 - 0.5 * (self.cos_falloff_start + self.cos_total))
    }

    #[inline]
    fn sample_li(&self, r: &SurfacePoint, _u: Vec2, _geom: &Aggregate) -> Option<LightSample> {
        sample_at_point(self.p, r, |w| {
            self.intensity * self.falloff(self.frame.to_local(w).z)
        })
    }

    /// pbrt-v3's: no density by area (a point), uniform over the cone.
    fn pdf_le(&self, d: Vec3, _n: Vec3) -> (f32, f32) {
        let inside = d.dot(self.frame.n) >= self.cos_total;
        (
            0.0,
            if inside {
                uniform_cone_pdf(self.cos_total)
            } else {
                0.0
            },
        )
    }

    /// pbrt-v3's: a direction uniform over the cone of `coneangle`.
    fn sample_le(&self, u1: Vec2, _u2: Vec2, _geom: &Aggregate) -> Option<EmittedRay> {
        let local = uniform_sample_cone(u1, self.cos_total);
        let d = self.frame.from_local(local);
        Some(EmittedRay {
            le: self.intensity * self.falloff(local.z),
            ray: Ray::new(self.p, d),
            n: d,
            pdf_pos: 1.0,
            pdf_dir: uniform_cone_pdf(self.cos_total),
        })
    }

    /// pbrt-v4's: a point emitting in the falloff cone and spreading to the
    /// total cone, φ = 4π·I.
    fn bounds(&self, _geom: &Aggregate) -> Option<LightBounds> {
        Some(LightBounds {
            bounds: Bounds3::from_point(self.p),
            w: self.frame.n,
            phi: 4.0 * PI * luminance(self.intensity),
            cos_theta_o: self.cos_falloff_start,
            cos_theta_e: (safe_acos(self.cos_total) - safe_acos(self.cos_falloff_start)).cos(),
            two_sided: false,
        })
    }
}
