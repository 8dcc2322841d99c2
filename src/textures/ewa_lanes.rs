//! EWA's scan of a footprint ([`super::mipmap::ewa_scan_plain`]) with the
//! r² of eight texels of a row at a time in the lanes of one AVX2 vector:
//! which texels are inside the ellipse and their weight-table entries come
//! out of one pass of vector operations, without a branch per texel, and
//! only the texels inside are then read and added. Each lane computes the
//! plain code's r² with its operations in the same order, the table index
//! is the plain code's (truncated and clamped alike), and the sums add the
//! texels in the plain code's order, so the sums are its bit for bit
//! (tested in `mipmap.rs`). Builds without AVX2 use the plain code.

use super::mipmap::{Ellipse, Level, Wrap, WEIGHT_LUT_SIZE};
use super::TexValue;

/// The weighted sum of the footprint's texels and the sum of their
/// weights (see [`super::mipmap::ewa_scan_plain`]).
#[inline]
pub(super) fn scan<T: TexValue>(
    l: &Level<T>,
    e: &Ellipse,
    weights: &[f32; WEIGHT_LUT_SIZE],
    wrap: Wrap,
) -> (T, f32) {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        // SAFETY: AVX2 is enabled at compile time.
        unsafe { scan_avx2(l, e, weights, wrap) }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    {
        super::mipmap::ewa_scan_plain(l, e, weights, wrap)
    }
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
unsafe fn scan_avx2<T: TexValue>(
    l: &Level<T>,
    e: &Ellipse,
    weights: &[f32; WEIGHT_LUT_SIZE],
    wrap: Wrap,
) -> (T, f32) {
    use std::arch::x86_64::*;
    let (s0, s1, t0, t1) = e.texel_box();
    let mut sum = T::ZERO;
    let mut sum_w = 0.0f32;
    let repeat = wrap == Wrap::Repeat;
    // A level's sides are powers of two, so `repeat`'s remainder (the
    // plain code's `rem_euclid`) is a mask, for negative indices too.
    debug_assert!(l.w.count_ones() == 1 && l.h.count_ones() == 1);
    let (w_mask, h_mask) = (l.w - 1, l.h - 1);
    let lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let (a, b) = (_mm256_set1_ps(e.a), _mm256_set1_ps(e.b));
    let st_x = _mm256_set1_ps(e.st.x);
    let one = _mm256_set1_ps(1.0);
    let table_size = _mm256_set1_ps(WEIGHT_LUT_SIZE as f32);
    let (zero, last) = (
        _mm256_setzero_si256(),
        _mm256_set1_epi32(WEIGHT_LUT_SIZE as i32 - 1),
    );
    let mut index = [0i32; 8];
    // The rows' texels are far apart in a big level (a row of a 1024-texel
    // RGB level is 12 KiB): the first and last cache line of every row
    // (up to 16 rows) are asked for before the scan reads any, so that
    // their misses overlap. A hint: nothing is read.
    if t1 >= t0 && s1 >= s0 && (t1 as i64 - t0 as i64) < 16 {
        for it in t0..=t1 {
            for is in [s0, s1] {
                let (s, t) = match wrap {
                    Wrap::Repeat => (is & w_mask, it & h_mask),
                    Wrap::Clamp | Wrap::Black => (is.clamp(0, w_mask), it.clamp(0, h_mask)),
                };
                crate::accel::prefetch(l.texels.as_ptr().wrapping_add((t * l.w + s) as usize));
            }
        }
    }
    for it in t0..=t1 {
        let tt = it as f32 - e.st.y;
        let ctt = e.c * tt * tt;
        let (tt, ctt) = (_mm256_set1_ps(tt), _mm256_set1_ps(ctt));
        let row = if repeat { (it & h_mask) * l.w } else { 0 };
        let mut first = s0;
        loop {
            // Columns first..first + 8, of which `n` are in the box (the
            // lanes past it may wrap around i32 and are masked off).
            let count = s1 as i64 - first as i64 + 1;
            if count <= 0 {
                break;
            }
            let n = count.min(8) as u32;
            let is = _mm256_add_epi32(_mm256_set1_epi32(first), lanes);
            let ss = _mm256_sub_ps(_mm256_cvtepi32_ps(is), st_x);
            // a·ss·ss + b·ss·tt + c·tt·tt, as the plain code groups it.
            let r2 = _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(_mm256_mul_ps(a, ss), ss),
                    _mm256_mul_ps(_mm256_mul_ps(b, ss), tt),
                ),
                ctt,
            );
            let inside = _mm256_cmp_ps::<_CMP_LT_OQ>(r2, one);
            let mut mask = _mm256_movemask_ps(inside) as u32 & ((1u32 << n) - 1);
            if mask != 0 {
                // `as usize` truncates and takes negative values to 0; the
                // plain code then clamps to the table's last entry.
                let i = _mm256_cvttps_epi32(_mm256_mul_ps(r2, table_size));
                let i = _mm256_min_epi32(_mm256_max_epi32(i, zero), last);
                _mm256_storeu_si256(index.as_mut_ptr() as *mut __m256i, i);
                while mask != 0 {
                    let k = mask.trailing_zeros();
                    mask &= mask - 1;
                    let is = first + k as i32;
                    let weight = weights[index[k as usize] as usize];
                    let texel = if repeat {
                        l.texels[(row + (is & w_mask)) as usize]
                    } else {
                        super::mipmap::texel_of(l, is, it, wrap)
                    };
                    sum = sum.add(texel.scale(weight));
                    sum_w += weight;
                }
            }
            if count <= 8 {
                break;
            }
            first += 8;
        }
    }
    (sum, sum_w)
}
