//! pbrt-v3's `hyperboloid`: the surface of revolution a·(x² + y²) − c·z² = 1
//! of its object space that pbrt-v3 fits to the line through `p1` and `p2`,
//! for z between their heights and φ in [0, `phimax`] measured from the
//! line's point at each height. Its normal is ∂p/∂u × ∂p/∂v (away from the
//! axis when `p2` is above `p1`).
//!
//! | parameter | type  | pbrt-v3 default |
//! |-----------|-------|-----------------|
//! | `p1`      | point | 0 0 0           |
//! | `p2`      | point | 1 1 1           |
//! | `phimax`  | float | 360 (degrees)   |
//!
//! a and c come from pbrt-v3's construction: the implicit surface through
//! `p2` and a point further along the line (stepping until the system is
//! solvable). It equals the line's surface of revolution when the line is
//! closest to the axis at z = 0, as in every useful case. (pbrt-v3's
//! defaults describe a cone, on which its construction never ends: the
//! loader rejects lines that meet the axis.)
//!
//! Ray tests are pbrt-v3's: f32 in object space with running error bounds
//! (`EFloat`), as the cone's (see there). u = φ/φmax, v = (z − p1.z)/(p2.z − p1.z), derivatives as
//! pbrt-v3's `Hyperboloid::Intersect`. The bounds are the true extent of
//! the surface over its z range (pbrt-v3's box uses the radii at `p1` and
//! `p2` only). pbrt-v3 cannot sample hyperboloids; a hyperboloid area light is
//! a pbrs extension: uniform in z and φ, with its exact world-area density.

use super::analytic::{pbrt_closest, Analytic, AnalyticHit, Placed};
use super::{at_origin, phi_max, ShapeInput, ShapeKind, Surface, PHIMAX};
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::efloat::{quadratic, transform_ray, EFloat};
use crate::geometry::{gamma, Bounds3};
use crate::scene::{ParamSpec, ParamValues, Support};
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::f64::consts::TAU;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::point3("p1", [0.0, 0.0, 0.0], "a point of the line swept about z"),
    ParamSpec::point3("p2", [1.0, 1.0, 1.0], "another point of it (p1.z ≠ p2.z)"),
    PHIMAX,
];

pub const KIND: ShapeKind = ShapeKind {
    name: "hyperboloid",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "the hyperboloid of one sheet swept by the line p1 p2 about z. The surface pbrt-v3 fits to the line p1–p2; p1.z = p2.z, a line that meets the axis (pbrt-v3's defaults: it never finishes) or a fit without points over the z range: error; phimax 0: warning, skipped. Intersected as pbrt-v3. Area lights: a pbrs extension, uniform in z and φ with the exact density",
    build,
};

/// pbrt-v3's fitting, checked: p1 and p2 finite, at different heights, on a
/// line that misses the z axis, and the fitted surface has points at every
/// height between them (errors otherwise: pbrt-v3 divides by zero, loops
/// forever or makes NaNs).
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Surface> {
    let (p1, p2) = (p.point("p1"), p.point("p2"));
    let at = Some("p1");
    if !(p1.as_vec3().is_finite() && p2.as_vec3().is_finite()) {
        r.error(
            at,
            "hyperboloid p1/p2 are not finite 32-bit floats".into(),
            "bad point",
        );
        return None;
    }
    let (p1, p2) = (p1.as_vec3(), p2.as_vec3());
    let bad = |why: &str| {
        format!(
            "hyperboloid p1 [{} {} {}], p2 [{} {} {}]: {why}",
            p1.x, p1.y, p1.z, p2.x, p2.y, p2.z
        )
    };
    if p1.z == p2.z {
        r.error(at, bad("p1 and p2 are at the same height, so they define no hyperboloid (pbrt-v3 divides by zero); use a disk for an annulus"), "p1.z = p2.z");
        return None;
    }
    let Some((a, c)) = hyperboloid_coefficients(p1.as_dvec3(), p2.as_dvec3()) else {
        r.error(at, bad("the line through them meets the z axis, which makes a cone, not a hyperboloid (pbrt-v3 never finishes building it); use a cone"), "no hyperboloid");
        return None;
    };
    let (z0, z1) = (p1.z.min(p2.z) as f64, p1.z.max(p2.z) as f64);
    let rho2 = |z: f64| (1.0 + c * z * z) / a;
    let inside = z0 < 0.0 && z1 > 0.0;
    if !(rho2(z0) > 0.0 && rho2(z1) > 0.0 && (!inside || rho2(0.0) > 0.0)) {
        r.error(at, bad("the implicit surface pbrt-v3 fits to them has no points at some heights between p1 and p2 (not a hyperboloid of one sheet there)"), "not a hyperboloid");
        return None;
    }
    let phimax = phi_max("hyperboloid", p, r)?;
    at_origin(Hyperboloid::new(Placed::origin((p1, p2, phimax))))
}

#[derive(Clone, Debug)]
pub struct Hyperboloid {
    /// Its parameters, placement, material and area light.
    pub at: Placed<(Vec3, Vec3, f32)>,
    pub p1: DVec3,
    pub p2: DVec3,
    pub z_min: f64,
    pub z_max: f64,
    /// Radians.
    pub phi_max: f64,
    /// a·(x² + y²) − c·z² = 1.
    pub a: f64,
    pub c: f64,
    r_max: f64,
    obj_area: f64,
    area: f32,
}

/// pbrt-v3's fit of a and c to the line through `p1` and `p2`; `None` when
/// the line has no hyperboloid (it is horizontal or meets the axis).
pub fn hyperboloid_coefficients(p1: DVec3, p2: DVec3) -> Option<(f64, f64)> {
    // In f32, as pbrt-v3 computes them.
    let (mut p1, mut p2) = (p1.as_vec3(), p2.as_vec3());
    if p1.z == p2.z {
        return None;
    }
    if p2.z == 0.0 {
        std::mem::swap(&mut p1, &mut p2);
    }
    let mut pp = p1;
    // pbrt-v3 steps along the line until the 2×2 system is regular; when
    // the line meets the axis it never is (pbrt-v3 loops forever).
    for _ in 0..64 {
        pp += 2.0 * (p2 - p1);
        let xy1 = pp.x * pp.x + pp.y * pp.y;
        let xy2 = p2.x * p2.x + p2.y * p2.y;
        let z2 = p2.z * p2.z;
        let a = (1.0 / xy1 - (pp.z * pp.z) / (xy1 * z2)) / (1.0 - (xy2 * pp.z * pp.z) / (xy1 * z2));
        let c = (a * xy2 - 1.0) / z2;
        if a.is_finite() && c.is_finite() {
            return Some((a as f64, c as f64));
        }
        if !pp.is_finite() {
            break;
        }
    }
    None
}

impl Hyperboloid {
    /// The loader checks `hyperboloid_coefficients` and the radius over the
    /// z range first.
    pub fn new(at: Placed<(Vec3, Vec3, f32)>) -> Hyperboloid {
        let (p1, p2, phi_max_deg) = at.args;
        let (mut p1, mut p2) = (p1.as_dvec3(), p2.as_dvec3());
        let (a, c) = hyperboloid_coefficients(p1, p2).unwrap_or((f64::NAN, f64::NAN));
        // pbrt-v3 swaps its points for the fit, and keeps them swapped (v
        // and φ are then measured from the other end).
        if p2.z == 0.0 {
            std::mem::swap(&mut p1, &mut p2);
        }
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let (z_min, z_max) = (p1.z.min(p2.z), p1.z.max(p2.z));
        let rho2 = |z: f64| (1.0 + c * z * z) / a;
        let mut r2 = rho2(z_min).max(rho2(z_max));
        if z_min < 0.0 && z_max > 0.0 {
            r2 = r2.max(rho2(0.0));
        }
        let mut h = Hyperboloid {
            p1,
            p2,
            z_min,
            z_max,
            phi_max,
            a,
            c,
            r_max: r2.sqrt(),
            obj_area: 0.0,
            area: 0.0,
            at,
        };
        h.obj_area = h.object_area();
        h.area = h.at.place.world_area(h.obj_area);
        h
    }

    /// x² + y² at height z.
    #[inline]
    fn rho2(&self, z: f64) -> f64 {
        (1.0 + self.c * z * z) / self.a
    }

    /// dA / (dz dφ) at height z: √(ρ² + (ρ dρ/dz)²).
    #[inline]
    fn area_element(&self, z: f64) -> f64 {
        let rr = self.c * z / self.a;
        (self.rho2(z).max(0.0) + rr * rr).sqrt()
    }

    /// φmax ∫ dA/(dz dφ) dz by Simpson's rule (the integrand is smooth).
    fn object_area(&self) -> f64 {
        let n = 256;
        let h = (self.z_max - self.z_min) / n as f64;
        let mut s = self.area_element(self.z_min) + self.area_element(self.z_max);
        for i in 1..n {
            let w = if i % 2 == 1 { 4.0 } else { 2.0 };
            s += w * self.area_element(self.z_min + i as f64 * h);
        }
        self.phi_max * s * h / 3.0
    }

    /// The line's point at height z (pbrt-v3's `pr`) and v.
    #[inline]
    fn line_at(&self, z: f64) -> (DVec3, f64) {
        let v = (z - self.p1.z) / (self.p2.z - self.p1.z);
        ((1.0 - v) * self.p1 + v * self.p2, v)
    }

    /// φ of p measured from the line's point at p's height, in [0, 2π).
    #[inline]
    fn phi(&self, p: DVec3) -> f64 {
        let (pr, _) = self.line_at(p.z);
        let phi = (pr.x * p.y - p.x * pr.y).atan2(p.x * pr.x + p.y * pr.y);
        if phi < 0.0 {
            phi + TAU
        } else {
            phi
        }
    }

    /// The object normal ∂p/∂u × ∂p/∂v, as pbrt-v3 orients it.
    #[inline]
    fn normal_obj(&self, p: DVec3) -> DVec3 {
        let (dpdu, dpdv) = self.tangents(p);
        dpdu.cross(dpdv)
    }

    #[inline]
    fn tangents(&self, p: DVec3) -> (DVec3, DVec3) {
        let phi = self.phi(p);
        let (s, c) = phi.sin_cos();
        let e = self.p2 - self.p1;
        let dpdu = DVec3::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        let dpdv = DVec3::new(e.x * c - e.y * s, e.x * s + e.y * c, e.z);
        (dpdu, dpdv)
    }

    #[inline]
    fn point_at(&self, p_obj: DVec3, err: DVec3) -> SurfacePoint {
        self.at
            .place
            .surface_point(p_obj, self.normal_obj(p_obj), err)
    }
}

impl Analytic for Hyperboloid {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        Hyperboloid::new(self.at.again(to_world, reverse, material))
    }

    fn area(&self) -> f32 {
        self.area
    }

    fn is_valid(&self) -> bool {
        self.a.is_finite()
            && self.c.is_finite()
            && self.z_max > self.z_min
            && self.r_max.is_finite()
            && self.at.place.is_valid()
            && self.at.place.holds(self.area)
    }

    fn bounds(&self) -> Bounds3 {
        let r = self.r_max;
        self.at
            .place
            .bounds(DVec3::new(-r, -r, self.z_min), DVec3::new(r, r, self.z_max))
    }

    /// Closest hit with 0 < t < t_max, as pbrt-v3's `Hyperboloid::Intersect`
    /// computes it (f32 with running error bounds).
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        let (o, d) = transform_ray(&self.at.place.world_to_object_f32, o, d);
        let (ah, ch) = (self.a as f32, self.c as f32);
        let [ox, oy, oz] = o;
        let [dx, dy, dz] = d;
        let a = ah * dx * dx + ah * dy * dy - ch * dz * dz;
        let b = 2.0 * (ah * dx * ox + ah * dy * oy - ch * dz * oz);
        let c = ah * ox * ox + ah * oy * oy - ch * oz * oz - EFloat::exact(1.0);
        let (z0, z1, phi_max) = (self.z_min as f32, self.z_max as f32, self.phi_max as f32);
        let (p1, p2) = (self.p1.as_vec3(), self.p2.as_vec3());
        pbrt_closest(quadratic(a, b, c)?, o, d, t_max, |p| {
            let v = (p.z - p1.z) / (p2.z - p1.z);
            let pr = (1.0 - v) * p1 + v * p2;
            let mut phi = (pr.x * p.y - p.x * pr.y).atan2(p.x * pr.x + p.y * pr.y);
            if phi < 0.0 {
                phi += std::f32::consts::TAU;
            }
            p.z < z0 || p.z > z1 || phi > phi_max
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
        let pm = self.phi_max;
        let u = self.phi(p) / pm;
        let (_, v) = self.line_at(p.z);
        let (dpdu, dpdv) = self.tangents(p);
        let d2uu = -pm * pm * DVec3::new(p.x, p.y, 0.0);
        let d2uv = pm * DVec3::new(-dpdv.y, dpdv.x, 0.0);
        self.at
            .place
            .diff_geom((u, v), dpdu, dpdv, [d2uu, d2uv, DVec3::ZERO])
    }

    /// Density by world area of uniform (z, φ) sampling at an object point.
    #[inline]
    fn area_density(&self, p_obj: DVec3) -> f32 {
        let per_obj_area =
            1.0 / (self.phi_max * (self.z_max - self.z_min) * self.area_element(p_obj.z));
        (per_obj_area / self.at.place.area_scale(self.normal_obj(p_obj))) as f32
    }

    /// Uniform in z and in φ from the line's point at that height.
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let z = self.z_min + (self.z_max - self.z_min) * u.x as f64;
        let (pr, _) = self.line_at(z);
        let phi = pr.y.atan2(pr.x) + self.phi_max * u.y as f64;
        let rho = self.rho2(z).max(0.0).sqrt();
        let p_obj = DVec3::new(rho * phi.cos(), rho * phi.sin(), z);
        Some(ShapeSample {
            point: self.point_at(p_obj, p_obj.abs() * gamma(5) as f64),
            pdf: self.area_density(p_obj),
        })
    }
}
