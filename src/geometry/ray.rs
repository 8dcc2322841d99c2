use glam::Vec3;

/// Fraction of a shadow segment left out at its far end (pbrt-v3's ShadowEpsilon),
/// on top of the far end's own error offset.
pub const SHADOW_EPSILON: f32 = 0.0001;

/// A ray `o + t d`, `0 < t < t_max`. `d` need not be unit length.
///
/// pbrt-v3's `Ray::time` is not a field: every ray of a path has the camera
/// ray's time, so the integrators keep it once per path and pass it to the
/// `*_at` queries of [`Aggregate`](crate::accel::Aggregate), and a
/// still scene's rays stay 28 bytes.
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

/// The two neighbouring rays of pbrt-v3's `RayDifferential`: where the
/// ray would start and go for a film position one pixel over in x and in
/// y. Kept beside a [`Ray`] (not in it) so that rays without differentials,
/// the vast majority, stay small.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayDiff {
    pub rx_o: Vec3,
    pub rx_d: Vec3,
    pub ry_o: Vec3,
    pub ry_d: Vec3,
}

impl RayDiff {
    /// Offset rays equal to `ray` (no footprint).
    #[inline]
    pub fn none(ray: &Ray) -> RayDiff {
        RayDiff {
            rx_o: ray.o,
            rx_d: ray.d,
            ry_o: ray.o,
            ry_d: ray.d,
        }
    }

    /// pbrt-v3's `ScaleDifferentials`: the offsets from `ray` times `s`.
    #[inline]
    pub fn scaled(&self, ray: &Ray, s: f32) -> RayDiff {
        RayDiff {
            rx_o: ray.o + (self.rx_o - ray.o) * s,
            ry_o: ray.o + (self.ry_o - ray.o) * s,
            rx_d: ray.d + (self.rx_d - ray.d) * s,
            ry_d: ray.d + (self.ry_d - ray.d) * s,
        }
    }
}

/// pbrt-v3's OffsetRayOrigin: push `p` past its error box along `n`, on the
/// side `w` points to, then round away from the surface.
#[inline(always)]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    // Negated when w·n < 0, by the sign bit rather than a branch (which
    // side a ray leaves by is as good as random to the predictor).
    let flip = ((w.dot(n) < 0.0) as u32) << 31;
    let offset = Vec3::from_array(
        (d * n)
            .to_array()
            .map(|c| f32::from_bits(c.to_bits() ^ flip)),
    );
    let po = p + offset;
    Vec3::new(
        step_away(po.x, offset.x),
        step_away(po.y, offset.y),
        step_away(po.z, offset.z),
    )
}

/// Move `v` one ulp in the direction of the sign of `dir` (not at all for 0),
/// as `next_float_up` / `next_float_down` do, without branches: the signs
/// here are as good as random, so branches would be mispredicted half the
/// time. Infinities and NaN stay as they are.
#[inline(always)]
fn step_away(v: f32, dir: f32) -> f32 {
    let b = v.to_bits();
    let d = dir.to_bits();
    let mag = b & 0x7fff_ffff;
    // Away from zero when v and dir share a sign (b + 1), towards zero
    // otherwise (b - 1): `differ` is all ones when the signs differ. From ±0
    // to the smallest subnormal of dir's sign. Selects by mask, not branch.
    let differ = (((b ^ d) as i32) >> 31) as u32;
    let stepped = b.wrapping_add(1).wrapping_add(differ << 1);
    let zero = ((mag == 0) as u32).wrapping_neg();
    let moved = (zero & ((d & 0x8000_0000) | 1)) | (!zero & stepped);
    // Keep v where dir is ±0 or NaN (its magnitude minus one wraps or lands
    // at or past the infinity bits) or v is infinite or NaN.
    let dmag = d & 0x7fff_ffff;
    let change =
        (((dmag.wrapping_sub(1) < 0x7f80_0000) & (mag < 0x7f80_0000)) as u32).wrapping_neg();
    f32::from_bits((change & moved) | (!change & b))
}

/// A ray leaving a surface point in direction `d`.
#[inline]
pub fn spawn_ray(p: Vec3, p_error: Vec3, n: Vec3, d: Vec3) -> Ray {
    Ray::new(offset_ray_origin(p, p_error, n, d), d)
}

/// A shadow ray between two surface points, both ends offset off their surfaces.
#[inline(always)]
pub fn spawn_ray_to(p0: Vec3, e0: Vec3, n0: Vec3, p1: Vec3, e1: Vec3, n1: Vec3) -> Ray {
    spawn_ray_from_to(offset_ray_origin(p0, e0, n0, p1 - p0), p1, e1, n1)
}

/// `spawn_ray_to` with the near end's offset origin `pf` already known.
#[inline]
pub fn spawn_ray_from_to(pf: Vec3, p1: Vec3, e1: Vec3, n1: Vec3) -> Ray {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{next_float_down, next_float_up};

    #[test]
    fn step_away_matches_next_float() {
        let values = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            1e30,
            -3.5e-20,
            f32::MAX,
            -f32::MAX,
        ];
        for &v in &values {
            assert_eq!(
                step_away(v, 2.0).to_bits(),
                next_float_up(v).to_bits(),
                "{v} up"
            );
            assert_eq!(
                step_away(v, -2.0).to_bits(),
                next_float_down(v).to_bits(),
                "{v} down"
            );
            assert_eq!(step_away(v, 0.0).to_bits(), v.to_bits());
            assert_eq!(step_away(v, -0.0).to_bits(), v.to_bits());
        }
        assert_eq!(step_away(f32::INFINITY, 1.0), f32::INFINITY);
        assert_eq!(step_away(f32::NEG_INFINITY, -1.0), f32::NEG_INFINITY);
        assert!(step_away(f32::NAN, 1.0).is_nan());
        assert_eq!(step_away(1.5, f32::NAN), 1.5);
        assert_eq!(step_away(-1.5, -f32::NAN), -1.5);
    }
}
