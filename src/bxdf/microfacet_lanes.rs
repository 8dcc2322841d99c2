//! Trowbridge–Reitz's `(D(wh), G(wo, wi), pdf(wo, wh))` with the three
//! directions in the lanes of one SSE vector: each direction's sin θ, its
//! cos φ and sin φ (a square root and two divisions), then `wh`'s
//! 1/α² along its azimuth and `wo`'s and `wi`'s α and tan θ for Λ (another
//! square root and division each), computed side by side instead of one
//! direction's chain after the other's. Every lane performs the plain
//! code's operations on its direction in the same order (a clamp as
//! `f32::clamp` with its NaN, a select where the plain code branches), so
//! the results are [`super::microfacet::d_g_pdf_plain`]'s bit for bit
//! (tested below). Other architectures use the plain code.

use super::microfacet::{MicrofacetModel, TrowbridgeReitz};
use glam::Vec3;

/// [`MicrofacetModel::d_g_pdf`] of `m`.
#[inline]
pub(super) fn trowbridge_reitz_d_g_pdf(
    m: &TrowbridgeReitz,
    wo: Vec3,
    wi: Option<Vec3>,
    wh: Vec3,
) -> (f32, f32, f32) {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE and SSE2 are part of x86_64.
        unsafe { d_g_pdf_sse(m, wo, wi, wh) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        super::microfacet::d_g_pdf_plain(m, wo, wi, wh)
    }
}

#[cfg(target_arch = "x86_64")]
#[inline]
unsafe fn d_g_pdf_sse(
    m: &TrowbridgeReitz,
    wo: Vec3,
    wi: Option<Vec3>,
    wh: Vec3,
) -> (f32, f32, f32) {
    use std::arch::x86_64::*;
    use std::f32::consts::PI;
    let (ax, ay) = (m.alpha_x, m.alpha_y);
    // Lanes: wh, wo, wi (wo again without wi), unused.
    let w2 = wi.unwrap_or(wo);
    let x = _mm_setr_ps(wh.x, wo.x, w2.x, 0.0);
    let y = _mm_setr_ps(wh.y, wo.y, w2.y, 0.0);
    let z = _mm_setr_ps(wh.z, wo.z, w2.z, 1.0);
    let (zero, one) = (_mm_setzero_ps(), _mm_set1_ps(1.0));
    // cos²θ, sin²θ = max(1 − cos²θ, 0) (a NaN gives 0, as f32::max), sin θ.
    let cos2 = _mm_mul_ps(z, z);
    let sin2 = _mm_max_ps(_mm_sub_ps(one, cos2), zero);
    let sin = _mm_sqrt_ps(sin2);
    // cos φ = clamp(x / sin θ, −1, 1) and sin φ = clamp(y / sin θ, −1, 1),
    // 1 and 0 where sin θ = 0. The constant is the first operand of max
    // and min, so that a NaN quotient passes through as f32::clamp's does.
    let clamp = |v: __m128| _mm_min_ps(one, _mm_max_ps(_mm_set1_ps(-1.0), v));
    let pole = _mm_cmpeq_ps(sin, zero);
    let select =
        |mask: __m128, a: __m128, b: __m128| _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
    let cos_phi = select(pole, one, clamp(_mm_div_ps(x, sin)));
    let sin_phi = select(pole, zero, clamp(_mm_div_ps(y, sin)));
    let cos2_phi = _mm_mul_ps(cos_phi, cos_phi);
    let sin2_phi = _mm_mul_ps(sin_phi, sin_phi);
    // D's 1/α² along the azimuth and (cos²θ + sin²θ/α²) (lane wh).
    let inv_alpha2 = _mm_add_ps(
        _mm_div_ps(cos2_phi, _mm_set1_ps(ax * ax)),
        _mm_div_ps(sin2_phi, _mm_set1_ps(ay * ay)),
    );
    let e = _mm_add_ps(cos2, _mm_mul_ps(sin2, inv_alpha2));
    // Λ's α along the azimuth, |tan θ| and Λ (lanes wo and wi).
    let (vax, vay) = (_mm_set1_ps(ax), _mm_set1_ps(ay));
    let alpha = _mm_sqrt_ps(_mm_add_ps(
        _mm_mul_ps(_mm_mul_ps(cos2_phi, vax), vax),
        _mm_mul_ps(_mm_mul_ps(sin2_phi, vay), vay),
    ));
    let tan = _mm_andnot_ps(_mm_set1_ps(-0.0), _mm_div_ps(sin, z));
    let at = _mm_mul_ps(alpha, tan);
    let lambda = _mm_mul_ps(
        _mm_set1_ps(0.5),
        _mm_sub_ps(_mm_sqrt_ps(_mm_add_ps(one, _mm_mul_ps(at, at))), one),
    );
    let lambda = select(_mm_cmpeq_ps(tan, _mm_set1_ps(f32::INFINITY)), zero, lambda);
    let mut c = [0f32; 4];
    let mut ev = [0f32; 4];
    let mut l = [0f32; 4];
    _mm_storeu_ps(c.as_mut_ptr(), cos2);
    _mm_storeu_ps(ev.as_mut_ptr(), e);
    _mm_storeu_ps(l.as_mut_ptr(), lambda);
    let d = if c[0] == 0.0 {
        0.0
    } else {
        1.0 / (PI * ax * ay * ev[0] * ev[0])
    };
    let visible = m.sample_visible();
    let lambda_o = if visible || wi.is_some() { l[1] } else { 0.0 };
    let g = if wi.is_some() {
        m.g_from_lambdas(lambda_o, l[2])
    } else {
        0.0
    };
    super::microfacet::d_g_pdf_finish(visible, d, g, lambda_o, wo, wh)
}

#[cfg(test)]
mod tests {
    use super::super::microfacet::d_g_pdf_plain;
    use super::*;
    use crate::sampling::rng::Pcg32;

    fn bits(v: (f32, f32, f32)) -> [u32; 3] {
        [v.0.to_bits(), v.1.to_bits(), v.2.to_bits()]
    }

    /// Random unit and non-unit directions, the poles (sin θ = 0, ±0
    /// components), the horizon (cos θ = 0), axis-aligned azimuths and
    /// NaN components; isotropic, anisotropic and extreme α; with and
    /// without `wi`, visible-normal sampling on and off.
    #[test]
    fn lanes_are_the_plain_terms() {
        let mut rng = Pcg32::with_sequence(5);
        let dir = |rng: &mut Pcg32| -> Vec3 {
            match rng.uniform_u32_below(12) {
                0 => Vec3::new(0.0, 0.0, 1.0),
                1 => Vec3::new(-0.0, 0.0, -1.0),
                2 => Vec3::new(1.0, 0.0, 0.0),
                3 => Vec3::new(0.6, -0.8, 0.0),
                4 => Vec3::new(0.0, 1.0, 1e-20),
                5 => Vec3::new(f32::NAN, 0.5, 0.5),
                6 => Vec3::new(1e-30, -1e-30, 1.0),
                7 => Vec3::new(rng.uniform_f32(), 0.0, rng.uniform_f32() - 0.5) * 3.0,
                _ => {
                    let v = Vec3::new(
                        rng.uniform_f32() - 0.5,
                        rng.uniform_f32() - 0.5,
                        rng.uniform_f32() - 0.5,
                    );
                    if rng.uniform_u32_below(4) == 0 {
                        v * 1.7
                    } else {
                        v.normalize()
                    }
                }
            }
        };
        let alphas = [1e-3, 0.01, 0.2, 0.5, 1.0, 1.6, 30.0];
        let mut checked = 0;
        for _ in 0..200_000 {
            let ax = alphas[rng.uniform_u32_below(7) as usize] * (0.5 + rng.uniform_f32());
            let ay = if rng.uniform_u32_below(2) == 0 {
                ax
            } else {
                alphas[rng.uniform_u32_below(7) as usize]
            };
            let m =
                TrowbridgeReitz::new(ax, ay).with_visible_sampling(rng.uniform_u32_below(3) != 0);
            let (wo, wh) = (dir(&mut rng), dir(&mut rng));
            let wi = (rng.uniform_u32_below(3) != 0).then(|| dir(&mut rng));
            let fast = trowbridge_reitz_d_g_pdf(&m, wo, wi, wh);
            let plain = d_g_pdf_plain(&m, wo, wi, wh);
            assert_eq!(
                bits(fast),
                bits(plain),
                "{m:?} wo {wo} wi {wi:?} wh {wh}: {fast:?} {plain:?}"
            );
            checked += 1;
        }
        assert_eq!(checked, 200_000);
    }
}
