//! Glossy lobes of a rough interface (pbrt-v3 `MicrofacetReflection`,
//! `MicrofacetTransmission`, Torrance–Sparrow and Walter et al. 2007), for
//! radiance transport.
//!
//! - `MicrofacetReflection { r, distribution, fresnel }`:
//!   f = r·D(wh)·G(wo, wi)·F(wi·wh) / (4 |cos θo| |cos θi|), wh = normalised
//!   wo + wi (turned to the normal's side for the Fresnel term, so that total
//!   internal reflection is seen). Samples wh from the distribution and
//!   reflects wo about it; density `pdf(wh) / (4 wo·wh)`.
//! - `MicrofacetTransmission { t, distribution, eta_a, eta_b }` (η_a outside,
//!   on the normal's side; η_b inside): with η = η_i/η_o and the generalised
//!   half vector wh ∝ wo + η·wi,
//!   f = (1 − F(wo·wh))·t·D·G·|wi·wh|·|wo·wh| / (|cos θi| |cos θo| (wo·wh + η wi·wh)²).
//!   pbrt-v3 writes the Jacobian's η² and radiance's 1/η² as separate
//!   factors; they cancel. Samples wh and refracts wo through it; density
//!   `pdf(wh)·η²|wi·wh| / (wo·wh + η wi·wh)²`.
//!
//! `f` and `pdf` share the half vector, D and Λ(wo) in `f_pdf`.
//!
//! As in pbrt-v3, the transmission's `f` and `pdf` are also non-zero for
//! pairs whose half vector has wo or wi behind the facet (no facet refracts
//! one into the other; the sampler never produces them, pbrt-v4 drops them).
//! Their share of the density is small (a few 1e-4 at α = 0.05) but makes
//! it integrate to slightly more than the sampler's success probability.

use super::{
    cos_theta, fr_dielectric, reflect, refract, same_hemisphere, BxdfFlags, BxdfModel, BxdfSample,
    Fresnel, MicrofacetDistribution, MicrofacetModel,
};
use glam::{Vec2, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct MicrofacetReflection {
    pub r: Vec3,
    pub distribution: MicrofacetDistribution,
    pub fresnel: Fresnel,
}

#[derive(Clone, Copy, Debug)]
pub struct MicrofacetTransmission {
    pub t: Vec3,
    pub distribution: MicrofacetDistribution,
    pub eta_a: f32,
    pub eta_b: f32,
}

impl MicrofacetReflection {
    /// `(f, pdf)` for `wi` reached through the facet normal `wh`.
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3, wh: Vec3) -> (Vec3, f32) {
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        let (d, g, pdf_wh) = self.distribution.d_g_pdf(wo, Some(wi), wh);
        let wh_up = if wh.z < 0.0 { -wh } else { wh };
        let f = self.fresnel.evaluate(wi.dot(wh_up)) * self.r * (d * g / (4.0 * cos_i * cos_o));
        // f has no hemisphere test (the BSDF decides by the geometric
        // normal); the density is zero across the surface.
        let pdf = if same_hemisphere(wo, wi) {
            pdf_wh / (4.0 * wo.dot(wh))
        } else {
            0.0
        };
        (f, pdf)
    }
}

impl BxdfModel for MicrofacetReflection {
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
        self.distribution.pdf(wo, wh) / (4.0 * wo.dot(wh))
    }
    #[inline]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let sum = wo + wi;
        // Grazing or opposite directions: no value and (by the hemisphere
        // test) no density either.
        if wo.z == 0.0 || wi.z == 0.0 || sum == Vec3::ZERO {
            return (Vec3::ZERO, 0.0);
        }
        self.eval(wo, wi, sum.normalize())
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        let (wi, wh) = self.sample_wi_wh(wo, u)?;
        let (f, pdf) = self.eval(wo, wi, wh);
        Some(BxdfSample {
            f,
            wi,
            pdf,
            flags: self.flags(),
        })
    }
    /// `sample_f` without the value: the density needs D(wh) and Λ(wo)
    /// only (the same bits as `eval`'s), not G's Λ(wi) or the Fresnel term.
    #[inline]
    fn sample_wi(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        let (wi, wh) = self.sample_wi_wh(wo, u)?;
        let pdf_wh = self.distribution.d_g_pdf(wo, None, wh).2;
        Some(BxdfSample {
            f: Vec3::ZERO,
            wi,
            pdf: pdf_wh / (4.0 * wo.dot(wh)),
            flags: self.flags(),
        })
    }
}

impl MicrofacetReflection {
    /// A facet normal sampled for `wo` and the direction it reflects `wo`
    /// to, `None` where either is on the wrong side.
    #[inline]
    fn sample_wi_wh(&self, wo: Vec3, u: Vec2) -> Option<(Vec3, Vec3)> {
        if wo.z == 0.0 {
            return None;
        }
        let wh = self.distribution.sample_wh(wo, u);
        if wo.dot(wh) < 0.0 {
            return None;
        }
        let wi = reflect(wo, wh);
        if !same_hemisphere(wo, wi) {
            return None;
        }
        Some((wi, wh))
    }
}

impl BxdfModel for MicrofacetTransmission {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::TRANSMISSION | BxdfFlags::GLOSSY
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.f_pdf(wo, wi).0
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.f_pdf(wo, wi).1
    }
    #[inline]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (cos_o, cos_i) = (cos_theta(wo), cos_theta(wi));
        if same_hemisphere(wo, wi) || cos_o == 0.0 || cos_i == 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        // η_i/η_o: wi is inside when wo is outside.
        let eta = if cos_o > 0.0 {
            self.eta_b / self.eta_a
        } else {
            self.eta_a / self.eta_b
        };
        let sum = wo + wi * eta;
        if sum == Vec3::ZERO {
            return (Vec3::ZERO, 0.0);
        }
        let wh = sum.normalize();
        let wh = if wh.z < 0.0 { -wh } else { wh };
        let (wo_h, wi_h) = (wo.dot(wh), wi.dot(wh));
        // Both on one side of the facet: not a refraction through it.
        if wo_h * wi_h > 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let (d, g, pdf_wh) = self.distribution.d_g_pdf(wo, Some(wi), wh);
        let denom = wo_h + eta * wi_h;
        let denom2 = denom * denom;
        let fr = fr_dielectric(wo_h, self.eta_a, self.eta_b);
        let f = self.t * (1.0 - fr) * (d * g * wi_h * wo_h / (cos_i * cos_o * denom2)).abs();
        let pdf = pdf_wh * (eta * eta * wi_h / denom2).abs();
        (f, pdf)
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wh = self.distribution.sample_wh(wo, u);
        if wo.dot(wh) < 0.0 {
            return None;
        }
        let eta = if wo.z > 0.0 {
            self.eta_a / self.eta_b
        } else {
            self.eta_b / self.eta_a
        };
        let wi = refract(wo, wh, eta)?;
        let (f, pdf) = self.f_pdf(wo, wi);
        Some(BxdfSample {
            f,
            wi,
            pdf,
            flags: self.flags(),
        })
    }
}
