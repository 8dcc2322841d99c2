//! pbrt-v3's running error bounds (`EFloat`): an f32 value with an interval
//! [low, high] that contains the exact result of the same computation, each
//! operation widening the interval outwards by one ulp.
//!
//! pbrt-v3 intersects cones, paraboloids and hyperboloids with these (in
//! f32), and its images show what that precision gives: rays that leave
//! such a surface near a cone's apex or a hyperboloid's waist sometimes
//! re-hit it, because its quadratic solver bounds the square root of the
//! discriminant by its own rounding only. pbrs computes those shapes the
//! same way so that its images match pbrt-v3's (see the shapes' files).

use super::{gamma, next_float_down, next_float_up};
use glam::{Mat4, Vec3};
use std::ops::{Add, Div, Mul, Neg, Sub};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EFloat {
    pub v: f32,
    pub low: f32,
    pub high: f32,
}

impl EFloat {
    #[inline]
    pub fn exact(v: f32) -> EFloat {
        EFloat { v, low: v, high: v }
    }

    /// `v` ± `err` (pbrt-v3: an exact value when `err` is 0).
    #[inline]
    pub fn new(v: f32, err: f32) -> EFloat {
        if err == 0.0 {
            EFloat::exact(v)
        } else {
            EFloat {
                v,
                low: next_float_down(v - err),
                high: next_float_up(v + err),
            }
        }
    }

    #[inline]
    pub fn abs_error(self) -> f32 {
        next_float_up((self.high - self.v).abs().max((self.v - self.low).abs()))
    }

    #[inline]
    fn span(v: f32, c: [f32; 4]) -> EFloat {
        EFloat {
            v,
            low: next_float_down(c[0].min(c[1]).min(c[2].min(c[3]))),
            high: next_float_up(c[0].max(c[1]).max(c[2].max(c[3]))),
        }
    }
}

impl Add for EFloat {
    type Output = EFloat;
    #[inline]
    fn add(self, b: EFloat) -> EFloat {
        EFloat {
            v: self.v + b.v,
            low: next_float_down(self.low + b.low),
            high: next_float_up(self.high + b.high),
        }
    }
}

impl Sub for EFloat {
    type Output = EFloat;
    #[inline]
    fn sub(self, b: EFloat) -> EFloat {
        EFloat {
            v: self.v - b.v,
            low: next_float_down(self.low - b.high),
            high: next_float_up(self.high - b.low),
        }
    }
}

impl Mul for EFloat {
    type Output = EFloat;
    #[inline]
    fn mul(self, b: EFloat) -> EFloat {
        EFloat::span(
            self.v * b.v,
            [
                self.low * b.low,
                self.high * b.low,
                self.low * b.high,
                self.high * b.high,
            ],
        )
    }
}

impl Mul<EFloat> for f32 {
    type Output = EFloat;
    #[inline]
    fn mul(self, b: EFloat) -> EFloat {
        EFloat::exact(self) * b
    }
}

impl Div for EFloat {
    type Output = EFloat;
    #[inline]
    fn div(self, b: EFloat) -> EFloat {
        let v = self.v / b.v;
        if b.low < 0.0 && b.high > 0.0 {
            return EFloat {
                v,
                low: f32::NEG_INFINITY,
                high: f32::INFINITY,
            };
        }
        EFloat::span(
            v,
            [
                self.low / b.low,
                self.high / b.low,
                self.low / b.high,
                self.high / b.high,
            ],
        )
    }
}

impl Neg for EFloat {
    type Output = EFloat;
    #[inline]
    fn neg(self) -> EFloat {
        EFloat {
            v: -self.v,
            low: -self.high,
            high: -self.low,
        }
    }
}

/// pbrt-v3's `Quadratic(EFloat…)`: the discriminant in f64 from the values
/// alone, its root bounded by its own rounding; roots ordered by value.
#[inline]
pub fn quadratic(a: EFloat, b: EFloat, c: EFloat) -> Option<(EFloat, EFloat)> {
    let disc = b.v as f64 * b.v as f64 - 4.0 * a.v as f64 * c.v as f64;
    if disc < 0.0 || disc.is_nan() {
        return None;
    }
    let root = disc.sqrt();
    let root = EFloat::new(root as f32, (f32::EPSILON * 0.5) * root as f32);
    let q = if b.v < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let (t0, t1) = (q / a, c / q);
    Some(if t0.v > t1.v { (t1, t0) } else { (t0, t1) })
}

/// A ray in an object space as pbrt-v3's `Transform` gives it: f32
/// arithmetic in its operation order, the rounding bounds of origin and
/// direction, and the origin moved to the far edge of its bound along the
/// direction.
#[inline]
pub fn transform_ray(m: &Mat4, o: Vec3, d: Vec3) -> ([EFloat; 3], [EFloat; 3]) {
    let c = m.to_cols_array_2d();
    // c[col][row]: row i of the matrix is (c[0][i], c[1][i], c[2][i], c[3][i]).
    let g3 = gamma(3);
    let mut op = [0.0f32; 3];
    let mut oe = [0.0f32; 3];
    let mut dp = [0.0f32; 3];
    let mut de = [0.0f32; 3];
    for i in 0..3 {
        let (m0, m1, m2, m3) = (c[0][i], c[1][i], c[2][i], c[3][i]);
        op[i] = (m0 * o.x + m1 * o.y) + (m2 * o.z + m3);
        oe[i] = g3 * ((m0 * o.x).abs() + (m1 * o.y).abs() + (m2 * o.z).abs() + m3.abs());
        dp[i] = m0 * d.x + m1 * d.y + m2 * d.z;
        de[i] = g3 * ((m0 * d.x).abs() + (m1 * d.y).abs() + (m2 * d.z).abs());
    }
    let w = (c[0][3] * o.x + c[1][3] * o.y) + (c[2][3] * o.z + c[3][3]);
    if w != 1.0 {
        for v in &mut op {
            *v /= w;
        }
    }
    let dv = Vec3::from(dp);
    let len2 = dv.length_squared();
    if len2 > 0.0 {
        let dt = dv.abs().dot(Vec3::from(oe)) / len2;
        for i in 0..3 {
            op[i] += dp[i] * dt;
        }
    }
    (
        [0, 1, 2].map(|i| EFloat::new(op[i], oe[i])),
        [0, 1, 2].map(|i| EFloat::new(dp[i], de[i])),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_contain_the_exact_result() {
        let a = EFloat::new(0.1, 1e-8);
        let b = EFloat::new(3.0, 0.0);
        for e in [a + b, a - b, a * b, a / b, -a, 2.0 * a] {
            assert!(e.low <= e.v && e.v <= e.high, "{e:?}");
        }
        let exact = 0.1f64 / 3.0;
        let q = a / b;
        assert!((q.low as f64) <= exact && exact <= q.high as f64);
        // Division by an interval that contains 0 is unbounded.
        let z = EFloat::new(0.0, 1e-3);
        assert_eq!((a / z).high, f32::INFINITY);
        let (t0, t1) =
            quadratic(EFloat::exact(1.0), EFloat::exact(-3.0), EFloat::exact(2.0)).expect("roots");
        assert_eq!((t0.v, t1.v), (1.0, 2.0));
        assert!(quadratic(EFloat::exact(1.0), EFloat::exact(0.0), EFloat::exact(1.0)).is_none());
    }
}
