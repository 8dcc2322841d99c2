//! pbrt-v3's `cone`: x² + y² = (`radius`/`height`)² (z − `height`)² of its
//! object space for z in [0, `height`] (base circle of `radius` at z = 0,
//! apex at z = `height`), φ in [0, `phimax`]; open at the base. Its normal
//! points away from the axis.
//!
//! | parameter | type  | pbrt-v3 default |
//! |-----------|-------|-----------------|
//! | `radius`  | float | 1               |
//! | `height`  | float | 1               |
//! | `phimax`  | float | 360 (degrees)   |
//!
//! Ray tests are pbrt-v3's: f32 in object space with running error bounds
//! (`EFloat`), its choice of root, and the hit's error bound from the same
//! intervals. pbrt-v3's images show what that precision gives (rays leaving
//! the surface near the apex sometimes re-hit it; an f64 test gave a cone up
//! to 1% brighter there than pbrt-v3's), so pbrs keeps it. u = φ/φmax,
//! v = z/height, dp/du, dp/dv and the normal derivatives as pbrt-v3's
//! `Cone::Intersect`. pbrt-v3 cannot sample cones (`Cone::Sample` aborts), so
//! a cone area light is a pbrs extension: uniform by area (v = 1 − √(1 − ξ)),
//! with the exact world-area density.

use super::analytic::{pbrt_closest, phi_f32, phi_of, Analytic, AnalyticHit, Placed};
use super::{at_origin, check_floats, phi_max, ShapeInput, ShapeKind, Surface, PHIMAX};
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::efloat::{quadratic, transform_ray, EFloat};
use crate::geometry::{gamma, Bounds3};
use crate::scene::{ParamSpec, ParamValues, Support};
use glam::{DMat4, DVec3, Vec2, Vec3};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::float("radius", 1.0, "radius of its base (> 0)"),
    ParamSpec::float("height", 1.0, "height of its apex (> 0)"),
    PHIMAX,
];

pub const KIND: ShapeKind = ShapeKind {
    name: "cone",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a cone (or a sector of one) from a base at z = 0 to its apex. Open at the base; radius or height ≤ 0 or not a 32-bit float: error; phimax 0: warning, skipped. Intersected as pbrt-v3 (f32 with running error bounds). Area lights: a pbrs extension (pbrt-v3 cannot sample cones), uniform by area",
    build,
};

/// pbrt-v3's checks: radius and height positive 32-bit floats (error),
/// phimax > 0 (warning, skipped).
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Surface> {
    let radius = p.float("radius");
    let height = p.float("height");
    if !check_floats(
        "cone",
        r,
        &[("radius", radius, true), ("height", height, true)],
    ) {
        return None;
    }
    let phimax = phi_max("cone", p, r)?;
    at_origin(Cone::new(Placed::origin((radius, height, phimax))))
}

#[derive(Clone, Debug)]
pub struct Cone {
    /// Its parameters, placement, material and area light.
    pub at: Placed<(f32, f32, f32)>,
    pub radius: f64,
    pub height: f64,
    /// Radians.
    pub phi_max: f64,
    obj_area: f64,
    area: f32,
}

impl Cone {
    pub fn new(at: Placed<(f32, f32, f32)>) -> Cone {
        let (radius, height, phi_max_deg) = at.args;
        let (r, h) = (radius.abs() as f64, height as f64);
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let place = &at.place;
        let obj_area = r * (h * h + r * r).sqrt() * phi_max / 2.0;
        Cone {
            radius: r,
            height: h,
            phi_max,
            area: place.world_area(obj_area),
            obj_area,
            at,
        }
    }

    /// (radius/height)²: the cone is x² + y² = k (z − h)².
    #[inline]
    fn k(&self) -> f64 {
        let s = self.radius / self.height;
        s * s
    }

    /// ∂p/∂u and ∂p/∂v (pbrt-v3's parametrisation).
    #[inline]
    fn tangents(&self, p: DVec3) -> (DVec3, DVec3) {
        let (h, pm) = (self.height, self.phi_max);
        let v = p.z / h;
        (
            DVec3::new(-pm * p.y, pm * p.x, 0.0),
            DVec3::new(-p.x / (1.0 - v), -p.y / (1.0 - v), h),
        )
    }

    /// Outward object normal: ∂p/∂u × ∂p/∂v as pbrt-v3 (the implicit
    /// gradient where that is undefined, at the apex, and the axis on it).
    #[inline]
    fn normal_obj(&self, p: DVec3) -> DVec3 {
        let (dpdu, dpdv) = self.tangents(p);
        let n = dpdu.cross(dpdv);
        if n.is_finite() && n.length_squared() > 0.0 {
            n
        } else {
            // On the axis (the apex): the axis itself, the limit of the
            // normals' mean.
            let g = DVec3::new(p.x, p.y, self.k() * (self.height - p.z));
            if g.length_squared() > 0.0 {
                g
            } else {
                DVec3::Z
            }
        }
    }

    #[inline]
    fn point_at(&self, p_obj: DVec3, err: DVec3) -> SurfacePoint {
        self.at
            .place
            .surface_point(p_obj, self.normal_obj(p_obj), err)
    }
}

impl Analytic for Cone {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        Cone::new(self.at.again(to_world, reverse, material))
    }

    fn area(&self) -> f32 {
        self.area
    }

    fn is_valid(&self) -> bool {
        self.radius > 0.0
            && self.height > 0.0
            && self.at.place.is_valid()
            && self.at.place.holds(self.area)
    }

    fn bounds(&self) -> Bounds3 {
        let r = self.radius;
        self.at
            .place
            .bounds(DVec3::new(-r, -r, 0.0), DVec3::new(r, r, self.height))
    }

    /// Closest hit with 0 < t < t_max, as pbrt-v3's `Cone::Intersect`
    /// computes it (f32 with running error bounds): t, the object-space
    /// point and its error bound.
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        let (o, d) = transform_ray(&self.at.place.world_to_object_f32, o, d);
        let (r, h) = (self.radius as f32, self.height as f32);
        let k = EFloat::exact(r) / EFloat::exact(h);
        let k = k * k;
        let [ox, oy, oz] = o;
        let [dx, dy, dz] = d;
        let ozh = oz - EFloat::exact(h);
        let a = dx * dx + dy * dy - k * dz * dz;
        let b = 2.0 * (dx * ox + dy * oy - k * dz * ozh);
        let c = ox * ox + oy * oy - k * ozh * ozh;
        let phi_max = self.phi_max as f32;
        pbrt_closest(quadratic(a, b, c)?, o, d, t_max, |p| {
            p.z < 0.0 || p.z > h || phi_f32(p) > phi_max
        })
        .map(|(t, p, err)| (t, AnalyticHit::Bounded { p, err }))
    }

    #[inline]
    fn surface_point(&self, h: AnalyticHit) -> SurfacePoint {
        let (p, err) = h.point_and_error();
        self.point_at(p, err)
    }

    #[inline]
    fn diff_geom(&self, h: AnalyticHit) -> DiffGeom {
        let p = h.point_and_error().0;
        let (h, pm) = (self.height, self.phi_max);
        let u = phi_of(p) / pm;
        let v = p.z / h;
        let (dpdu, dpdv) = self.tangents(p);
        let d2uu = -pm * pm * DVec3::new(p.x, p.y, 0.0);
        let d2uv = pm / (1.0 - v) * DVec3::new(p.y, -p.x, 0.0);
        self.at
            .place
            .diff_geom((u, v), dpdu, dpdv, [d2uu, d2uv, DVec3::ZERO])
    }

    /// Density by world area at an object point.
    #[inline]
    fn area_density(&self, p_obj: DVec3) -> f32 {
        (1.0 / (self.obj_area * self.at.place.area_scale(self.normal_obj(p_obj)))) as f32
    }

    /// Uniform by area: the radius fraction s = √(1 − ξ₁) has density 2s.
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let s = (1.0 - u.x as f64).max(0.0).sqrt();
        let phi = self.phi_max * u.y as f64;
        let rho = self.radius * s;
        let p_obj = DVec3::new(rho * phi.cos(), rho * phi.sin(), self.height * (1.0 - s));
        Some(ShapeSample {
            point: self.point_at(p_obj, p_obj.abs() * gamma(5) as f64),
            pdf: self.area_density(p_obj),
        })
    }
}
