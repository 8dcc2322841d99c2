//! The closed set of analytic shapes (pbrt-v3's quadrics) as one enum that
//! only delegates: the BVH holds them as non-triangle primitives, traced by
//! callback, and area lights sit on them.

use super::{Cylinder, DiffGeom, Disk, ShapeSample, Sphere, SurfacePoint};
use crate::render::geometry::Bounds3;
use glam::{DVec3, Vec2, Vec3};

#[derive(Clone, Debug)]
pub enum Quadric {
    Sphere(Sphere),
    Disk(Disk),
    Cylinder(Cylinder),
}

macro_rules! each {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Quadric::Sphere($s) => $e,
            Quadric::Disk($s) => $e,
            Quadric::Cylinder($s) => $e,
        }
    };
}

impl Quadric {
    #[inline]
    pub fn material(&self) -> u32 {
        each!(self, s => s.material)
    }

    #[inline]
    pub fn light(&self) -> Option<u32> {
        each!(self, s => s.light)
    }

    pub fn set_light(&mut self, light: Option<u32>) {
        each!(self, s => s.light = light)
    }

    pub fn area(&self) -> f32 {
        each!(self, s => s.area())
    }

    pub fn bounds(&self) -> Bounds3 {
        each!(self, s => s.bounds())
    }

    /// False for shapes left out of the scene (singular transforms, no area).
    pub fn is_valid(&self) -> bool {
        match self {
            Quadric::Sphere(s) => s.radius > 0.0 && s.is_invertible(),
            Quadric::Disk(d) => d.is_valid(),
            Quadric::Cylinder(c) => c.is_valid(),
        }
    }

    /// Closest hit with 0 < t < t_max: t and the object-space point.
    #[inline]
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, DVec3)> {
        each!(self, s => s.intersect(o, d, t_max))
    }

    #[inline]
    pub fn surface_point(&self, p_obj: DVec3) -> SurfacePoint {
        each!(self, s => s.surface_point(p_obj))
    }

    #[inline]
    pub fn diff_geom(&self, p_obj: DVec3) -> DiffGeom {
        each!(self, s => s.diff_geom(p_obj))
    }

    /// A point sampled as seen from a reference point; density by solid angle.
    #[inline]
    pub fn sample_from(&self, p: Vec3, p_error: Vec3, n: Vec3, u: Vec2) -> Option<ShapeSample> {
        match self {
            Quadric::Sphere(s) => s.sample_from(p, p_error, n, u),
            Quadric::Disk(d) => d.sample_from(p, u),
            Quadric::Cylinder(c) => c.sample_from(p, u),
        }
    }

    /// Density by solid angle of `sample_from` producing direction `wi`.
    #[inline]
    pub fn pdf_from(&self, p: Vec3, p_error: Vec3, n: Vec3, wi: Vec3) -> f32 {
        match self {
            Quadric::Sphere(s) => {
                s.pdf_from(p, p_error, n, wi, |o, d| s.intersect(o, d, f32::INFINITY))
            }
            Quadric::Disk(d) => d.pdf_from(p, p_error, n, wi),
            Quadric::Cylinder(c) => c.pdf_from(p, p_error, n, wi),
        }
    }
}
