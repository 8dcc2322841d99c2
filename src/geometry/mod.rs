//! Geometry: rays, bounds, frames, and robust ray origins.
//!
//! Spawned rays never hit the surface they leave, at any scene scale: every hit
//! point carries a conservative bound on its floating-point error (pbrt-v3,
//! §3.9), and spawned origins are pushed past that bound along the geometric
//! normal and rounded away from the surface. There is no fixed epsilon.

mod bounds;
pub mod efloat;
mod frame;
mod ray;

pub use bounds::{Bounds2i, Bounds3};
pub use frame::Frame;
pub use ray::{
    offset_ray_origin, spawn_ray, spawn_ray_from_to, spawn_ray_to, spawn_ray_to_point, Ray,
    RayDiff, SHADOW_EPSILON,
};

use glam::Vec3;

/// Half of f32's machine epsilon: the bound on relative rounding error.
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// pbrt's γ(n) = nε / (1 − nε), bounding the error of n rounded operations.
#[inline]
pub const fn gamma(n: i32) -> f32 {
    (n as f32 * MACHINE_EPSILON) / (1.0 - n as f32 * MACHINE_EPSILON)
}

/// Next representable f32 above `v` (identity for +inf).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v >= 0.0 { bits + 1 } else { bits - 1 };
    f32::from_bits(bits)
}

/// Next representable f32 below `v` (identity for -inf).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    let bits = if v > 0.0 { bits - 1 } else { bits + 1 };
    f32::from_bits(bits)
}

/// Luminance of a linear RGB triple (pbrt-v3's `RGBSpectrum::y`).
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z
}

/// Flip `v` to lie in the same hemisphere as `n`.
#[inline]
pub fn face_forward(v: Vec3, n: Vec3) -> Vec3 {
    if v.dot(n) < 0.0 {
        -v
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float_steps_one_ulp() {
        for v in [0.0f32, -0.0, 1.0, -1.0, 1e-30, -1e30, 3.5e5] {
            assert!(next_float_up(v) > v);
            assert!(next_float_down(v) < v);
            assert_eq!(
                next_float_down(next_float_up(v)),
                if v == -0.0 { 0.0 } else { v }
            );
        }
    }
}
