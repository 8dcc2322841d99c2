//! Ashikhmin–Shirley's coupled diffuse and glossy reflection (pbrt-v3
//! `FresnelBlend`): a diffuse base under a glossy coat.
//!
//! `FresnelBlend { rd, rs, distribution }`: f = f_d + f_s with
//!
//! - f_d = 28/(23π)·rd·(1 − rs)·(1 − (1 − |cos θi|/2)⁵)·(1 − (1 − |cos θo|/2)⁵),
//! - f_s = D(wh)·S(wi·wh) / (4 |wi·wh| max(|cos θi|, |cos θo|)),
//!
//! Schlick's S(c) = rs + (1 − c)⁵(1 − rs) and wh the normalised wo + wi.
//! Sampling picks the cosine-weighted hemisphere or a reflection about a
//! sampled facet normal with probability ½ each (pbrt-v3's); the density is
//! the average of the two.

use super::{
    abs_cos_theta, reflect, same_hemisphere, BxdfFlags, BxdfModel, BxdfSample,
    MicrofacetDistribution, MicrofacetModel,
};
use crate::sampling::{cosine_sample_hemisphere, ONE_MINUS_EPSILON};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

#[derive(Clone, Copy, Debug)]
pub struct FresnelBlend {
    pub rd: Vec3,
    pub rs: Vec3,
    pub distribution: MicrofacetDistribution,
}

#[inline]
fn pow5(v: f32) -> f32 {
    (v * v) * (v * v) * v
}

impl FresnelBlend {
    #[inline]
    fn schlick(&self, cos_theta: f32) -> Vec3 {
        self.rs + pow5(1.0 - cos_theta) * (Vec3::ONE - self.rs)
    }
}

impl BxdfModel for FresnelBlend {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::GLOSSY
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.f_pdf(wo, wi).0
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let wh = (wo + wi).normalize();
        let pdf_wh = self.distribution.pdf(wo, wh);
        0.5 * (abs_cos_theta(wi) * FRAC_1_PI + pdf_wh / (4.0 * wo.dot(wh)))
    }
    #[inline]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let sum = wo + wi;
        if sum == Vec3::ZERO {
            return (Vec3::ZERO, 0.0);
        }
        let (cos_i, cos_o) = (abs_cos_theta(wi), abs_cos_theta(wo));
        let diffuse = (28.0 / (23.0 * PI))
            * self.rd
            * (Vec3::ONE - self.rs)
            * ((1.0 - pow5(1.0 - 0.5 * cos_i)) * (1.0 - pow5(1.0 - 0.5 * cos_o)));
        let wh = sum.normalize();
        let (d, _, pdf_wh) = self.distribution.d_g_pdf(wo, None, wh);
        let wi_h = wi.dot(wh);
        let specular = self.schlick(wi_h) * (d / (4.0 * wi_h.abs() * cos_i.max(cos_o)));
        let pdf = if same_hemisphere(wo, wi) {
            0.5 * (cos_i * FRAC_1_PI + pdf_wh / (4.0 * wo.dot(wh)))
        } else {
            0.0
        };
        (diffuse + specular, pdf)
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        let wi = if u.x < 0.5 {
            let u = Vec2::new((2.0 * u.x).min(ONE_MINUS_EPSILON), u.y);
            let mut wi = cosine_sample_hemisphere(u);
            if wo.z < 0.0 {
                wi.z = -wi.z;
            }
            wi
        } else {
            let u = Vec2::new((2.0 * (u.x - 0.5)).min(ONE_MINUS_EPSILON), u.y);
            let wh = self.distribution.sample_wh(wo, u);
            let wi = reflect(wo, wh);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            wi
        };
        let (f, pdf) = self.f_pdf(wo, wi);
        Some(BxdfSample {
            f,
            wi,
            pdf,
            flags: self.flags(),
        })
    }
}
