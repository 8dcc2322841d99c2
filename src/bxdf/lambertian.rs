//! Lambertian lobes (pbrt-v3 `LambertianReflection`, `LambertianTransmission`).
//!
//! - `LambertianReflection { r }`: f = r/π on `wo`'s side, cosine-sampled.
//! - `LambertianTransmission { t }`: f = t/π on the other side, cosine-sampled
//!   there.

use super::{abs_cos_theta, same_hemisphere, BxdfFlags, BxdfModel, BxdfSample};
use crate::sampling::cosine_sample_hemisphere;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Copy, Debug)]
pub struct LambertianReflection {
    pub r: Vec3,
}

impl BxdfModel for LambertianReflection {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::DIFFUSE
    }
    #[inline]
    fn f(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        self.r * FRAC_1_PI
    }
}

#[derive(Clone, Copy, Debug)]
pub struct LambertianTransmission {
    pub t: Vec3,
}

impl BxdfModel for LambertianTransmission {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::TRANSMISSION | BxdfFlags::DIFFUSE
    }
    #[inline]
    fn f(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        self.t * FRAC_1_PI
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        let mut wi = cosine_sample_hemisphere(u);
        if wo.z > 0.0 {
            wi.z = -wi.z;
        }
        Some(BxdfSample {
            f: self.f(wo, wi),
            wi,
            pdf: self.pdf(wo, wi),
            flags: self.flags(),
        })
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if same_hemisphere(wo, wi) {
            0.0
        } else {
            abs_cos_theta(wi) * FRAC_1_PI
        }
    }
}
