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

use super::quadric::{Analytic, QuadricHit};
use super::{at_origin, check_floats, phi_max, Geometry, ShapeInput, ShapeKind, ORIGIN, PHIMAX};
use crate::scene::{ParamSpec, ParamValues, Support};

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
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Geometry> {
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
    at_origin(Cone::new(radius, height, phimax, ORIGIN, false, 0))
}

use super::quadric::{pbrt_closest, phi_f32, phi_of, Placement};
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::efloat::{quadratic, transform_ray, EFloat};
use crate::geometry::{gamma, Bounds3};
use glam::{DMat4, DVec3, Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct Cone {
    /// The arguments of [`Cone::new`] but the placement: the shape as its
    /// kind built it, placed again by [`Analytic::placed`].
    pub args: (f32, f32, f32),
    pub radius: f64,
    pub height: f64,
    /// Radians.
    pub phi_max: f64,
    pub place: Placement,
    pub material: u32,
    pub light: Option<u32>,
    obj_area: f64,
    area: f32,
}

impl Cone {
    pub fn new(
        radius: f32,
        height: f32,
        phi_max_deg: f32,
        object_to_world: DMat4,
        reverse: bool,
        material: u32,
    ) -> Cone {
        let (r, h) = (radius.abs() as f64, height as f64);
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let place = Placement::new(object_to_world, reverse);
        let obj_area = r * (h * h + r * r).sqrt() * phi_max / 2.0;
        Cone {
            args: (radius, height, phi_max_deg),
            radius: r,
            height: h,
            phi_max,
            area: place.world_area(obj_area),
            place,
            material,
            light: None,
            obj_area,
        }
    }

    pub fn area(&self) -> f32 {
        self.area
    }

    pub fn is_valid(&self) -> bool {
        self.place.is_valid()
            && self.radius > 0.0
            && self.height > 0.0
            && self.area > 0.0
            && self.area.is_finite()
    }

    pub fn bounds(&self) -> Bounds3 {
        let r = self.radius;
        self.place
            .bounds(DVec3::new(-r, -r, 0.0), DVec3::new(r, r, self.height))
    }

    /// (radius/height)²: the cone is x² + y² = k (z − h)².
    #[inline]
    fn k(&self) -> f64 {
        let s = self.radius / self.height;
        s * s
    }

    /// Closest hit with 0 < t < t_max, as pbrt-v3's `Cone::Intersect`
    /// computes it (f32 with running error bounds): t, the object-space
    /// point and its error bound.
    #[inline]
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, Vec3, Vec3)> {
        let (o, d) = transform_ray(&self.place.world_to_object_f32, o, d);
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

    pub fn surface_point(&self, p_obj: DVec3, err: DVec3) -> SurfacePoint {
        self.place.surface_point(p_obj, self.normal_obj(p_obj), err)
    }

    pub fn diff_geom(&self, p: DVec3) -> DiffGeom {
        let (h, pm) = (self.height, self.phi_max);
        let u = phi_of(p) / pm;
        let v = p.z / h;
        let (dpdu, dpdv) = self.tangents(p);
        let d2uu = -pm * pm * DVec3::new(p.x, p.y, 0.0);
        let d2uv = pm / (1.0 - v) * DVec3::new(p.y, -p.x, 0.0);
        self.place
            .diff_geom((u, v), dpdu, dpdv, [d2uu, d2uv, DVec3::ZERO])
    }

    /// Density by world area at an object point.
    #[inline]
    pub fn area_density(&self, p_obj: DVec3) -> f32 {
        (1.0 / (self.obj_area * self.place.area_scale(self.normal_obj(p_obj)))) as f32
    }

    /// Uniform by area: the radius fraction s = √(1 − ξ₁) has density 2s.
    pub fn sample_area(&self, u: Vec2) -> ShapeSample {
        let s = (1.0 - u.x as f64).max(0.0).sqrt();
        let phi = self.phi_max * u.y as f64;
        let rho = self.radius * s;
        let p_obj = DVec3::new(rho * phi.cos(), rho * phi.sin(), self.height * (1.0 - s));
        ShapeSample {
            point: self.surface_point(p_obj, p_obj.abs() * gamma(5) as f64),
            pdf: self.area_density(p_obj),
        }
    }
}

impl Analytic for Cone {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        let a = self.args;
        Cone::new(a.0, a.1, a.2, to_world, reverse, material)
    }
    fn valid(&self) -> bool {
        self.is_valid()
    }
    #[inline]
    fn hit(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, QuadricHit)> {
        self.intersect(o, d, t_max)
            .map(|(t, p, err)| (t, QuadricHit::Bounded { p, err }))
    }
    #[inline]
    fn point(&self, h: QuadricHit) -> SurfacePoint {
        let (p, err) = h.point_and_error();
        self.surface_point(p, err)
    }
    #[inline]
    fn geom(&self, h: QuadricHit) -> DiffGeom {
        self.diff_geom(h.point_and_error().0)
    }
    fn density_at(&self, p_obj: DVec3) -> f32 {
        self.area_density(p_obj)
    }
    fn area_sample(&self, u: Vec2) -> Option<ShapeSample> {
        Some(self.sample_area(u))
    }
}
