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

use super::quadric::{Analytic, QuadricHit};
use super::{at_origin, Geometry, ShapeInput, ShapeKind, ORIGIN, PHIMAX};
use crate::scene::{ParamSpec, ParamValues, Support};

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
fn build(p: &ParamValues, r: &mut dyn ShapeInput) -> Option<Geometry> {
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
    at_origin(Disk::new(height, radius, inner, phimax, ORIGIN, false, 0))
}

use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::{gamma, offset_ray_origin, Bounds3};
use crate::sampling::concentric_sample_disk;
use glam::{DMat3, DMat4, DVec3, Vec2, Vec3};
use std::f64::consts::TAU;

#[derive(Clone, Debug)]
pub struct Disk {
    /// The arguments of [`Disk::new`] but the placement: the shape as its
    /// kind built it, placed again by [`Analytic::placed`].
    pub args: (f32, f32, f32, f32),
    pub height: f64,
    pub radius: f64,
    pub inner_radius: f64,
    /// Radians.
    pub phi_max: f64,
    pub object_to_world: DMat4,
    pub world_to_object: DMat4,
    /// Oriented world-space unit normal (constant over the disk).
    n: Vec3,
    pub flip_normal: bool,
    pub material: u32,
    pub light: Option<u32>,
    /// World area of the partial disk.
    area: f32,
}

impl Disk {
    /// `inner_radius` must be in [0, radius); the loader checks it.
    pub fn new(
        height: f32,
        radius: f32,
        inner_radius: f32,
        phi_max_deg: f32,
        object_to_world: DMat4,
        reverse: bool,
        material: u32,
    ) -> Disk {
        let r = radius.abs() as f64;
        let ri = (inner_radius as f64).clamp(0.0, r);
        let phi_max = (phi_max_deg.clamp(0.0, 360.0) as f64).to_radians();
        let lin = DMat3::from_mat4(object_to_world);
        let det = lin.determinant();
        let normal_matrix = lin.inverse().transpose();
        let flip_normal = reverse ^ (det < 0.0);
        let mut n = (normal_matrix * DVec3::Z).normalize().as_vec3();
        if flip_normal {
            n = -n;
        }
        // dA_world / dA_obj = |det M| · |M^-T z|, the same everywhere on a plane.
        let jacobian = det.abs() * (normal_matrix * DVec3::Z).length();
        let obj_area = 0.5 * phi_max * (r * r - ri * ri);
        Disk {
            args: (height, radius, inner_radius, phi_max_deg),
            height: height as f64,
            radius: r,
            inner_radius: ri,
            phi_max,
            object_to_world,
            world_to_object: object_to_world.inverse(),
            n,
            flip_normal,
            material,
            light: None,
            area: (obj_area * jacobian) as f32,
        }
    }

    pub fn area(&self) -> f32 {
        self.area
    }

    /// False for singular transforms and empty disks: left out of the scene.
    pub fn is_valid(&self) -> bool {
        self.world_to_object.is_finite()
            && self.radius > 0.0
            && self.area > 0.0
            && self.area.is_finite()
            && self.n.is_finite()
    }

    pub fn bounds(&self) -> Bounds3 {
        let r = self.radius;
        let mut b = Bounds3::EMPTY;
        for i in 0..4 {
            let c = DVec3::new(
                if i & 1 == 0 { -r } else { r },
                if i & 2 == 0 { -r } else { r },
                self.height,
            );
            b = b.union_point(self.object_to_world.transform_point3(c).as_vec3());
        }
        // A few ulps of padding keep the f32 corners conservative (and give
        // an axis-aligned disk's box some thickness).
        let pad = (b.max.abs().max(b.min.abs())) * 4.0 * f32::EPSILON;
        Bounds3 {
            min: b.min - pad,
            max: b.max + pad,
        }
    }

    /// Closest hit with 0 < t < t_max (pbrt-v3's `Disk::Intersect`): t and
    /// the object-space point, on the plane exactly.
    #[inline]
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, DVec3)> {
        let oo = self.world_to_object.transform_point3(o.as_dvec3());
        let od = self.world_to_object.transform_vector3(d.as_dvec3());
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
        Some((t as f32, DVec3::new(p.x, p.y, self.height)))
    }

    /// World-space surface point for an object-space point on the disk.
    pub fn surface_point(&self, p_obj: DVec3) -> SurfacePoint {
        let pw = self.object_to_world.transform_point3(p_obj);
        let p = pw.as_vec3();
        // Zero object-space error (z is exact; x, y are f64): the transform's
        // rounding as pbrt-v3 bounds it, plus the final rounding to f32.
        let lin = DMat3::from_mat4(self.object_to_world);
        let abs_lin = DMat3::from_cols(lin.x_axis.abs(), lin.y_axis.abs(), lin.z_axis.abs());
        let err = (abs_lin * p_obj.abs() + self.object_to_world.w_axis.truncate().abs())
            * gamma(3) as f64;
        SurfacePoint {
            p,
            p_error: err.as_vec3() + p.abs() * f32::EPSILON,
            n: self.n,
            ns: self.n,
        }
    }

    /// pbrt-v3's parameterisation: u = φ/φmax, v = (radius − r)/(radius −
    /// innerradius); the normal does not change over the plane.
    pub fn diff_geom(&self, p_obj: DVec3) -> DiffGeom {
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
        let lin = DMat3::from_mat4(self.object_to_world);
        let (dpdu, dpdv) = ((lin * dpdu).as_vec3(), (lin * dpdv).as_vec3());
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
    pub fn sample_area(&self, u: Vec2) -> ShapeSample {
        let pd = concentric_sample_disk(u).as_dvec2() * self.radius;
        let p_obj = DVec3::new(pd.x, pd.y, self.height);
        ShapeSample {
            point: self.surface_point(p_obj),
            pdf: 1.0 / self.area,
        }
    }

    /// A point sampled by area, its density converted to solid angle at `p`.
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<ShapeSample> {
        super::to_solid_angle(p, self.sample_area(u))
    }

    /// pbrt-v3's `Shape::Pdf(ref, wi)`: the area density at the first hit
    /// of the ray spawned along `wi`, by solid angle.
    pub fn pdf_from(&self, p: Vec3, p_error: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let o = offset_ray_origin(p, p_error, n, wi);
        let Some((_, p_obj)) = self.intersect(o, wi, f32::INFINITY) else {
            return 0.0;
        };
        let h = self.surface_point(p_obj);
        let pdf = h.p.distance_squared(p) / (self.area * h.n.dot(wi).abs());
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }
}

/// φ in [0, 2π) of an object-space point.
#[inline]
fn phi_of(p: DVec3) -> f64 {
    let phi = p.y.atan2(p.x);
    if phi < 0.0 {
        phi + TAU
    } else {
        phi
    }
}

impl Analytic for Disk {
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self {
        let a = self.args;
        Disk::new(a.0, a.1, a.2, a.3, to_world, reverse, material)
    }
    fn valid(&self) -> bool {
        self.is_valid()
    }
    #[inline]
    fn hit(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, QuadricHit)> {
        self.intersect(o, d, t_max)
            .map(|(t, p)| (t, QuadricHit::Exact(p)))
    }
    #[inline]
    fn point(&self, h: QuadricHit) -> SurfacePoint {
        self.surface_point(h.point_and_error().0)
    }
    #[inline]
    fn geom(&self, h: QuadricHit) -> DiffGeom {
        self.diff_geom(h.point_and_error().0)
    }
    fn area_sample(&self, u: Vec2) -> Option<ShapeSample> {
        Some(self.sample_area(u))
    }
    #[inline]
    fn pdf_toward(&self, p: Vec3, p_error: Vec3, n: Vec3, wi: Vec3) -> f32 {
        self.pdf_from(p, p_error, n, wi)
    }
}
