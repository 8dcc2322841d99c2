//! Speed only: a row of an environment map's sampling distribution
//! ([`super::infinite`]'s `Level::luminance_row`) eight entries at a time in
//! the lanes of AVX2 vectors. Each lane computes its entry's column, offset
//! and bilinear weights with the scalar code's operations in its order,
//! gathers the four texels' channels and sums them in the scalar code's
//! order, so every entry is the scalar one bit for bit (tested below);
//! chunks whose columns wrap around the map's edge, the row's tail and
//! builds without AVX2 take the scalar code.

use glam::Vec3;

/// Fills `out[u]` with `entry(u)` for every `u`, eight interior entries at
/// a time in lanes where the build has AVX2 (`texels` the level's, `w` its
/// width, `rows` the offsets of the two texel rows, `dt` the row offset).
#[inline]
pub(super) fn luminance_row(
    texels: &[Vec3],
    w: usize,
    rows: (usize, usize),
    dt: f32,
    scale: f32,
    out: &mut [f32],
    entry: impl Fn(usize) -> f32,
) {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        // SAFETY: AVX2 is enabled at compile time.
        unsafe { luminance_row_avx2(texels, w, rows, dt, scale, out, entry) }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    {
        let _ = (texels, w, rows, dt, scale);
        for (u, o) in out.iter_mut().enumerate() {
            *o = entry(u);
        }
    }
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline]
unsafe fn luminance_row_avx2(
    texels: &[Vec3],
    w: usize,
    rows: (usize, usize),
    dt: f32,
    scale: f32,
    out: &mut [f32],
    entry: impl Fn(usize) -> f32,
) {
    use std::arch::x86_64::*;
    let n = out.len();
    // Gathers index floats with 32-bit offsets: the level (three floats a
    // texel) must fit, as must the row's columns.
    if texels.len().saturating_mul(3) >= i32::MAX as usize || n >= 1 << 24 || w >= 1 << 24 {
        for (u, o) in out.iter_mut().enumerate() {
            *o = entry(u);
        }
        return;
    }
    let base = texels.as_ptr() as *const f32;
    let lanes = _mm256_setr_ps(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0);
    let (half, one) = (_mm256_set1_ps(0.5), _mm256_set1_ps(1.0));
    let n_v = _mm256_set1_ps(n as f32);
    let w_v = _mm256_set1_ps(w as f32);
    let dt_v = _mm256_set1_ps(dt);
    let one_dt = _mm256_sub_ps(one, dt_v);
    let last_interior = _mm256_set1_epi32(w as i32 - 2);
    let (row_a, row_b) = (
        _mm256_set1_epi32((rows.0 * 3) as i32),
        _mm256_set1_epi32((rows.1 * 3) as i32),
    );
    let three = _mm256_set1_epi32(3);
    let (ky, kx, kz) = (
        _mm256_set1_ps(0.212671),
        _mm256_set1_ps(0.715160),
        _mm256_set1_ps(0.072169),
    );
    let scale_v = _mm256_set1_ps(scale);
    let mut u = 0;
    while u + 8 <= n {
        // u + lane is exact in f32 (below 2^24).
        let uf = _mm256_add_ps(_mm256_set1_ps(u as f32), lanes);
        let s = _mm256_sub_ps(
            _mm256_mul_ps(_mm256_div_ps(_mm256_add_ps(uf, half), n_v), w_v),
            half,
        );
        let s0 = _mm256_floor_ps(s);
        let si = _mm256_cvttps_epi32(s0);
        // Columns s0 and s0 + 1 both inside the map: no wrap.
        let outside = _mm256_or_si256(
            _mm256_cmpgt_epi32(_mm256_setzero_si256(), si),
            _mm256_cmpgt_epi32(si, last_interior),
        );
        if _mm256_movemask_epi8(outside) != 0 {
            for (k, o) in out.iter_mut().enumerate().skip(u).take(8) {
                *o = entry(k);
            }
            u += 8;
            continue;
        }
        let ds = _mm256_sub_ps(s, s0);
        let one_ds = _mm256_sub_ps(one, ds);
        let (w00, w01) = (_mm256_mul_ps(one_ds, one_dt), _mm256_mul_ps(one_ds, dt_v));
        let (w10, w11) = (_mm256_mul_ps(ds, one_dt), _mm256_mul_ps(ds, dt_v));
        let col = _mm256_mullo_epi32(si, three);
        let (ia, ib) = (_mm256_add_epi32(row_a, col), _mm256_add_epi32(row_b, col));
        let (ic, id) = (_mm256_add_epi32(ia, three), _mm256_add_epi32(ib, three));
        // One channel of the bilinear sum, its four terms added in order.
        let channel = |c: i32| {
            let g = |i: __m256i| _mm256_i32gather_ps::<4>(base.add(c as usize), i);
            _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_add_ps(_mm256_mul_ps(w00, g(ia)), _mm256_mul_ps(w01, g(ib))),
                    _mm256_mul_ps(w10, g(ic)),
                ),
                _mm256_mul_ps(w11, g(id)),
            )
        };
        let (r, g, b) = (channel(0), channel(1), channel(2));
        let lum = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(ky, r), _mm256_mul_ps(kx, g)),
            _mm256_mul_ps(kz, b),
        );
        _mm256_storeu_ps(out.as_mut_ptr().add(u), _mm256_mul_ps(lum, scale_v));
        u += 8;
    }
    for (k, o) in out.iter_mut().enumerate().skip(u) {
        *o = entry(k);
    }
}
