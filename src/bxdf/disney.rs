//! The lobes of pbrt-v3's Disney BSDF (Burley 2012 and 2015, as pbrt-v3's
//! `materials/disney.cpp` has them), in the local shading frame. The
//! `disney` material combines them with pbrt-v3's microfacet lobes.
//!
//! With `Fo`, `Fi` the Schlick weights (1 − |cos θ|)⁵ of wo and wi, and
//! cos θd = wi·wh for the half vector wh = normalised wo + wi:
//!
//! - `DisneyDiffuse { r }`: f = r/π·(1 − Fo/2)(1 − Fi/2) (diffuse Fresnel:
//!   1 at normal incidence, ½ at grazing).
//! - `DisneyFakeSS { r, roughness }`: Hanrahan–Krueger-like flattened
//!   diffuse for thin surfaces: with Fss90 = cos²θd·roughness and
//!   Fss = lerp(Fo, 1, Fss90)·lerp(Fi, 1, Fss90),
//!   f = r/π·1.25·(Fss·(1/(|cos θo| + |cos θi|) − ½) + ½).
//! - `DisneyRetro { r, roughness }`: retro-reflection, with
//!   Rr = 2·roughness·cos²θd, f = r/π·Rr·(Fo + Fi + Fo·Fi·(Rr − 1)).
//! - `DisneySheen { r }`: f = r·(1 − cos θd)⁵ (no 1/π, as Burley's sheen).
//! - `DisneyClearcoat { weight, alpha }`: a glossy coat with the GTR1
//!   (Berry) normal distribution D(θh) = (α² − 1)/(π ln α² (1 + (α² − 1)cos²θh)),
//!   Schlick Fresnel with R0 = 0.04 at wo·wh, and a separable Smith GGX
//!   term with α = 0.25 written as G1/(2 cos θ), so that
//!   f = weight·D·F·g(θo)·g(θi)/4 with g(θ) = 1/(cos θ + √(α² + cos²θ − α²cos²θ)).
//!   It samples wh from D·cos θh exactly; density D·|cos θh|/(4 wo·wh).
//! - [`DisneyFresnel`]: the specular lobe's Fresnel term, lerp(metallic,
//!   dielectric Fresnel for η, Schlick Fresnel from R0).
//! - [`DisneyMicrofacet`]: the specular distribution, Trowbridge–Reitz with
//!   separable masking G = G1(wo)·G1(wi) (pbrt-v3's
//!   `DisneyMicrofacetDistribution`); D, Λ, sampling and density are
//!   Trowbridge–Reitz's.
//!
//! The diffuse-type lobes (all but the clearcoat) are cosine-sampled on
//! wo's side. None of their `f` tests the hemisphere: the BSDF decides
//! reflection against transmission by the geometric normal.

use super::{
    abs_cos_theta, fr_dielectric, reflect, same_hemisphere, BxdfFlags, BxdfModel, BxdfSample,
    MicrofacetModel, TrowbridgeReitz,
};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// Schlick's weight (1 − cos θ)⁵, the argument clamped to [0, 1].
#[inline]
pub fn schlick_weight(cos_theta: f32) -> f32 {
    let m = (1.0 - cos_theta).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's Fresnel approximation from the reflectance at normal incidence.
#[inline]
pub fn fr_schlick(r0: Vec3, cos_theta: f32) -> Vec3 {
    let w = schlick_weight(cos_theta);
    (1.0 - w) * r0 + Vec3::splat(w)
}

/// Reflectance at normal incidence of a dielectric of index `eta` in air.
#[inline]
pub fn schlick_r0_from_eta(eta: f32) -> f32 {
    let a = eta - 1.0;
    let b = eta + 1.0;
    (a * a) / (b * b)
}

/// cos θd = wi·wh for the half vector of `wo` and `wi`; None when they are
/// opposite (no half vector, where pbrt-v3's lobes return zero).
#[inline]
fn cos_theta_d(wo: Vec3, wi: Vec3) -> Option<f32> {
    let h = wo + wi;
    if h == Vec3::ZERO {
        None
    } else {
        Some(wi.dot(h.normalize()))
    }
}

const DIFFUSE_REFLECTION: BxdfFlags = BxdfFlags(BxdfFlags::REFLECTION.0 | BxdfFlags::DIFFUSE.0);

#[derive(Clone, Copy, Debug)]
pub struct DisneyDiffuse {
    pub r: Vec3,
}

impl BxdfModel for DisneyDiffuse {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        DIFFUSE_REFLECTION
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let fo = schlick_weight(abs_cos_theta(wo));
        let fi = schlick_weight(abs_cos_theta(wi));
        self.r * (FRAC_1_PI * (1.0 - 0.5 * fo) * (1.0 - 0.5 * fi))
    }
}

#[derive(Clone, Copy, Debug)]
pub struct DisneyFakeSS {
    pub r: Vec3,
    pub roughness: f32,
}

impl BxdfModel for DisneyFakeSS {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        DIFFUSE_REFLECTION
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(cd) = cos_theta_d(wo, wi) else {
            return Vec3::ZERO;
        };
        let fss90 = cd * cd * self.roughness;
        let (co, ci) = (abs_cos_theta(wo), abs_cos_theta(wi));
        let (fo, fi) = (schlick_weight(co), schlick_weight(ci));
        // lerp(t, 1, Fss90) = 1 + t·(Fss90 − 1).
        let fss = (1.0 + fo * (fss90 - 1.0)) * (1.0 + fi * (fss90 - 1.0));
        let ss = 1.25 * (fss * (1.0 / (co + ci) - 0.5) + 0.5);
        self.r * (FRAC_1_PI * ss)
    }
}

#[derive(Clone, Copy, Debug)]
pub struct DisneyRetro {
    pub r: Vec3,
    pub roughness: f32,
}

impl BxdfModel for DisneyRetro {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        DIFFUSE_REFLECTION
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(cd) = cos_theta_d(wo, wi) else {
            return Vec3::ZERO;
        };
        let fo = schlick_weight(abs_cos_theta(wo));
        let fi = schlick_weight(abs_cos_theta(wi));
        let rr = 2.0 * self.roughness * cd * cd;
        self.r * (FRAC_1_PI * rr * (fo + fi + fo * fi * (rr - 1.0)))
    }
}

#[derive(Clone, Copy, Debug)]
pub struct DisneySheen {
    pub r: Vec3,
}

impl BxdfModel for DisneySheen {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        DIFFUSE_REFLECTION
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match cos_theta_d(wo, wi) {
            Some(cd) => self.r * schlick_weight(cd),
            None => Vec3::ZERO,
        }
    }
}

/// Clearcoat: `weight` scales the lobe; `alpha` is GTR1's α (the material
/// maps `clearcoatgloss` 0..1 to α 0.1..0.001).
#[derive(Clone, Copy, Debug)]
pub struct DisneyClearcoat {
    pub weight: f32,
    pub alpha: f32,
}

/// GTR1 (Berry) normal distribution, normalised so that ∫ D cos θh dω = 1.
#[inline]
pub fn gtr1(cos_theta: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    (a2 - 1.0) / (PI * a2.ln() * (1.0 + (a2 - 1.0) * cos_theta * cos_theta))
}

/// Smith GGX masking for one direction, divided by 2 cos θ.
#[inline]
fn smith_g_ggx(cos_theta: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let c2 = cos_theta * cos_theta;
    1.0 / (cos_theta + (a2 + c2 - a2 * c2).sqrt())
}

/// The coat's masking roughness, fixed whatever the gloss (Burley 2012).
const CLEARCOAT_G_ALPHA: f32 = 0.25;

impl DisneyClearcoat {
    /// Half vector of a reflection pair, None when there is none.
    #[inline]
    fn half(wo: Vec3, wi: Vec3) -> Option<Vec3> {
        let h = wo + wi;
        (h != Vec3::ZERO).then(|| h.normalize())
    }
}

impl BxdfModel for DisneyClearcoat {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::REFLECTION | BxdfFlags::GLOSSY
    }
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(wh) = Self::half(wo, wi) else {
            return Vec3::ZERO;
        };
        let d = gtr1(abs_cos_theta(wh), self.alpha);
        // Schlick with R0 = 0.04 (an index of 1.5).
        let w = schlick_weight(wo.dot(wh));
        let fr = (1.0 - w) * 0.04 + w;
        let g = smith_g_ggx(abs_cos_theta(wo), CLEARCOAT_G_ALPHA)
            * smith_g_ggx(abs_cos_theta(wi), CLEARCOAT_G_ALPHA);
        Vec3::splat(self.weight * g * fr * d * 0.25)
    }
    #[inline]
    fn sample_f(&self, wo: Vec3, u: Vec2) -> Option<BxdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        // Invert the CDF of D·cos θh in cos²θh; φ uniform.
        let a2 = self.alpha * self.alpha;
        let cos_h = ((1.0 - a2.powf(1.0 - u.x)) / (1.0 - a2)).max(0.0).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let (s, c) = (2.0 * PI * u.y).sin_cos();
        let mut wh = Vec3::new(sin_h * c, sin_h * s, cos_h);
        if !same_hemisphere(wo, wh) {
            wh = -wh;
        }
        let wi = reflect(wo, wh);
        if !same_hemisphere(wo, wi) {
            return None;
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
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let Some(wh) = Self::half(wo, wi) else {
            return 0.0;
        };
        let cos_h = abs_cos_theta(wh);
        gtr1(cos_h, self.alpha) * cos_h / (4.0 * wo.dot(wh))
    }
}

/// The Disney specular Fresnel term: a blend by `metallic` of the
/// dielectric Fresnel of index `eta` (from air) and Schlick's from `r0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneyFresnel {
    pub r0: Vec3,
    pub metallic: f32,
    pub eta: f32,
}

impl DisneyFresnel {
    #[inline]
    pub fn evaluate(&self, cos_theta_i: f32) -> Vec3 {
        let dielectric = fr_dielectric(cos_theta_i, 1.0, self.eta);
        let schlick = fr_schlick(self.r0, cos_theta_i);
        (1.0 - self.metallic) * Vec3::splat(dielectric) + self.metallic * schlick
    }
}

/// Trowbridge–Reitz with Burley's separable Smith masking in place of the
/// height-correlated one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisneyMicrofacet {
    pub tr: TrowbridgeReitz,
}

impl DisneyMicrofacet {
    /// α along dp/du and dp/dv (clamped to ≥ 0.001), visible-normal sampling.
    #[inline]
    pub fn new(alpha_x: f32, alpha_y: f32) -> DisneyMicrofacet {
        DisneyMicrofacet {
            tr: TrowbridgeReitz::new(alpha_x, alpha_y),
        }
    }
}

impl MicrofacetModel for DisneyMicrofacet {
    #[inline]
    fn d(&self, wh: Vec3) -> f32 {
        self.tr.d(wh)
    }
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        self.tr.lambda(w)
    }
    #[inline]
    fn sample_wh(&self, wo: Vec3, u: Vec2) -> Vec3 {
        self.tr.sample_wh(wo, u)
    }
    #[inline]
    fn sample_visible(&self) -> bool {
        self.tr.sample_visible()
    }
    #[inline]
    fn g_from_lambdas(&self, lambda_o: f32, lambda_i: f32) -> f32 {
        1.0 / ((1.0 + lambda_o) * (1.0 + lambda_i))
    }
}
