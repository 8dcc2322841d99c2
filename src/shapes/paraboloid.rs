//! pbrt-v3's `paraboloid`: x² + y² = `radius`² · z / `zmax` of its object
//! space (radius `radius` at z = `zmax`, apex at the origin) for z in
//! [`zmin`, `zmax`] and φ in [0, `phimax`]; open at the top. Its normal
//! points away from the axis (and down).
//!
//! | parameter | type  | pbrt-v3 default |
//! |-----------|-------|-----------------|
//! | `radius`  | float | 1               |
//! | `zmin`    | float | 0               |
//! | `zmax`    | float | 1               |
//! | `phimax`  | float | 360 (degrees)   |
//!
//! Ray tests are pbrt-v3's: f32 in object space with running error bounds
//! (`EFloat`), as the cone's (see there). u = φ/φmax,
//! v = (z − zmin)/(zmax − zmin), derivatives as pbrt-v3's
//! `Paraboloid::Intersect`. pbrt-v3 cannot sample paraboloids, so a
//! paraboloid area light is a pbrs extension: uniform by area (the area
//! above z grows as (4cz + 1)^{3/2}, inverted in closed form), with the
//! exact world-area density.

use super::analytic::{pbrt_closest, phi_f32, phi_of, Analytic, AnalyticHit, Placed};
use super::{at_origin, check_floats, phi_max, ShapeInput, ShapeKind, Surface, PHIMAX};
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::efloat::{quadratic, transform_ray, EFloat};
use crate::geometry::{gamma, Bounds3};
use crate::scene::{ParamSpec, ParamValues, Support};
use glam::{DMat4, DVec3, Vec2, Vec3};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::float("radius", 1.0, "radius at zmax (> 0)"),
    ParamSpec::float("zmin", 0.0, "lower end (≥ 0; pbrt-v3 orders zmin and zmax)"),
    ParamSpec::float("zmax", 1.0, "upper end (> 0)"),
    PHIMAX,
];

pub const KIND: ShapeKind = ShapeKind {
    name: "paraboloid",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a paraboloid (or a sector of one) opening upwards from z = 0: x² + y² = radius²·z/zmax; zmin/zmax ordered; radius ≤ 0 or zmax ≤ 0: error; zmin < 0: warning, 0; zmin = zmax or phimax 0: warning, skipped. Intersected as pbrt-v3 (f32 with running error bounds). Area lights: a pbrs extension, uniform by area",
    build,
};

/// pbrt-v3's checks: finite values, a positive radius and zmax (error); a
/// zmin below the apex is 0 (warning); an empty extent is skipped.
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Surface> {
    let radius = p.float("radius");
    let (zmin, zmax) = (p.float("zmin"), p.float("zmax"));
    let values = [
        ("radius", radius, true),
        ("zmin", zmin, false),
        ("zmax", zmax, false),
    ];
    if !check_floats("paraboloid", r, &values) {
        return None;
    }
    // pbrt-v3 orders zmin and zmax; its surface x² + y² = r² z / zmax has
    // points only where z / zmax >= 0.
    let (mut z0, z1) = (zmin.min(zmax), zmin.max(zmax));
    if z1 <= 0.0 {
        r.error(
            Some("zmax"),
            format!(
                "paraboloid zmax {z1} is not positive (the paraboloid opens upwards from z = 0)"
            ),
            "zmax must be > 0",
        );
        return None;
    }
    if z0 < 0.0 {
        r.warn(
            Some("zmin"),
            format!("paraboloid zmin {z0} is below its apex at z = 0: 0 is used (the surface has no points below)"),
            "negative zmin",
        );
        z0 = 0.0;
    }
    if z0 >= z1 {
        r.warn(
            None,
            format!("paraboloid with zmin = zmax = {z1}: an empty surface, skipped"),
            "empty paraboloid",
        );
        return None;
    }
    let phimax = phi_max("paraboloid", p, r)?;
    at_origin(Paraboloid::new(Placed::origin((radius, z0, z1, phimax))))
}

#[derive(Clone, Debug)]
pub struct Paraboloid {
    /// Its parameters, placement, material and area light.
    pub at: Placed<(f32, f32, f32, f32)>,
    pub radius: f64,
    pub z_min: f64,
    pub z_max: f64,
    /// Radians.
    pub phi_max: f64,
    /// (4c·zmin + 1)^{3/2} and (4c·zmax + 1)^{3/2}, c = zmax / radius².
    a_min: f64,
    a_max: f64,
    obj_area: f64,
    area: f32,
}

impl Paraboloid {
    /// The loader ensures 0 <= z_min < z_max and radius > 0.
    pub fn new(at: Placed<(f32, f32, f32, f32)>) -> Paraboloid {
        let (radius, z_min, z_max, phi_max_deg) = at.args;
        let r = radius.abs() as f64;
        let (z0, z1) = (z_min.min(z_max) as f64, z_min.max(z_max) as f64);
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let place = &at.place;
        let c = z1 / (r * r);
        let (a_min, a_max) = (
            (4.0 * c * z0 + 1.0).powf(1.5),
            (4.0 * c * z1 + 1.0).powf(1.5),
        );
        let obj_area = phi_max / (12.0 * c * c) * (a_max - a_min);
        Paraboloid {
            radius: r,
            z_min: z0,
            z_max: z1,
            phi_max,
            area: place.world_area(obj_area),
            a_min,
            a_max,
            obj_area,
            at,
        }
    }

    /// c = zmax / radius²: the surface is c (x² + y²) = z.
    #[inline]
    fn c(&self) -> f64 {
        self.z_max / (self.radius * self.radius)
    }

    #[inline]
    fn tangents(&self, p: DVec3) -> (DVec3, DVec3) {
        let (pm, dz) = (self.phi_max, self.z_max - self.z_min);
        (
            DVec3::new(-pm * p.y, pm * p.x, 0.0),
            dz * DVec3::new(p.x / (2.0 * p.z), p.y / (2.0 * p.z), 1.0),
        )
    }

    /// Outward object normal: ∂p/∂u × ∂p/∂v as pbrt-v3 (the implicit
    /// gradient at the apex, where that is undefined).
    #[inline]
    fn normal_obj(&self, p: DVec3) -> DVec3 {
        let (dpdu, dpdv) = self.tangents(p);
        let n = dpdu.cross(dpdv);
        if n.is_finite() && n.length_squared() > 0.0 {
            n
        } else {
            let k = self.c();
            DVec3::new(2.0 * k * p.x, 2.0 * k * p.y, -1.0)
        }
    }

    #[inline]
    fn point_at(&self, p_obj: DVec3, err: DVec3) -> SurfacePoint {
        self.at
            .place
            .surface_point(p_obj, self.normal_obj(p_obj), err)
    }
}

impl Analytic for Paraboloid {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        Paraboloid::new(self.at.again(to_world, reverse, material))
    }

    fn area(&self) -> f32 {
        self.area
    }

    fn is_valid(&self) -> bool {
        self.radius > 0.0
            && self.z_max > self.z_min
            && self.z_min >= 0.0
            && self.at.place.is_valid()
            && self.at.place.holds(self.area)
    }

    fn bounds(&self) -> Bounds3 {
        self.at
            .place
            .zone_bounds(self.radius, self.z_min, self.z_max)
    }

    /// Closest hit with 0 < t < t_max, as pbrt-v3's `Paraboloid::Intersect`
    /// computes it (f32 with running error bounds).
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        let (o, d) = transform_ray(&self.at.place.world_to_object_f32, o, d);
        let (r, z0, z1) = (self.radius as f32, self.z_min as f32, self.z_max as f32);
        let k = EFloat::exact(z1) / (EFloat::exact(r) * EFloat::exact(r));
        let [ox, oy, oz] = o;
        let [dx, dy, dz] = d;
        let a = k * (dx * dx + dy * dy);
        let b = 2.0 * k * (dx * ox + dy * oy) - dz;
        let c = k * (ox * ox + oy * oy) - oz;
        let phi_max = self.phi_max as f32;
        pbrt_closest(quadratic(a, b, c)?, o, d, t_max, |p| {
            p.z < z0 || p.z > z1 || phi_f32(p) > phi_max
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
        let (pm, dz) = (self.phi_max, self.z_max - self.z_min);
        let u = phi_of(p) / pm;
        let v = (p.z - self.z_min) / dz;
        let (dpdu, dpdv) = self.tangents(p);
        let d2uu = -pm * pm * DVec3::new(p.x, p.y, 0.0);
        let d2uv = dz * pm * DVec3::new(-p.y / (2.0 * p.z), p.x / (2.0 * p.z), 0.0);
        let d2vv = -dz * dz * DVec3::new(p.x / (4.0 * p.z * p.z), p.y / (4.0 * p.z * p.z), 0.0);
        self.at
            .place
            .diff_geom((u, v), dpdu, dpdv, [d2uu, d2uv, d2vv])
    }

    #[inline]
    fn area_density(&self, p_obj: DVec3) -> f32 {
        (1.0 / (self.obj_area * self.at.place.area_scale(self.normal_obj(p_obj)))) as f32
    }

    /// Uniform by area.
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let k = self.c();
        let a = self.a_min + (self.a_max - self.a_min) * u.x as f64;
        let z = ((a.powf(2.0 / 3.0) - 1.0) / (4.0 * k)).clamp(self.z_min, self.z_max);
        let phi = self.phi_max * u.y as f64;
        let rho = (z / k).sqrt();
        let p_obj = DVec3::new(rho * phi.cos(), rho * phi.sin(), z);
        Some(ShapeSample {
            point: self.point_at(p_obj, p_obj.abs() * gamma(5) as f64),
            pdf: self.area_density(p_obj),
        })
    }
}
