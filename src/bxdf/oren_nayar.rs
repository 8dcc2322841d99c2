//! Oren–Nayar rough diffuse reflection (pbrt-v3 `OrenNayar`), with pbrt-v3's
//! A and B from σ in degrees; cosine-sampled.

use super::{BxdfFlags, BxdfModel};
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug)]
pub struct OrenNayar {
    pub r: Vec3,
    pub a: f32,
    pub b: f32,
}

impl OrenNayar {
    /// `sigma`: the standard deviation of the facet angle, in degrees.
    pub fn new(r: Vec3, sigma_degrees: f32) -> OrenNayar {
        let s = sigma_degrees.to_radians();
        let s2 = s * s;
        OrenNayar {
            r,
            a: 1.0 - s2 / (2.0 * (s2 + 0.33)),
            b: 0.45 * s2 / (s2 + 0.09),
        }
    }
}

impl BxdfModel for OrenNayar {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::DIFFUSE
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let sin_i = (1.0 - wi.z * wi.z).max(0.0).sqrt();
        let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
        let mut max_cos = 0.0;
        if sin_i > 1e-4 && sin_o > 1e-4 {
            let (ci, si) = (wi.x / sin_i, wi.y / sin_i);
            let (co, so) = (wo.x / sin_o, wo.y / sin_o);
            max_cos = (ci.clamp(-1.0, 1.0) * co.clamp(-1.0, 1.0)
                + si.clamp(-1.0, 1.0) * so.clamp(-1.0, 1.0))
            .max(0.0);
        }
        let (sin_alpha, tan_beta) = if wi.z.abs() > wo.z.abs() {
            (sin_o, sin_i / wi.z.abs())
        } else {
            (sin_i, sin_o / wo.z.abs())
        };
        self.r * FRAC_1_PI * (self.a + self.b * max_cos * sin_alpha * tan_beta)
    }
}
