//! pbrt-v3's `AnimatedTransform`: two keyframe transforms at two times
//! (`TransformTimes`, default 0 and 1), interpolated in between by
//! decomposing each into translation T, rotation R (a unit quaternion) and the
//! remaining scale/shear S (`M = T R S`), lerping T and S and slerping R.
//! Before the start time the start transform holds, after the end time the
//! end transform, exactly (no decomposition round trip at the keyframes).
//!
//! Motion bounds: pbrt-v3 bounds each box corner's path analytically (the
//! zeros of the derivative of the rotating path). pbrs instead samples the
//! interval and pads the union by how far any point of the box can move
//! between two samples (the speed bound of `T(t) R(t) S(t) p`), which is a
//! conservative bound too and simpler to check.

use glam::{DMat3, DMat4, DQuat, DVec3, DVec4};

/// Two transforms that differ, at two times. A pair of equal transforms is
/// not animated: scene building keeps the plain `DMat4` then, so that static
/// scenes carry no motion data at all.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimatedTransform {
    pub start: DMat4,
    pub end: DMat4,
    pub start_time: f64,
    pub end_time: f64,
    keys: [Decomposed; 2],
    /// The two rotations differ enough to need slerp (pbrt-v3's
    /// `hasRotation`: quaternion dot below 0.9995).
    has_rotation: bool,
}

/// `M = T * R * S` of one keyframe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decomposed {
    pub t: DVec3,
    pub r: DQuat,
    pub s: DMat3,
}

/// Above this quaternion dot product the rotations are interpolated
/// linearly and renormalised (pbrt-v3's slerp threshold).
const SLERP_LINEAR_DOT: f64 = 0.9995;

impl AnimatedTransform {
    /// `None` when `start == end`: nothing moves (pbrt-v3's
    /// `actuallyAnimated` is false and every query returns `start`).
    pub fn new(start: DMat4, start_time: f64, end: DMat4, end_time: f64) -> Option<Self> {
        if start == end {
            return None;
        }
        let k0 = decompose(&start);
        let mut k1 = decompose(&end);
        // The shorter way round: q and -q are the same rotation.
        if k0.r.dot(k1.r) < 0.0 {
            k1.r = -k1.r;
        }
        let has_rotation = k0.r.dot(k1.r) < SLERP_LINEAR_DOT;
        Some(AnimatedTransform {
            start,
            end,
            start_time,
            end_time,
            keys: [k0, k1],
            has_rotation,
        })
    }

    pub fn keys(&self) -> &[Decomposed; 2] {
        &self.keys
    }

    /// The transform at `time` (clamped to the two keyframes).
    pub fn interpolate(&self, time: f64) -> DMat4 {
        // A NaN time reads the start.
        if time <= self.start_time || time.is_nan() {
            return self.start;
        }
        if time >= self.end_time {
            return self.end;
        }
        let u = (time - self.start_time) / (self.end_time - self.start_time);
        self.at_fraction(u)
    }

    /// The interpolated transform at fraction `u` in [0, 1] of the interval.
    fn at_fraction(&self, u: f64) -> DMat4 {
        let [a, b] = &self.keys;
        let t = a.t.lerp(b.t, u);
        let r = slerp(u, a.r, b.r);
        let s = DMat3::from_cols(
            a.s.x_axis.lerp(b.s.x_axis, u),
            a.s.y_axis.lerp(b.s.y_axis, u),
            a.s.z_axis.lerp(b.s.z_axis, u),
        );
        let m = DMat3::from_quat(r) * s;
        DMat4::from_cols(
            m.x_axis.extend(0.0),
            m.y_axis.extend(0.0),
            m.z_axis.extend(0.0),
            t.extend(1.0),
        )
    }

    /// A box that contains the box `[lo, hi]` under every transform of the
    /// interval (conservative, see the module doc).
    pub fn motion_bounds(&self, lo: DVec3, hi: DVec3) -> (DVec3, DVec3) {
        let corners = box_corners(lo, hi);
        let (mut bmin, mut bmax) = transform_box(&self.start, &corners);
        let (emin, emax) = transform_box(&self.end, &corners);
        bmin = bmin.min(emin);
        bmax = bmax.max(emax);
        let [a, b] = &self.keys;
        if !self.has_rotation && a.s == b.s {
            // Pure translation: every point moves on a segment, the union of
            // the two end boxes holds the whole sweep.
            return (bmin, bmax);
        }
        // The speed |dp/du| of p(u) = T(u) R(u) S(u) p is at most
        // |ΔT| + ω |S(u) p| + |ΔS p|, with ω the rotation angle over the
        // interval (slerp turns at a constant rate; the linear blend of
        // nearly equal rotations stays within 1% of it).
        let omega = if self.has_rotation {
            2.0 * a.r.dot(b.r).clamp(-1.0, 1.0).acos() * 1.01
        } else {
            // Nearly equal rotations, blended linearly: the angle θ between
            // them has |q0 - q1| = 2 sin(θ/4), so θ < π |q0 - q1| < 4 |q0 - q1|.
            4.0 * (a.r - b.r).length() * 1.01
        };
        let mut reach: f64 = 0.0;
        let mut shear: f64 = 0.0;
        for c in &corners {
            reach = reach.max((a.s * *c).length()).max((b.s * *c).length());
            shear = shear.max(((b.s - a.s) * *c).length());
        }
        let speed = (b.t - a.t).length() + omega * reach + shear;
        const STEPS: usize = 32;
        for i in 1..STEPS {
            let m = self.at_fraction(i as f64 / STEPS as f64);
            let (smin, smax) = transform_box(&m, &corners);
            bmin = bmin.min(smin);
            bmax = bmax.max(smax);
        }
        // Any time is within half a step of a sample; a little relative room
        // covers the rounding of the samples themselves.
        let scale = bmin.abs().max(bmax.abs()).max_element();
        let pad = speed * 0.5 / STEPS as f64 + scale * 1e-9;
        (bmin - DVec3::splat(pad), bmax + DVec3::splat(pad))
    }
}

fn box_corners(lo: DVec3, hi: DVec3) -> [DVec3; 8] {
    std::array::from_fn(|i| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

fn transform_box(m: &DMat4, corners: &[DVec3; 8]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for c in corners {
        let p = m.project_point3(*c);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo, hi)
}

/// pbrt-v3's slerp: the great-circle blend, or a normalised linear blend
/// when the two are nearly equal (where the great-circle formula divides by
/// almost zero).
pub fn slerp(u: f64, q0: DQuat, q1: DQuat) -> DQuat {
    let cos = q0.dot(q1);
    if cos > SLERP_LINEAR_DOT {
        return (q0 * (1.0 - u) + q1 * u).normalize();
    }
    let theta = cos.clamp(-1.0, 1.0).acos() * u;
    let perp = (q1 - q0 * cos).normalize();
    q0 * theta.cos() + perp * theta.sin()
}

/// `M = T R S` as pbrt-v3 decomposes it: the translation column, then the
/// rotation of the polar decomposition of the upper 3×3 (by averaging with
/// the inverse transpose until it settles), then `S = R⁻¹ M`.
pub fn decompose(m: &DMat4) -> Decomposed {
    let t = m.w_axis.truncate();
    let upper = DMat3::from_mat4(*m);
    let mut r = upper;
    for _ in 0..100 {
        let inv_t = r.transpose().inverse();
        let next = (r + inv_t) * 0.5;
        // The largest row sum of |r - next| (pbrt-v3's norm).
        let d = r - next;
        let norm = (0..3)
            .map(|row| {
                let v: DVec3 = d.row(row);
                v.abs().element_sum()
            })
            .fold(0.0, f64::max);
        r = next;
        // Converged to rounding (pbrt-v3 stops at 1e-4; the iteration is
        // quadratic, so the tighter stop costs a step or two).
        if norm <= 1e-13 || norm.is_nan() {
            break;
        }
    }
    // A mirroring transform has det(R) = -1, which no quaternion holds:
    // pbrs moves the mirror into S (pbrt-v3 builds a meaningless
    // quaternion there; both agree at the keyframes).
    if r.determinant() < 0.0 {
        r = -r;
    }
    let q = if r.is_finite() {
        DQuat::from_mat3(&r).normalize()
    } else {
        DQuat::IDENTITY
    };
    let r = if q.is_finite() { q } else { DQuat::IDENTITY };
    // S from the unit quaternion's own matrix (pbrt-v3 uses the iterate),
    // so that T R S gives back M to rounding.
    let s = DMat3::from_quat(r).transpose() * upper;
    Decomposed { t, r, s }
}

/// `true` if the bottom row is (0, 0, 0, 1): a decomposition into T R S
/// reproduces the transform.
pub fn is_affine(m: &DMat4) -> bool {
    m.row(3) == DVec4::new(0.0, 0.0, 0.0, 1.0)
}
