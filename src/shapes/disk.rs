//! pbrt-v3's `disk`: an annulus (or a sector of one) in the plane
//! z = `height` of its object space, between `innerradius` and `radius`,
//! over φ in [0, `phimax`]. Its object-space normal is +z.
//!
//! | parameter     | type  | pbrt-v3 default |
//! |---------------|-------|-----------------|
//! | `height`      | float | 0               |
//! | `radius`      | float | 1               |
//! | `innerradius` | float | 0               |
//! | `phimax`      | float | 360 (degrees)   |
//!
//! Ray tests run in object space in f64; the hit point's z is set to the
//! plane exactly (as pbrt-v3 refines it), so its object-space error is zero
//! and the world error is the transform's rounding alone.
//!
//! Area sampling follows pbrt-v3's `Disk::Sample`: a concentric sample of the
//! *whole* disk of `radius`, ignoring `innerradius` and `phimax`, with the
//! density 1 / (area of the partial disk). For a partial disk this is
//! pbrt-v3's behaviour (samples may fall in the hole or the cut-out sector,
//! and the density does not integrate to one); pbrs keeps it so that images
//! match. Unlike pbrt-v3, the area is the world area (the transform's
//! Jacobian is constant for a plane), so scaled disk lights are unbiased.

use super::analytic::{phi_of, Analytic, AnalyticHit, Placed};
use super::{at_origin, ShapeInput, ShapeKind, Surface, PHIMAX};
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::{offset_ray_origin, Bounds3};
use crate::sampling::concentric_sample_disk;
use crate::scene::{ParamSpec, ParamValues, Support};
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::f64::consts::TAU;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::float("height", 0.0, "z of its plane"),
    ParamSpec::float("radius", 1.0, "outer radius (> 0)"),
    ParamSpec::float(
        "innerradius",
        0.0,
        "inner radius (0 ≤ innerradius < radius)",
    ),
    PHIMAX,
];

pub const KIND: ShapeKind = ShapeKind {
    name: "disk",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a disk or annulus (or a sector of one) in a plane z = height. `phimax` clamped to [0, 360] as pbrt-v3; radius ≤ 0 or not a 32-bit float: error; innerradius < 0: warning, 0; innerradius ≥ radius or phimax 0: warning, skipped. As an area light it is sampled as pbrt-v3's `Disk::Sample`: the whole disk of `radius`, density 1/area of the partial disk",
    build,
};

/// pbrt-v3's checks: a positive radius (error), a negative inner radius is
/// 0 (warning), an empty annulus or sector is skipped (warning).
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Surface> {
    let height = p.float("height");
    let radius = p.float("radius");
    let mut inner = p.float("innerradius");
    let phimax = p.float("phimax").clamp(0.0, 360.0);
    if radius.is_nan()
        || radius <= 0.0
        || !radius.is_finite()
        || !height.is_finite()
        || !inner.is_finite()
    {
        r.error(
            Some("radius"),
            format!("disk radius {radius} (height {height}, innerradius {inner}) is not a positive 32-bit float"),
            "bad disk",
        );
        return None;
    }
    if inner < 0.0 {
        r.warn(
            Some("innerradius"),
            format!("disk innerradius {inner} is negative: 0 is used"),
            "negative innerradius",
        );
        inner = 0.0;
    }
    if inner >= radius || phimax <= 0.0 {
        r.warn(
            None,
            format!("disk with an empty extent (innerradius {inner} >= radius {radius}, or phimax 0): skipped"),
            "empty disk",
        );
        return None;
    }
    at_origin(Disk::new(Placed::origin((height, radius, inner, phimax))))
}

#[derive(Clone, Debug)]
pub struct Disk {
    /// Its parameters, placement, material and area light.
    pub at: Placed<(f32, f32, f32, f32)>,
    pub height: f64,
    pub radius: f64,
    pub inner_radius: f64,
    /// Radians.
    pub phi_max: f64,
    /// Oriented world-space unit normal (constant over the disk).
    n: Vec3,
    /// World area of the partial disk.
    area: f32,
}

impl Disk {
    /// `inner_radius` must be in [0, radius); the loader checks it.
    pub fn new(at: Placed<(f32, f32, f32, f32)>) -> Disk {
        let (height, radius, inner_radius, phi_max_deg) = at.args;
        let r = radius.abs() as f64;
        let ri = (inner_radius as f64).clamp(0.0, r);
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let place = &at.place;
        // dA_world / dA_obj, the same everywhere on a plane.
        let jacobian = place.area_scale(DVec3::Z);
        let obj_area = 0.5 * phi_max * (r * r - ri * ri);
        Disk {
            height: height as f64,
            radius: r,
            inner_radius: ri,
            phi_max,
            n: place.normal(DVec3::Z),
            area: (obj_area * jacobian) as f32,
            at,
        }
    }

    /// World-space surface point for an object-space point on the disk:
    /// zero object-space error (z is exact; x, y are f64).
    #[inline]
    fn point_at(&self, p_obj: DVec3) -> SurfacePoint {
        self.at.place.exact_point(p_obj, None, self.n)
    }
}

impl Analytic for Disk {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        Disk::new(self.at.again(to_world, reverse, material))
    }

    /// False for singular transforms and empty disks: left out of the scene.
    fn is_valid(&self) -> bool {
        self.radius > 0.0 && self.n.is_finite() && self.at.place.holds(self.area)
    }

    fn area(&self) -> f32 {
        self.area
    }

    /// The padding of [`Placement::bounds`] also gives an axis-aligned
    /// disk's box some thickness.
    fn bounds(&self) -> Bounds3 {
        let (r, h) = (self.radius, self.height);
        self.at
            .place
            .bounds(DVec3::new(-r, -r, h), DVec3::new(r, r, h))
    }

    /// Closest hit with 0 < t < t_max (pbrt-v3's `Disk::Intersect`): t and
    /// the object-space point, on the plane exactly.
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        let (oo, od) = self.at.place.ray_to_object(o, d);
        if od.z == 0.0 {
            return None;
        }
        let t = (self.height - oo.z) / od.z;
        if !(t > 0.0 && t < t_max as f64 && t as f32 > 0.0) {
            return None;
        }
        let p = oo + t * od;
        let dist2 = p.x * p.x + p.y * p.y;
        let (r, ri) = (self.radius, self.inner_radius);
        if dist2 > r * r || dist2 < ri * ri {
            return None;
        }
        if self.phi_max < TAU && phi_of(p) > self.phi_max {
            return None;
        }
        Some((
            t as f32,
            AnalyticHit::Exact(DVec3::new(p.x, p.y, self.height)),
        ))
    }

    #[inline]
    fn surface_point(&self, h: AnalyticHit) -> SurfacePoint {
        self.point_at(h.point_and_error().0)
    }

    /// pbrt-v3's parameterisation: u = φ/φmax, v = (radius − r)/(radius −
    /// innerradius); the normal does not change over the plane.
    #[inline]
    fn diff_geom(&self, h: AnalyticHit) -> DiffGeom {
        let p_obj = h.point_and_error().0;
        let r_hit = (p_obj.x * p_obj.x + p_obj.y * p_obj.y).sqrt();
        let phi = phi_of(p_obj);
        let u = phi / self.phi_max;
        let v = (self.radius - r_hit) / (self.radius - self.inner_radius);
        let dpdu = DVec3::new(-self.phi_max * p_obj.y, self.phi_max * p_obj.x, 0.0);
        // Radially inwards; at the centre, along φ = 0.
        let radial = if r_hit > 0.0 {
            DVec3::new(p_obj.x / r_hit, p_obj.y / r_hit, 0.0)
        } else {
            DVec3::X
        };
        let dpdv = (self.inner_radius - self.radius) * radial;
        let (dpdu, dpdv) = (self.at.place.vector(dpdu), self.at.place.vector(dpdv));
        DiffGeom {
            uv: Vec2::new(u as f32, v as f32),
            dpdu,
            dpdv,
            shading_dpdu: dpdu,
            shading_dpdv: dpdv,
            ..DiffGeom::ZERO
        }
    }

    /// pbrt-v3's `Disk::Sample(u)`: concentric over the whole disk, density
    /// 1 / area (see the module notes for partial disks).
    #[inline]
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let pd = concentric_sample_disk(u).as_dvec2() * self.radius;
        let p_obj = DVec3::new(pd.x, pd.y, self.height);
        Some(ShapeSample {
            point: self.point_at(p_obj),
            pdf: 1.0 / self.area,
        })
    }

    /// pbrt-v3's `Shape::Pdf(ref, wi)`: the area density at the first hit
    /// of the ray spawned along `wi`, by solid angle.
    #[inline]
    fn pdf_from(&self, p: Vec3, p_error: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let o = offset_ray_origin(p, p_error, n, wi);
        let Some((_, hit)) = self.intersect(o, wi, f32::INFINITY) else {
            return 0.0;
        };
        let h = self.surface_point(hit);
        let pdf = h.p.distance_squared(p) / (self.area * h.n.dot(wi).abs());
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }
}
