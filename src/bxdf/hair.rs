//! pbrt-v3's `HairBSDF` (materials/hair.{h,cpp}; d'Eon et al.'s and
//! Chiang et al.'s model as pbrt-v3 implements it): scattering from a
//! rough dielectric cylinder with an absorbing interior, as the sum of
//! the paths p = 0 (R), 1 (TT), 2 (TRT) and a term for every longer path.
//!
//! Local frame: x along the hair (the curve's dp/du), the y-z plane across
//! it; θ is measured from that plane (sin θ = w.x) and φ in it
//! (φ = atan2(z, y)). `h` ∈ [−1, 1] is where the ray meets the hair's
//! width (the curve's v mapped to [−1, 1]).
//!
//! - Longitudinal: `m_p`, the von Mises–Fisher-like lobe of variance v_p
//!   (v_0 from β_m, v_1 = v_0 / 4, v_2 = v_3 = 4 v_0), with the scales'
//!   tilt α rotating θ_i by 2α, −α and −4α for p = 0, 1, 2.
//! - Attenuation: `a_p` from the dielectric Fresnel term at the entry point
//!   and the transmittance T = exp(−σ_a · 2 cos γ_t / cos θ_t) of one
//!   crossing, with the geometric series for p ≥ 3.
//! - Azimuthal: `n_p`, a logistic of scale s (from β_n) trimmed to
//!   [−π, π] around Φ(p) = 2p γ_t − 2γ_o + pπ; uniform for p ≥ 3.
//!
//! Sampling as pbrt-v3: the two uniform numbers are split into four by
//! de-interleaving their bits; the first picks p by the luminance of a_p,
//! the second θ_i from m_p, then φ from n_p. Everything is f32 in pbrt-v3's
//! order of operations.

use super::{BxdfFlags, BxdfModel, BxdfSample};
use crate::bxdf::fr_dielectric;
use crate::geometry::luminance;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Paths given their own lobes (p < P_MAX); p = P_MAX stands for all longer.
pub const P_MAX: usize = 3;
const SQRT_PI_OVER_8: f32 = 0.626_657_07;

/// pbrt-v3's `Pow<n>`: squares of the half power, in its order.
fn pow_n(v: f32, n: u32) -> f32 {
    match n {
        0 => 1.0,
        1 => v,
        _ => {
            let h = pow_n(v, n / 2);
            h * h * pow_n(v, n & 1)
        }
    }
}

fn sqr(v: f32) -> f32 {
    v * v
}

fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

fn safe_asin(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).asin()
}

/// The modified Bessel function I₀ by its series' first ten terms.
fn i0(x: f32) -> f32 {
    let mut val = 0.0f32;
    let mut x2i = 1.0f32;
    let mut ifact = 1i32;
    let mut i4 = 1i32;
    for i in 0..10 {
        if i > 1 {
            ifact *= i;
        }
        val += x2i / (i4 as f32 * sqr(ifact as f32));
        x2i *= x * x;
        i4 *= 4;
    }
    val
}

fn log_i0(x: f32) -> f32 {
    if x > 12.0 {
        // pbrt-v3's `0.5` is a double: the sum is rounded once, at the end.
        let tail = -(2.0 * PI).ln() + (1.0 / x).ln() + 1.0 / (8.0 * x);
        (x as f64 + 0.5 * tail as f64) as f32
    } else {
        i0(x).ln()
    }
}

/// The longitudinal lobe (pbrt-v3's constant 0.6931 for ln 2, kept).
#[allow(clippy::approx_constant)]
fn mp(cos_i: f32, cos_o: f32, sin_i: f32, sin_o: f32, v: f32) -> f32 {
    let a = cos_i * cos_o / v;
    let b = sin_i * sin_o / v;
    if v <= 0.1 {
        (log_i0(a) - b - 1.0 / v + 0.6931 + (1.0 / (2.0 * v)).ln()).exp()
    } else {
        ((-b).exp() * i0(a)) / ((1.0 / v).sinh() * 2.0 * v)
    }
}

/// Attenuation of each p.
fn ap(cos_o: f32, eta: f32, h: f32, t: Vec3) -> [Vec3; P_MAX + 1] {
    let cos_gamma_o = safe_sqrt(1.0 - h * h);
    let cos_theta = cos_o * cos_gamma_o;
    let f = fr_dielectric(cos_theta, 1.0, eta);
    let mut a = [Vec3::ZERO; P_MAX + 1];
    a[0] = Vec3::splat(f);
    a[1] = sqr(1.0 - f) * t;
    for p in 2..P_MAX {
        a[p] = a[p - 1] * t * f;
    }
    a[P_MAX] = a[P_MAX - 1] * f * t / (Vec3::ONE - t * f);
    a
}

fn phi(p: usize, gamma_o: f32, gamma_t: f32) -> f32 {
    2.0 * p as f32 * gamma_t - 2.0 * gamma_o + p as f32 * PI
}

fn logistic(x: f32, s: f32) -> f32 {
    let x = x.abs();
    (-x / s).exp() / (s * sqr(1.0 + (-x / s).exp()))
}

fn logistic_cdf(x: f32, s: f32) -> f32 {
    1.0 / (1.0 + (-x / s).exp())
}

fn trimmed_logistic(x: f32, s: f32, a: f32, b: f32) -> f32 {
    logistic(x, s) / (logistic_cdf(b, s) - logistic_cdf(a, s))
}

/// The azimuthal lobe at relative azimuth `phi_` (wrapped to [−π, π]).
fn np(phi_: f32, p: usize, s: f32, gamma_o: f32, gamma_t: f32) -> f32 {
    let mut dphi = phi_ - phi(p, gamma_o, gamma_t);
    while dphi > PI {
        dphi -= 2.0 * PI;
    }
    while dphi < -PI {
        dphi += 2.0 * PI;
    }
    trimmed_logistic(dphi, s, -PI, PI)
}

fn sample_trimmed_logistic(u: f32, s: f32, a: f32, b: f32) -> f32 {
    let k = logistic_cdf(b, s) - logistic_cdf(a, s);
    let x = -s * (1.0 / (u * k + logistic_cdf(a, s)) - 1.0).ln();
    x.clamp(a, b)
}

/// Even bits of `x` packed into the low 16.
fn compact_1_by_1(x: u32) -> u32 {
    let mut x = x & 0x5555_5555;
    x = (x ^ (x >> 1)) & 0x3333_3333;
    x = (x ^ (x >> 2)) & 0x0f0f_0f0f;
    x = (x ^ (x >> 4)) & 0x00ff_00ff;
    x = (x ^ (x >> 8)) & 0x0000_ffff;
    x
}

/// Two 16-bit uniform numbers from the interleaved bits of one.
fn demux(f: f32) -> Vec2 {
    let v = (f * 4_294_967_296.0) as u64;
    let a = compact_1_by_1(v as u32);
    let b = compact_1_by_1((v >> 1) as u32);
    Vec2::new(a as f32 / 65536.0, b as f32 / 65536.0)
}

/// pbrt-v3's `SigmaAFromConcentration`: absorption of eumelanin and
/// pheomelanin concentrations.
pub fn sigma_a_from_concentration(ce: f32, cp: f32) -> Vec3 {
    let eu = [0.419f32, 0.697, 1.37];
    let ph = [0.187f32, 0.4, 1.05];
    Vec3::from_array(std::array::from_fn(|i| ce * eu[i] + cp * ph[i]))
}

/// pbrt-v3's `SigmaAFromReflectance`: the absorption that gives roughly
/// the colour `c` after multiple scattering, for azimuthal roughness β_n.
pub fn sigma_a_from_reflectance(c: Vec3, beta_n: f32) -> Vec3 {
    let d = 5.969 - 0.215 * beta_n + 2.532 * sqr(beta_n) - 10.73 * pow_n(beta_n, 3)
        + 5.574 * pow_n(beta_n, 4)
        + 0.245 * pow_n(beta_n, 5);
    Vec3::from_array(c.to_array().map(|c| sqr(c.ln() / d)))
}

#[derive(Clone, Copy, Debug)]
pub struct HairBsdf {
    h: f32,
    gamma_o: f32,
    eta: f32,
    sigma_a: Vec3,
    /// v_0, v_1, v_2 (v_3 = v_2).
    v: [f32; 3],
    s: f32,
    sin_2k_alpha: [f32; 3],
    cos_2k_alpha: [f32; 3],
}

impl HairBsdf {
    /// `alpha` is the scales' tilt as pbrt-v3's `HairBSDF` constructor
    /// takes it (it applies `Radians` to it).
    pub fn new(h: f32, eta: f32, sigma_a: Vec3, beta_m: f32, beta_n: f32, alpha: f32) -> Self {
        let v0 = sqr(0.726 * beta_m + 0.812 * sqr(beta_m) + 3.7 * pow_n(beta_m, 20));
        let s = SQRT_PI_OVER_8 * (0.265 * beta_n + 1.194 * sqr(beta_n) + 5.372 * pow_n(beta_n, 22));
        let mut sin_2k_alpha = [0.0f32; 3];
        let mut cos_2k_alpha = [0.0f32; 3];
        sin_2k_alpha[0] = alpha.to_radians().sin();
        cos_2k_alpha[0] = safe_sqrt(1.0 - sqr(sin_2k_alpha[0]));
        for i in 1..3 {
            sin_2k_alpha[i] = 2.0 * cos_2k_alpha[i - 1] * sin_2k_alpha[i - 1];
            cos_2k_alpha[i] = sqr(cos_2k_alpha[i - 1]) - sqr(sin_2k_alpha[i - 1]);
        }
        HairBsdf {
            h,
            gamma_o: safe_asin(h),
            eta,
            sigma_a,
            v: [v0, 0.25 * v0, 4.0 * v0],
            s,
            sin_2k_alpha,
            cos_2k_alpha,
        }
    }

    #[inline]
    fn v(&self, p: usize) -> f32 {
        self.v[p.min(2)]
    }

    /// sin θ_i, cos θ_i with the scales' tilt for lobe p, as `f` and `pdf`
    /// evaluate it.
    fn tilted(&self, p: usize, sin_i: f32, cos_i: f32) -> (f32, f32) {
        let (s, c) = (&self.sin_2k_alpha, &self.cos_2k_alpha);
        let (sin_ip, cos_ip) = match p {
            0 => (sin_i * c[1] + cos_i * s[1], cos_i * c[1] - sin_i * s[1]),
            1 => (sin_i * c[0] - cos_i * s[0], cos_i * c[0] + sin_i * s[0]),
            2 => (sin_i * c[2] - cos_i * s[2], cos_i * c[2] + sin_i * s[2]),
            _ => (sin_i, cos_i),
        };
        (sin_ip, cos_ip.abs())
    }

    /// γ_t and the transmittance of one crossing, for sin θ_o.
    fn refracted(&self, sin_o: f32, cos_o: f32) -> (f32, Vec3) {
        let sin_t = sin_o / self.eta;
        let cos_t = safe_sqrt(1.0 - sqr(sin_t));
        let etap = (self.eta * self.eta - sqr(sin_o)).sqrt() / cos_o;
        let sin_gamma_t = self.h / etap;
        let cos_gamma_t = safe_sqrt(1.0 - sqr(sin_gamma_t));
        let t = (-self.sigma_a * (2.0 * cos_gamma_t / cos_t)).exp();
        (safe_asin(sin_gamma_t), t)
    }

    /// γ_t alone (pbrt-v3's `Sample_f` and `Pdf` compute it so).
    fn gamma_t(&self, sin_o: f32, cos_o: f32) -> f32 {
        let etap = (self.eta * self.eta - sqr(sin_o)).sqrt() / cos_o;
        safe_asin(self.h / etap)
    }

    /// How likely each p is sampled: a_p's luminance, normalised.
    fn ap_pdf(&self, cos_o: f32) -> [f32; P_MAX + 1] {
        let sin_o = safe_sqrt(1.0 - cos_o * cos_o);
        let (_, t) = self.refracted(sin_o, cos_o);
        let a = ap(cos_o, self.eta, self.h, t);
        let sum = a.iter().fold(0.0f32, |s, a| s + luminance(*a));
        a.map(|a| luminance(a) / sum)
    }

    /// The density of `wi` given `wo`'s angles, the relative azimuth and
    /// the p probabilities.
    #[allow(clippy::too_many_arguments)]
    fn pdf_of(
        &self,
        sin_o: f32,
        cos_o: f32,
        sin_i: f32,
        cos_i: f32,
        dphi: f32,
        gamma_t: f32,
        ap_pdf: &[f32; P_MAX + 1],
    ) -> f32 {
        let mut pdf = 0.0;
        for (p, &w) in ap_pdf.iter().enumerate().take(P_MAX) {
            let (sin_ip, cos_ip) = self.tilted(p, sin_i, cos_i);
            pdf += mp(cos_ip, cos_o, sin_ip, sin_o, self.v(p))
                * w
                * np(dphi, p, self.s, self.gamma_o, gamma_t);
        }
        pdf + mp(cos_i, cos_o, sin_i, sin_o, self.v(P_MAX)) * ap_pdf[P_MAX] * (1.0 / (2.0 * PI))
    }
}

/// sin θ, cos θ and φ of a local direction.
fn angles(w: Vec3) -> (f32, f32, f32) {
    (w.x, safe_sqrt(1.0 - sqr(w.x)), w.z.atan2(w.y))
}

impl BxdfModel for HairBsdf {
    #[inline]
    fn flags(&self) -> BxdfFlags {
        BxdfFlags::GLOSSY | BxdfFlags::REFLECTION | BxdfFlags::TRANSMISSION
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (sin_o, cos_o, phi_o) = angles(wo);
        let (sin_i, cos_i, phi_i) = angles(wi);
        let (gamma_t, t) = self.refracted(sin_o, cos_o);
        let dphi = phi_i - phi_o;
        let a = ap(cos_o, self.eta, self.h, t);
        let mut sum = Vec3::ZERO;
        for (p, a) in a.iter().enumerate().take(P_MAX) {
            let (sin_ip, cos_ip) = self.tilted(p, sin_i, cos_i);
            sum += mp(cos_ip, cos_o, sin_ip, sin_o, self.v(p))
                * *a
                * np(dphi, p, self.s, self.gamma_o, gamma_t);
        }
        sum += mp(cos_i, cos_o, sin_i, sin_o, self.v(P_MAX)) * a[P_MAX] / (2.0 * PI);
        if wi.z.abs() > 0.0 {
            sum /= wi.z.abs();
        }
        sum
    }

    fn sample_f(&self, wo: Vec3, u2: Vec2) -> Option<BxdfSample> {
        let (sin_o, cos_o, phi_o) = angles(wo);
        let (mut u0, mut u1) = (demux(u2.x), demux(u2.y));
        let ap_pdf = self.ap_pdf(cos_o);
        let mut p = 0;
        while p < P_MAX {
            if u0.x < ap_pdf[p] {
                break;
            }
            u0.x -= ap_pdf[p];
            p += 1;
        }
        // θ_i from m_p.
        u1.x = u1.x.max(1e-5);
        let v = self.v(p);
        let cos_theta = 1.0 + v * (u1.x + (1.0 - u1.x) * (-2.0 / v).exp()).ln();
        let sin_theta = safe_sqrt(1.0 - sqr(cos_theta));
        let cos_phi = (2.0 * PI * u1.y).cos();
        let mut sin_i = -cos_theta * sin_o + sin_theta * cos_phi * cos_o;
        let mut cos_i = safe_sqrt(1.0 - sqr(sin_i));
        // The scales' tilt, undone.
        let (s, c) = (&self.sin_2k_alpha, &self.cos_2k_alpha);
        (sin_i, cos_i) = match p {
            0 => (sin_i * c[1] - cos_i * s[1], cos_i * c[1] + sin_i * s[1]),
            1 => (sin_i * c[0] + cos_i * s[0], cos_i * c[0] - sin_i * s[0]),
            2 => (sin_i * c[2] + cos_i * s[2], cos_i * c[2] - sin_i * s[2]),
            _ => (sin_i, cos_i),
        };
        // φ from n_p.
        let gamma_t = self.gamma_t(sin_o, cos_o);
        let dphi = if p < P_MAX {
            phi(p, self.gamma_o, gamma_t) + sample_trimmed_logistic(u0.y, self.s, -PI, PI)
        } else {
            2.0 * PI * u0.y
        };
        let phi_i = phi_o + dphi;
        let wi = Vec3::new(sin_i, cos_i * phi_i.cos(), cos_i * phi_i.sin());
        let pdf = self.pdf_of(sin_o, cos_o, sin_i, cos_i, dphi, gamma_t, &ap_pdf);
        Some(BxdfSample {
            f: self.f(wo, wi),
            wi,
            pdf,
            flags: self.flags(),
        })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (sin_o, cos_o, phi_o) = angles(wo);
        let (sin_i, cos_i, phi_i) = angles(wi);
        let gamma_t = self.gamma_t(sin_o, cos_o);
        let ap_pdf = self.ap_pdf(cos_o);
        self.pdf_of(sin_o, cos_o, sin_i, cos_i, phi_i - phi_o, gamma_t, &ap_pdf)
    }
}
