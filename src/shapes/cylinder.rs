//! pbrt-v3's `cylinder`: the tube x² + y² = `radius`² of its object space
//! for z in [`zmin`, `zmax`] and φ in [0, `phimax`], open at both ends; its
//! normal points away from the axis.
//!
//! | parameter | type  | pbrt-v3 default |
//! |-----------|-------|-----------------|
//! | `radius`  | float | 1               |
//! | `zmin`    | float | -1              |
//! | `zmax`    | float | 1               |
//! | `phimax`  | float | 360 (degrees)   |
//!
//! Ray tests run in object space in f64; the hit is reprojected onto the
//! tube, with pbrt-v3's object-space error bound γ3·|(x, y, 0)|. Area
//! sampling is pbrt-v3's `Cylinder::Sample` (uniform in z and φ), density
//! 1/(world area) (pbrt-v3 uses the object-space area).

use super::analytic::{phi_of, Analytic, AnalyticHit, Placed};
use super::{at_origin, ShapeInput, ShapeKind, Surface, PHIMAX};
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::{gamma, Bounds3};
use crate::scene::{ParamSpec, ParamValues, Support};
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::f64::consts::TAU;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::float("radius", 1.0, "radius (> 0)"),
    ParamSpec::float("zmin", -1.0, "lower end (pbrt-v3 orders zmin and zmax)"),
    ParamSpec::float("zmax", 1.0, "upper end"),
    PHIMAX,
];

pub const KIND: ShapeKind = ShapeKind {
    name: "cylinder",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a cylinder (or a sector of one) about the z axis. Open tube; zmin/zmax ordered, phimax clamped as pbrt-v3; radius ≤ 0: error; zmin = zmax or phimax 0: warning, skipped; area lights sampled uniformly in z and φ (pbrt-v3's `Cylinder::Sample`)",
    build,
};

/// pbrt-v3's checks: a positive radius and finite ends (error), a
/// non-empty extent (warning, skipped).
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Surface> {
    let radius = p.float("radius");
    let (zmin, zmax) = (p.float("zmin"), p.float("zmax"));
    let phimax = p.float("phimax").clamp(0.0, 360.0);
    if radius.is_nan()
        || radius <= 0.0
        || !radius.is_finite()
        || !zmin.is_finite()
        || !zmax.is_finite()
    {
        r.error(
            Some("radius"),
            format!("cylinder radius {radius} (zmin {zmin}, zmax {zmax}) is not a positive 32-bit float"),
            "bad cylinder",
        );
        return None;
    }
    // pbrt-v3 orders zmin and zmax itself.
    let (z0, z1) = (zmin.min(zmax), zmin.max(zmax));
    if z0 >= z1 || phimax <= 0.0 {
        r.warn(
            None,
            "cylinder with an empty extent (zmin = zmax or phimax 0): skipped".into(),
            "empty cylinder",
        );
        return None;
    }
    at_origin(Cylinder::new(Placed::origin((radius, z0, z1, phimax))))
}

#[derive(Clone, Debug)]
pub struct Cylinder {
    /// Its parameters, placement, material and area light.
    pub at: Placed<(f32, f32, f32, f32)>,
    pub radius: f64,
    pub z_min: f64,
    pub z_max: f64,
    /// Radians.
    pub phi_max: f64,
    area: f32,
}

impl Cylinder {
    pub fn new(at: Placed<(f32, f32, f32, f32)>) -> Cylinder {
        let (radius, z_min, z_max, phi_max_deg) = at.args;
        let r = radius.abs() as f64;
        let (zmin, zmax) = (z_min.min(z_max) as f64, z_min.max(z_max) as f64);
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let place = &at.place;
        // World area: exact for similarities, a volume-based estimate
        // otherwise (only light power reads it then; the density is exact).
        let scale2 = place.det_abs.powf(2.0 / 3.0);
        Cylinder {
            radius: r,
            z_min: zmin,
            z_max: zmax,
            phi_max,
            area: ((zmax - zmin) * r * phi_max * scale2) as f32,
            at,
        }
    }

    /// World-space surface point for an object-space point on the tube,
    /// with pbrt-v3's object-space error bound γ3·|(x, y, 0)|.
    #[inline]
    fn point_at(&self, p_obj: DVec3) -> SurfacePoint {
        let obj_err = DVec3::new(p_obj.x.abs(), p_obj.y.abs(), 0.0) * gamma(3) as f64;
        let n = self.at.place.normal(DVec3::new(p_obj.x, p_obj.y, 0.0));
        self.at.place.exact_point(p_obj, Some(obj_err), n)
    }
}

impl Analytic for Cylinder {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        Cylinder::new(self.at.again(to_world, reverse, material))
    }

    fn is_valid(&self) -> bool {
        self.radius > 0.0 && self.z_max > self.z_min && self.at.place.holds(self.area)
    }

    fn area(&self) -> f32 {
        self.area
    }

    fn bounds(&self) -> Bounds3 {
        self.at
            .place
            .zone_bounds(self.radius, self.z_min, self.z_max)
    }

    /// Closest hit with 0 < t < t_max (pbrt-v3's `Cylinder::Intersect`).
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        let (oo, od) = self.at.place.ray_to_object(o, d);
        let a = od.x * od.x + od.y * od.y;
        if a == 0.0 {
            return None;
        }
        // Stable quadratic with the discriminant from the closest approach
        // to the axis (as the sphere's).
        let b = 2.0 * (od.x * oo.x + od.y * oo.y);
        let (vx, vy) = (oo.x - b / (2.0 * a) * od.x, oo.y - b / (2.0 * a) * od.y);
        let len = (vx * vx + vy * vy).sqrt();
        let c = oo.x * oo.x + oo.y * oo.y - self.radius * self.radius;
        let (t0, t1) = super::stable_roots(a, b, c, self.radius, len)?;
        let t_max = t_max as f64;
        for t in [t0, t1] {
            if !(t > 0.0 && t < t_max && t as f32 > 0.0) {
                continue;
            }
            let mut p = oo + t * od;
            let hit_r = (p.x * p.x + p.y * p.y).sqrt();
            p.x *= self.radius / hit_r;
            p.y *= self.radius / hit_r;
            if p.z < self.z_min || p.z > self.z_max {
                continue;
            }
            if self.phi_max < TAU && phi_of(p) > self.phi_max {
                continue;
            }
            return Some((t as f32, AnalyticHit::Exact(p)));
        }
        None
    }

    #[inline]
    fn surface_point(&self, h: AnalyticHit) -> SurfacePoint {
        self.point_at(h.point_and_error().0)
    }

    /// u = φ/φmax, v = (z − zmin)/(zmax − zmin); the Weingarten equations
    /// for a tube give dn/du = dp/du / radius and dn/dv = 0.
    #[inline]
    fn diff_geom(&self, h: AnalyticHit) -> DiffGeom {
        let p_obj = h.point_and_error().0;
        let u = phi_of(p_obj) / self.phi_max;
        let v = (p_obj.z - self.z_min) / (self.z_max - self.z_min);
        let dpdu = DVec3::new(-self.phi_max * p_obj.y, self.phi_max * p_obj.x, 0.0);
        let dpdv = DVec3::new(0.0, 0.0, self.z_max - self.z_min);
        let dndu = self.at.place.normal_derivative(dpdu / self.radius);
        let (dpdu, dpdv) = (self.at.place.vector(dpdu), self.at.place.vector(dpdv));
        DiffGeom {
            uv: Vec2::new(u as f32, v as f32),
            dpdu,
            dpdv,
            dndu,
            shading_dpdu: dpdu,
            shading_dpdv: dpdv,
            shading_dndu: dndu,
            ..DiffGeom::ZERO
        }
    }

    /// dA_world / dA_obj = |det M| · |M^-T n_obj|.
    #[inline]
    fn area_density(&self, p_obj: DVec3) -> f32 {
        let n_obj = DVec3::new(p_obj.x, p_obj.y, 0.0) / self.radius;
        let obj_area = (self.z_max - self.z_min) * self.radius * self.phi_max;
        let pl = &self.at.place;
        (1.0 / (obj_area * pl.det_abs * (pl.normal_matrix * n_obj).length())) as f32
    }

    /// Uniform in z and φ over the tube; density 1 / world area at the point.
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let z = self.z_min + (self.z_max - self.z_min) * u.x as f64;
        let phi = self.phi_max * u.y as f64;
        let p_obj = DVec3::new(self.radius * phi.cos(), self.radius * phi.sin(), z);
        Some(ShapeSample {
            point: self.point_at(p_obj),
            pdf: self.area_density(p_obj),
        })
    }
}
