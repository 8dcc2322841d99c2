//! Perfectly specular lobes (pbrt-v3 `SpecularReflection`,
//! `SpecularTransmission`, `FresnelSpecular`), for radiance transport.
//!
//! - `SpecularReflection { r, fresnel }`: the mirror direction, weight
//!   F(cos θi)·r.
//! - `SpecularTransmission { t, eta_a, eta_b }`: the refracted direction
//!   (η_a outside, on the normal's side; η_b inside), weight
//!   (1 − F)·t·(η_i/η_t)².
//! - `FresnelSpecular { r, t, eta_a, eta_b }`: one lobe that picks reflection
//!   with probability F and transmission otherwise.
//!
//! Their `f` and `pdf` are zero: a specular lobe is reached only by sampling.

use super::{abs_cos_theta, cos_theta, fr_dielectric, BxdfFlags, BxdfModel, BxdfSample, Fresnel};
use glam::{Vec2, Vec3};

/// Refraction of `wi` about `n` (same side as `wi`) with relative index
/// `eta` = η_i/η_t; None on total internal reflection.
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = n.dot(wi);
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = eta * eta * sin2_i;
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(eta * -wi + (eta * cos_i - cos_t) * n)
}

/// Specular transmission in local coordinates: (wi, η_i, η_t), or None on
/// total internal reflection.
#[inline]
fn transmit(wo: Vec3, eta_a: f32, eta_b: f32) -> Option<(Vec3, f32, f32)> {
    let entering = cos_theta(wo) > 0.0;
    let (ei, et) = if entering {
        (eta_a, eta_b)
    } else {
        (eta_b, eta_a)
    };
    let n = if entering { Vec3::Z } else { -Vec3::Z };
    refract(wo, n, ei / et).map(|wi| (wi, ei, et))
}

#[derive(Clone, Copy, Debug)]
pub struct SpecularReflection {
    pub r: Vec3,
    pub fresnel: Fresnel,
}

impl BxdfModel for SpecularReflection {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::SPECULAR_REFLECTION
    }
    #[inline]
    fn f(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, _u: Vec2) -> Option<BxdfSample> {
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        let f = match self.fresnel {
            // FresnelNoOp: exactly r (no multiply by one).
            Fresnel::NoOp => self.r,
            fr => fr.evaluate(cos_theta(wi)) * self.r,
        };
        Some(BxdfSample {
            f: f / abs_cos_theta(wi),
            wi,
            pdf: 1.0,
            flags: self.flags(),
        })
    }
    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }
}

#[derive(Clone, Copy, Debug)]
pub struct SpecularTransmission {
    pub t: Vec3,
    pub eta_a: f32,
    pub eta_b: f32,
}

impl BxdfModel for SpecularTransmission {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::SPECULAR_TRANSMISSION
    }
    #[inline]
    fn f(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, _u: Vec2) -> Option<BxdfSample> {
        let (wi, ei, et) = transmit(wo, self.eta_a, self.eta_b)?;
        let fr = fr_dielectric(cos_theta(wi), self.eta_a, self.eta_b);
        let ft = self.t * (1.0 - fr) * (ei * ei) / (et * et);
        Some(BxdfSample {
            f: ft / abs_cos_theta(wi),
            wi,
            pdf: 1.0,
            flags: self.flags(),
        })
    }
    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }
}

#[derive(Clone, Copy, Debug)]
pub struct FresnelSpecular {
    pub r: Vec3,
    pub t: Vec3,
    pub eta_a: f32,
    pub eta_b: f32,
}

impl BxdfModel for FresnelSpecular {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::TRANSMISSION | BxdfFlags::SPECULAR
    }
    #[inline]
    fn f(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        let f = fr_dielectric(cos_theta(wo), self.eta_a, self.eta_b);
        if u.x < f {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            Some(BxdfSample {
                f: f * self.r / abs_cos_theta(wi),
                wi,
                pdf: f,
                flags: BxdfFlags::SPECULAR_REFLECTION,
            })
        } else {
            let (wi, ei, et) = transmit(wo, self.eta_a, self.eta_b)?;
            let ft = self.t * (1.0 - f) * (ei * ei) / (et * et);
            Some(BxdfSample {
                f: ft / abs_cos_theta(wi),
                wi,
                pdf: 1.0 - f,
                flags: BxdfFlags::SPECULAR_TRANSMISSION,
            })
        }
    }
    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refraction_obeys_snell() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wi = refract(wo, Vec3::Z, 1.0 / 1.5).unwrap();
        let sin_o = 0.6;
        let sin_i = (wi.x * wi.x + wi.y * wi.y).sqrt();
        assert!((sin_o - 1.5 * sin_i).abs() < 1e-6);
        assert!(wi.z < 0.0 && (wi.length() - 1.0).abs() < 1e-6);
    }
}
