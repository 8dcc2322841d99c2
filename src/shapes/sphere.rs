//! pbrt-v3's `sphere`: a sphere of `radius` about its object-space origin,
//! cut to the zone `zmin`..`zmax` and to φ in [0, `phimax`].
//!
//! | parameter | type  | pbrt-v3 default |
//! |-----------|-------|-----------------|
//! | `radius`  | float | 1               |
//! | `zmin`    | float | -`radius`       |
//! | `zmax`    | float | `radius`        |
//! | `phimax`  | float | 360 (degrees)   |

use super::analytic::{Analytic, AnalyticHit, Placed};
use super::{at_origin, ShapeInput, ShapeKind, Surface, PHIMAX};
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::{gamma, offset_ray_origin, Bounds3, Frame};
use crate::sampling::uniform_cone_pdf;
use crate::scene::{ParamSpec, ParamValues, Support};
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::f32::consts::PI;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::float("radius", 1.0, "radius (> 0)"),
    ParamSpec::float_opt(
        "zmin",
        "lower end of the zone (default -radius; clamped to the sphere)",
    ),
    ParamSpec::float_opt(
        "zmax",
        "upper end of the zone (default radius; clamped to the sphere)",
    ),
    PHIMAX,
];

pub const KIND: ShapeKind = ShapeKind {
    name: "sphere",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a sphere (or a zone and sector of one) about the origin. The z range and phimax clamped as pbrt-v3; radius ≤ 0: error; empty: warning, skipped",
    build,
};

/// pbrt-v3's checks: radius > 0 (error), a non-empty zone and sector
/// (warning, skipped), a radius that fits a 32-bit float.
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Surface> {
    let radius = p.float("radius");
    if radius <= 0.0 {
        r.error(
            Some("radius"),
            format!("sphere radius {radius} is not positive"),
            "radius must be > 0",
        );
        return None;
    }
    let zmin = p.float_opt("zmin").unwrap_or(-radius);
    let zmax = p.float_opt("zmax").unwrap_or(radius);
    let phimax = p.float("phimax").clamp(0.0, 360.0);
    let (z0, z1) = (
        zmin.min(zmax).clamp(-radius, radius),
        zmin.max(zmax).clamp(-radius, radius),
    );
    if phimax <= 0.0 || z0 >= z1 {
        r.warn(
            None,
            "sphere with an empty extent (phimax 0 or zmin = zmax): skipped".into(),
            "empty sphere",
        );
        return None;
    }
    if radius == f32::INFINITY {
        r.error(
            None,
            "sphere radius does not fit a 32-bit float".into(),
            "radius too large",
        );
        return None;
    }
    at_origin(Sphere::new(Placed::origin((radius, z0, z1, phimax))))
}

/// A (possibly partial) sphere centred at its object-space origin. Ray tests
/// run in object space in f64, so hits are exact to far below f32 precision;
/// the world hit point carries an error bound like every other surface.
#[derive(Clone, Debug)]
pub struct Sphere {
    /// Its parameters, placement, material and area light.
    pub at: Placed<(f32, f32, f32, f32)>,
    pub radius: f64,
    pub z_min: f64,
    pub z_max: f64,
    /// Radians.
    pub phi_max: f64,
    /// pbrt-v3's θ range of the zone: θ(z_min) and θ(z_max), radians.
    theta_min: f64,
    theta_max: f64,
    /// Some((world centre, world radius)) when the transform is a similarity
    /// and the sphere is whole: then lights sample the cone it subtends.
    cone: Option<(Vec3, f32)>,
    area: f32,
}

impl Sphere {
    pub fn new(at: Placed<(f32, f32, f32, f32)>) -> Sphere {
        let (radius, z_min, z_max, phi_max_deg) = at.args;
        let r = radius.abs() as f64;
        let zmin = (z_min.min(z_max) as f64).clamp(-r, r);
        let zmax = (z_min.max(z_max) as f64).clamp(-r, r);
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let place = &at.place;
        let whole = zmin <= -r && zmax >= r && phi_max >= std::f64::consts::TAU;
        // Similarity: columns orthogonal with equal lengths.
        let (c0, c1, c2) = (place.lin.x_axis, place.lin.y_axis, place.lin.z_axis);
        let (l0, l1, l2) = (c0.length(), c1.length(), c2.length());
        let tol = 1e-6 * l0.max(l1).max(l2);
        let similarity = (l0 - l1).abs() < tol
            && (l0 - l2).abs() < tol
            && c0.dot(c1).abs() < tol * l0
            && c0.dot(c2).abs() < tol * l0
            && c1.dot(c2).abs() < tol * l0;
        let cone = (whole && similarity).then(|| {
            (
                place
                    .object_to_world
                    .transform_point3(DVec3::ZERO)
                    .as_vec3(),
                (r * l0) as f32,
            )
        });
        // Object-space area of the zone, scaled exactly for similarities;
        // for other transforms `area` is only used for light power.
        let obj_area = phi_max * r * (zmax - zmin);
        let scale2 = if similarity {
            l0 * l0
        } else {
            place.det_abs.powf(2.0 / 3.0)
        };
        Sphere {
            radius: r,
            z_min: zmin,
            z_max: zmax,
            phi_max,
            theta_min: (zmin / r).clamp(-1.0, 1.0).acos(),
            theta_max: (zmax / r).clamp(-1.0, 1.0).acos(),
            cone,
            area: (obj_area * scale2) as f32,
            at,
        }
    }

    #[inline]
    fn is_partial(&self) -> bool {
        self.z_min > -self.radius
            || self.z_max < self.radius
            || self.phi_max < std::f64::consts::TAU
    }

    /// World-space surface point for an object-space point on the sphere:
    /// the object-space error of the reprojected point is pbrt-v3's γ5·|p|.
    #[inline]
    fn point_at(&self, p_obj: DVec3) -> SurfacePoint {
        let obj_err = p_obj.abs() * gamma(5) as f64;
        self.at
            .place
            .exact_point(p_obj, Some(obj_err), self.at.place.normal(p_obj))
    }

    /// World-area density of `sample_area` at the point with object-space
    /// unit normal `n_obj`: dA_world / dA_obj = |det M| · |M^-T n_obj|.
    #[inline]
    fn density_at_normal(&self, n_obj: DVec3) -> f32 {
        let obj_area = self.phi_max * self.radius * (self.z_max - self.z_min);
        let pl = &self.at.place;
        (1.0 / (obj_area * pl.det_abs * (pl.normal_matrix * n_obj).length())) as f32
    }

    /// Density by area at a world point of this sphere (for area sampling).
    pub fn pdf_area(&self, p_world: Vec3) -> f32 {
        let p_obj = self
            .at
            .place
            .world_to_object
            .transform_point3(p_world.as_dvec3());
        self.density_at_normal(p_obj / p_obj.length().max(1e-300))
    }

    /// If a reference point sees the whole sphere as a cone, (centre, radius, cosθmax).
    fn cone_from(&self, p: Vec3, p_error: Vec3, n: Vec3) -> Option<(Vec3, f32, f32)> {
        let (c, r) = self.cone?;
        let origin = offset_ray_origin(p, p_error, n, c - p);
        if origin.distance_squared(c) <= r * r {
            return None;
        }
        let sin2 = r * r / p.distance_squared(c);
        let cos_max = (1.0 - sin2).max(0.0).sqrt();
        Some((c, r, cos_max))
    }

    /// The quadratic's roots t0 ≤ t1 for an object-space ray with a = |d|²,
    /// b = 2 d·o and c = |o|² − r² (`None` when it misses the sphere).
    #[inline(always)]
    fn roots(&self, oo: DVec3, od: DVec3, a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
        // The discriminant from the closest approach to the centre.
        let v = oo - (b / (2.0 * a)) * od;
        super::stable_roots(a, b, c, self.radius, v.length())
    }
}

impl Analytic for Sphere {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        Sphere::new(self.at.again(to_world, reverse, material))
    }

    /// False for singular transforms (e.g. `Scale 0 0 0`): such a sphere has
    /// no area and is left out of the scene.
    fn is_valid(&self) -> bool {
        self.radius > 0.0 && self.at.place.holds(self.area)
    }

    fn area(&self) -> f32 {
        self.area
    }

    fn bounds(&self) -> Bounds3 {
        self.at
            .place
            .zone_bounds(self.radius, self.z_min, self.z_max)
    }

    /// Closest hit with 0 < t < t_max; returns t and the object-space point.
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        let (oo, od) = self.at.place.ray_to_object(o, d);
        let a = od.length_squared();
        if a == 0.0 {
            return None;
        }
        let b = 2.0 * od.dot(oo);
        let c = oo.length_squared() - self.radius * self.radius;
        // Outside and moving away (every ray leaving the sphere's outer
        // side): both roots are ≤ 0 (q < 0 or -0, so t0 = q/a ≤ 0 and
        // t1 = c/q < 0), so no hit; decided before the square roots and
        // divisions of `roots`, from the same b and c.
        if b > 0.0 && c > 0.0 {
            return None;
        }
        let (t0, t1) = self.roots(oo, od, a, b, c)?;
        let t_max = t_max as f64;
        for t in [t0, t1] {
            if !(t > 0.0 && t < t_max && t as f32 > 0.0) {
                continue;
            }
            let mut p = oo + t * od;
            p *= self.radius / p.length();
            if p.x == 0.0 && p.y == 0.0 {
                p.x = 1e-5 * self.radius;
            }
            if self.is_partial() {
                let mut phi = p.y.atan2(p.x);
                if phi < 0.0 {
                    phi += std::f64::consts::TAU;
                }
                if p.z < self.z_min || p.z > self.z_max || phi > self.phi_max {
                    continue;
                }
            }
            return Some((t as f32, AnalyticHit::Exact(p)));
        }
        None
    }

    #[inline]
    fn surface_point(&self, h: AnalyticHit) -> SurfacePoint {
        self.point_at(h.point_and_error().0)
    }

    /// The differential geometry at an object-space hit point (pbrt-v3's
    /// `Sphere::Intersect`): u = φ/φmax, v from θ over the zone, dp/du,
    /// dp/dv and the Weingarten equations' dn/du, dn/dv, in world space.
    #[inline]
    fn diff_geom(&self, h: AnalyticHit) -> DiffGeom {
        let r = self.radius;
        let mut p = h.point_and_error().0;
        if p.x == 0.0 && p.y == 0.0 {
            p.x = 1e-5 * r;
        }
        let mut phi = p.y.atan2(p.x);
        if phi < 0.0 {
            phi += std::f64::consts::TAU;
        }
        let u = phi / self.phi_max;
        let cos_theta = (p.z / r).clamp(-1.0, 1.0);
        let theta = cos_theta.acos();
        let dtheta = self.theta_max - self.theta_min;
        let v = (theta - self.theta_min) / dtheta;
        let z_radius = (p.x * p.x + p.y * p.y).sqrt();
        let (cos_phi, sin_phi) = (p.x / z_radius, p.y / z_radius);
        let dpdu = DVec3::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let dpdv = dtheta * DVec3::new(p.z * cos_phi, p.z * sin_phi, -r * sin_theta);
        let d2pduu = -self.phi_max * self.phi_max * DVec3::new(p.x, p.y, 0.0);
        let d2pduv = dtheta * p.z * self.phi_max * DVec3::new(-sin_phi, cos_phi, 0.0);
        let d2pdvv = -dtheta * dtheta * p;
        self.at
            .place
            .diff_geom((u, v), dpdu, dpdv, [d2pduu, d2pduv, d2pdvv])
    }

    /// Uniform sample by area on the sphere's zone (object space), with the
    /// density converted to world area through the transform's Jacobian.
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let r = self.radius;
        let z = self.z_min + (self.z_max - self.z_min) * u.x as f64;
        let phi = self.phi_max * u.y as f64;
        let rxy = (r * r - z * z).max(0.0).sqrt();
        let p_obj = DVec3::new(rxy * phi.cos(), rxy * phi.sin(), z);
        Some(ShapeSample {
            point: self.point_at(p_obj),
            pdf: self.density_at_normal(p_obj / r),
        })
    }

    /// Sample a point as seen from a reference point; density by solid angle.
    fn sample_from(&self, p: Vec3, p_error: Vec3, n: Vec3, u: Vec2) -> Option<ShapeSample> {
        if let Some((c, r, cos_max)) = self.cone_from(p, p_error, n) {
            // pbrt-v3 Sphere::Sample(ref, u): sample the subtended cone, then
            // find the point on the sphere along the sampled direction.
            let dc = p.distance(c);
            let wc = (c - p) / dc;
            let frame = Frame::from_normal(wc);
            let cos_theta = (1.0 - u.x) + u.x * cos_max;
            let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
            let phi = u.y * 2.0 * PI;
            let ds = dc * cos_theta - (r * r - dc * dc * sin_theta * sin_theta).max(0.0).sqrt();
            let cos_alpha = ((dc * dc + r * r - ds * ds) / (2.0 * dc * r)).clamp(-1.0, 1.0);
            let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
            let local = Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha);
            let n_world = -frame.from_local(local);
            let pw = c + r * n_world;
            let mut point = SurfacePoint {
                p: pw,
                p_error: gamma(5) * pw.abs(),
                n: n_world,
                ns: n_world,
            };
            if self.at.place.flip_normal {
                point.n = -point.n;
                point.ns = point.n;
            }
            return Some(ShapeSample {
                point,
                pdf: uniform_cone_pdf(cos_max),
            });
        }
        to_solid_angle(p, self.sample_area(u)?)
    }

    /// Density by solid angle of `sample_from` producing direction `wi`
    /// from `p` (pbrt-v3's Sphere::Pdf): the cone density when the sphere is
    /// seen from outside, else the area density at the first hit of `wi`.
    #[inline]
    fn pdf_from(&self, p: Vec3, p_error: Vec3, n: Vec3, wi: Vec3) -> f32 {
        if let Some((_, _, cos_max)) = self.cone_from(p, p_error, n) {
            return uniform_cone_pdf(cos_max);
        }
        let o = offset_ray_origin(p, p_error, n, wi);
        match self.intersect(o, wi, f32::INFINITY) {
            Some((_, hit)) => {
                let h = self.surface_point(hit);
                // pbrt-v3's Shape::Pdf: the cosine with the ray direction wi
                // (not with p→hit: the ray starts at the offset origin, and
                // the mixed form is off by ~|offset|/(2cos²θ) at grazing wi).
                let d2 = h.p.distance_squared(p);
                let pdf = self.pdf_area(h.p) * d2 / h.n.dot(wi).abs();
                if pdf.is_finite() {
                    pdf
                } else {
                    0.0
                }
            }
            None => 0.0,
        }
    }
}

/// Convert an area sample to a solid-angle density as seen from `p`.
#[inline(always)]
pub fn to_solid_angle(p: Vec3, mut s: ShapeSample) -> Option<ShapeSample> {
    s.pdf = area_to_solid_angle(p, s.point.p, s.point.n, s.pdf);
    (s.pdf > 0.0).then_some(s)
}

/// pdf_A · r² / |cos θ'|; 0 when degenerate or infinite.
#[inline]
pub fn area_to_solid_angle(p: Vec3, q: Vec3, nq: Vec3, pdf_area: f32) -> f32 {
    let d = q - p;
    let dist2 = d.length_squared();
    if dist2 == 0.0 {
        return 0.0;
    }
    let cos = nq.dot(-d).abs() / dist2.sqrt();
    let pdf = pdf_area * dist2 / cos;
    if pdf.is_finite() {
        pdf
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_sphere_hits_and_normals() {
        let s = Sphere::new(Placed::new(
            (1.0, -1.0, 1.0, 360.0),
            DMat4::from_translation(DVec3::new(0.0, 0.0, 5.0)),
            false,
            0,
        ));
        let (t, p) = s.intersect(Vec3::ZERO, Vec3::Z, f32::INFINITY).unwrap();
        assert!((t - 4.0).abs() < 1e-6);
        let sp = s.surface_point(p);
        // pbrt nudges hits at the poles by 1e-5·r off the axis.
        assert!((sp.n - (-Vec3::Z)).length() < 2e-5);
        // From inside, the far hit.
        let (t, _) = s
            .intersect(Vec3::new(0.0, 0.0, 5.0), Vec3::Z, f32::INFINITY)
            .unwrap();
        assert!((t - 1.0).abs() < 1e-6);
        assert!(s.intersect(Vec3::ZERO, -Vec3::Z, f32::INFINITY).is_none());
        assert!((s.area() - 4.0 * PI).abs() < 1e-4);
    }

    #[test]
    fn leaving_ray_does_not_rehit() {
        for scale in [1e-4f64, 1.0, 1e5] {
            let s = Sphere::new(Placed::new(
                (1.0, -1.0, 1.0, 360.0),
                DMat4::from_scale(DVec3::splat(scale)),
                false,
                0,
            ));
            for i in 0..1000 {
                let u = Vec2::new((i as f32 * 0.618034) % 1.0, (i as f32 * 0.7548776) % 1.0);
                let smp = s.sample_area(u).unwrap();
                let sp = smp.point;
                // Outward along a tangent-ish direction must miss the sphere.
                let w = (sp.n + Frame::from_normal(sp.n).s * 30.0).normalize();
                let o = offset_ray_origin(sp.p, sp.p_error, sp.n, w);
                assert!(
                    s.intersect(o, w, f32::INFINITY).is_none(),
                    "scale {scale} i {i}"
                );
            }
        }
    }

    /// The early miss of rays outside the sphere and moving away agrees
    /// with the quadratic: for such rays `roots` has no root above 0, at
    /// any scale and for rays just off the surface as well as far away.
    #[test]
    fn outside_and_moving_away_has_no_positive_root() {
        let mut rng = crate::sampling::rng::Pcg32::new();
        let mut checked = 0;
        for scale in [1e-4f64, 1.0, 1e5] {
            let s = Sphere::new(Placed::new(
                (1.3, -1.3, 1.3, 360.0),
                DMat4::from_scale(DVec3::splat(scale)),
                false,
                0,
            ));
            for _ in 0..20000 {
                let dir = |r: &mut crate::sampling::rng::Pcg32| {
                    DVec3::new(
                        r.uniform_f32() as f64 - 0.5,
                        r.uniform_f32() as f64 - 0.5,
                        r.uniform_f32() as f64 - 0.5,
                    )
                };
                // Points near the surface (either side) and far out.
                let radial = [1.0 + 1e-12, 1.0 + 1e-7, 1.0 - 1e-9, 1.5, 40.0]
                    [rng.uniform_u32_below(5) as usize];
                let oo = dir(&mut rng).normalize() * s.radius * radial;
                let od = dir(&mut rng) * [1e-3, 1.0, 1e3][rng.uniform_u32_below(3) as usize];
                let (a, b) = (od.length_squared(), 2.0 * od.dot(oo));
                let c = oo.length_squared() - s.radius * s.radius;
                if a == 0.0 || !(b > 0.0 && c > 0.0) {
                    continue;
                }
                checked += 1;
                if let Some((t0, t1)) = s.roots(oo, od, a, b, c) {
                    assert!(t0 <= 0.0 && t1 <= 0.0, "{oo} {od}: {t0} {t1}");
                }
            }
        }
        assert!(checked > 10000);
    }
}
