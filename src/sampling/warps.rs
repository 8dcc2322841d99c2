//! Warps from the unit square to common domains, with their densities
//! (pbrt-v3 core/sampling.{h,cpp} conventions: z is up, pdfs are per unit
//! solid angle or per unit area).

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};
use std::ops::{Add, Mul, Sub};

const INV_2PI: f32 = 0.5 * FRAC_1_PI;
const INV_4PI: f32 = 0.25 * FRAC_1_PI;

/// Uniform direction on the hemisphere z >= 0.
#[inline]
pub fn uniform_sample_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

#[inline]
pub fn uniform_hemisphere_pdf() -> f32 {
    INV_2PI
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn uniform_sample_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    INV_4PI
}

/// Shirley–Chiu concentric map from the square to the unit disk.
#[inline]
pub fn concentric_sample_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    // θ = π/4·(y/x), or π/2 − π/4·(x/y) whose cosine and sine are the sine
    // and cosine of π/4·(x/y): either way an angle in [−π/4, π/4].
    if o.x.abs() > o.y.abs() {
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.y / o.x));
        o.x * Vec2::new(c, s)
    } else {
        let (s, c) = sin_cos_quarter(FRAC_PI_4 * (o.x / o.y));
        o.y * Vec2::new(s, c)
    }
}

/// `(sin x, cos x)` for `|x| <= π/4` by their Taylor polynomials (to x⁹ and
/// x¹⁰: truncation error below 3e-9 there), evaluated in `f32`; within
/// 2 ulp of the correctly rounded values, without libm's range reduction
/// and call. Generic so that one polynomial serves `f32` and four-lane
/// `Vec4` (the same operations in each lane).
#[inline(always)]
pub fn sin_cos_quarter<T>(x: T) -> (T, T)
where
    T: Copy + Add<Output = T> + Mul<Output = T> + Mul<f32, Output = T>,
    f32: Add<T, Output = T> + Sub<T, Output = T>,
{
    let x2 = x * x;
    let s = x + x
        * x2
        * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0))));
    let c = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0 - x2 * (1.0 / 3_628_800.0)))));
    (s, c)
}

/// Polar map from the square to the unit disk (density 1/π).
#[inline]
pub fn uniform_sample_disk(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    Vec2::new(r * c, r * s)
}

/// Density of both disk maps per unit area.
#[inline]
pub fn uniform_disk_pdf() -> f32 {
    FRAC_1_PI
}

/// Cosine-weighted direction on the hemisphere z >= 0 (Malley's method).
#[inline]
pub fn cosine_sample_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_sample_disk(u);
    let z = (1.0 - d.x * d.x - d.y * d.y).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta * FRAC_1_PI
}

/// Uniform direction in the cone around +z with `cos θ >= cos_theta_max`.
#[inline]
pub fn uniform_sample_cone(u: Vec2, cos_theta_max: f32) -> Vec3 {
    let cos_theta = (1.0 - u.x) + u.x * cos_theta_max;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    Vec3::new(sin_theta * c, sin_theta * s, cos_theta)
}

#[inline]
pub fn uniform_cone_pdf(cos_theta_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_theta_max))
}

/// Uniform point on a triangle as barycentrics `(b0, b1)` (b2 = 1 − b0 − b1);
/// the density per unit area is `1 / area`.
#[inline]
pub fn uniform_sample_triangle(u: Vec2) -> Vec2 {
    let su0 = u.x.sqrt();
    Vec2::new(1.0 - su0, u.y * su0)
}

/// Weights of the MIS heuristics: `f`'s share given `g`. Never NaN: zero,
/// negative or NaN pdfs count as 0, infinite ones (delta) win.
#[inline]
fn mis_weight(nf: u32, f_pdf: f32, ng: u32, g_pdf: f32, power: bool) -> f32 {
    let f = nf as f32 * f_pdf;
    let g = ng as f32 * g_pdf;
    let f_ok = f > 0.0; // false for NaN
    let g_ok = g > 0.0;
    match (f_ok, g_ok) {
        (false, _) => 0.0,
        (true, false) => 1.0,
        (true, true) => match (f.is_infinite(), g.is_infinite()) {
            (true, true) => 0.5,
            (true, false) => 1.0,
            (false, true) => 0.0,
            (false, false) => {
                let (f, g) = (f as f64, g as f64);
                if power {
                    (f * f / (f * f + g * g)) as f32
                } else {
                    (f / (f + g)) as f32
                }
            }
        },
    }
}

/// Veach's balance heuristic `f / (f + g)` with `f = nf·f_pdf`, `g = ng·g_pdf`.
#[inline]
pub fn balance_heuristic(nf: u32, f_pdf: f32, ng: u32, g_pdf: f32) -> f32 {
    mis_weight(nf, f_pdf, ng, g_pdf, false)
}

/// Veach's power heuristic (β = 2) `f² / (f² + g²)`.
#[inline]
pub fn power_heuristic(nf: u32, f_pdf: f32, ng: u32, g_pdf: f32) -> f32 {
    mis_weight(nf, f_pdf, ng, g_pdf, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heuristics_never_nan() {
        let vals = [
            0.0,
            -1.0,
            f32::NAN,
            f32::INFINITY,
            1e-30,
            1.0,
            1e30,
            f32::MAX,
        ];
        for &a in &vals {
            for &b in &vals {
                for h in [power_heuristic(1, a, 1, b), balance_heuristic(1, a, 1, b)] {
                    assert!(h.is_finite() && (0.0..=1.0).contains(&h), "{a} {b} -> {h}");
                }
            }
        }
        assert_eq!(power_heuristic(1, 1.0, 1, 1.0), 0.5);
        assert!((power_heuristic(1, 2.0, 1, 1.0) - 0.8).abs() < 1e-6);
        assert!((balance_heuristic(1, 3.0, 1, 1.0) - 0.75).abs() < 1e-6);
        assert_eq!(power_heuristic(1, f32::INFINITY, 1, 5.0), 1.0);
        assert_eq!(power_heuristic(1, 5.0, 1, f32::INFINITY), 0.0);
        assert_eq!(power_heuristic(1, 1e30, 1, 1e30), 0.5);
    }

    #[test]
    fn quarter_sin_cos_is_accurate() {
        let n = 100_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let x = (i as f64 / n as f64 * 2.0 - 1.0) * std::f64::consts::FRAC_PI_4;
            let (s, c) = sin_cos_quarter(x as f32);
            let xf = x as f32 as f64;
            worst = worst
                .max((s as f64 - xf.sin()).abs())
                .max((c as f64 - xf.cos()).abs());
        }
        assert!(worst < 1.2e-7, "max error {worst}");
    }

    #[test]
    fn warps_land_in_domain() {
        let mut r = crate::sampling::rng::Pcg32::with_sequence(3);
        for _ in 0..10_000 {
            let u = Vec2::new(r.uniform_f32(), r.uniform_f32());
            assert!((uniform_sample_sphere(u).length() - 1.0).abs() < 1e-5);
            let h = uniform_sample_hemisphere(u);
            assert!(h.z >= 0.0 && (h.length() - 1.0).abs() < 1e-5);
            let c = cosine_sample_hemisphere(u);
            assert!(c.z >= 0.0 && (c.length() - 1.0).abs() < 1e-5);
            assert!(concentric_sample_disk(u).length() <= 1.0 + 1e-6);
            assert!(uniform_sample_disk(u).length() <= 1.0 + 1e-6);
            let k = uniform_sample_cone(u, 0.9);
            assert!(k.z >= 0.9 - 1e-6);
            let b = uniform_sample_triangle(u);
            assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
        }
        assert_eq!(concentric_sample_disk(Vec2::splat(0.5)), Vec2::ZERO);
    }
}
