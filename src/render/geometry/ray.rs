use super::{next_float_down, next_float_up};
use glam::Vec3;

/// Fraction of a shadow segment left out at its far end (pbrt-v3's ShadowEpsilon),
/// on top of the far end's own error offset.
pub const SHADOW_EPSILON: f32 = 0.0001;

/// A ray `o + t d`, `0 < t < t_max`. `d` need not be unit length.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
    pub t_max: f32,
}

impl Ray {
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Ray {
        Ray {
            o,
            d,
            t_max: f32::INFINITY,
        }
    }
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// pbrt-v3's OffsetRayOrigin: push `p` past its error box along `n`, on the
/// side `w` points to, then round away from the surface.
#[inline]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let mut offset = d * n;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let po = p + offset;
    Vec3::new(
        step_away(po.x, offset.x),
        step_away(po.y, offset.y),
        step_away(po.z, offset.z),
    )
}

/// Move `v` one ulp in the direction of the sign of `dir` (not at all for 0).
#[inline(always)]
fn step_away(v: f32, dir: f32) -> f32 {
    if dir > 0.0 {
        next_float_up(v)
    } else if dir < 0.0 {
        next_float_down(v)
    } else {
        v
    }
}

/// A ray leaving a surface point in direction `d`.
#[inline]
pub fn spawn_ray(p: Vec3, p_error: Vec3, n: Vec3, d: Vec3) -> Ray {
    Ray::new(offset_ray_origin(p, p_error, n, d), d)
}

/// A shadow ray between two surface points, both ends offset off their surfaces.
#[inline]
pub fn spawn_ray_to(p0: Vec3, e0: Vec3, n0: Vec3, p1: Vec3, e1: Vec3, n1: Vec3) -> Ray {
    let pf = offset_ray_origin(p0, e0, n0, p1 - p0);
    let pt = offset_ray_origin(p1, e1, n1, pf - p1);
    Ray {
        o: pf,
        d: pt - pf,
        t_max: 1.0 - SHADOW_EPSILON,
    }
}

/// A shadow ray from a surface point to a point in space (a point light).
#[inline]
pub fn spawn_ray_to_point(p0: Vec3, e0: Vec3, n0: Vec3, p1: Vec3) -> Ray {
    let pf = offset_ray_origin(p0, e0, n0, p1 - p0);
    Ray {
        o: pf,
        d: p1 - pf,
        t_max: 1.0 - SHADOW_EPSILON,
    }
}
