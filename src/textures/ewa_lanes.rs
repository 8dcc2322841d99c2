//! EWA's scan of a footprint ([`super::mipmap::ewa_scan_plain`]) with the
//! r² of eight texels of a row at a time in the lanes of one AVX2 vector:
//! which texels are inside the ellipse and their weight-table entries come
//! out of one pass of vector operations, without a branch per texel; the
//! inside texels' positions and table entries are packed into a list (a
//! permutation per eight-bit mask), and the list is then read and added in
//! one loop, whose length is all the footprint decides (a branch per
//! chunk and per inside texel cost more than the scan's arithmetic: on a
//! scene of EWA lookups through specular bounces the scan took 0.97 of
//! the time). Each lane computes the
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

/// Room for the texels inside a footprint gathered before they are added
/// (a footprint with more adds them in runs of up to this many), plus a
/// vector's slack for the last store.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
const RUN: usize = 64;

/// For each eight-bit mask, the lanes whose bit is set, in order, as byte
/// indices (the rest 0): the permutation that packs a vector's chosen
/// lanes to its front.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
static PACK: [u64; 256] = {
    let mut table = [0u64; 256];
    let mut mask = 0;
    while mask < 256 {
        let (mut packed, mut n, mut lane) = (0u64, 0, 0);
        while lane < 8 {
            if mask & (1 << lane) != 0 {
                packed |= (lane as u64) << (8 * n);
                n += 1;
            }
            lane += 1;
        }
        table[mask] = packed;
        mask += 1;
    }
    table
};

/// Each row's r², inside test and table indices for eight texels at a
/// time; the inside texels' positions in the level (-1 for `black`'s
/// texels off the image) and table indices are packed into a list, in
/// order, without a branch per chunk or texel; then the list is added in
/// order.
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
    // A level's sides are powers of two, so `repeat`'s remainder (the
    // plain code's `rem_euclid`) is a mask, for negative indices too.
    debug_assert!(l.w.count_ones() == 1 && l.h.count_ones() == 1);
    let (w_mask, h_mask) = (l.w - 1, l.h - 1);
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
    let lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let (a, b) = (_mm256_set1_ps(e.a), _mm256_set1_ps(e.b));
    let st_x = _mm256_set1_ps(e.st.x);
    let one = _mm256_set1_ps(1.0);
    let table_size = _mm256_set1_ps(WEIGHT_LUT_SIZE as f32);
    let (zero, last) = (
        _mm256_setzero_si256(),
        _mm256_set1_epi32(WEIGHT_LUT_SIZE as i32 - 1),
    );
    let (w_mask_v, width) = (_mm256_set1_epi32(w_mask), _mm256_set1_epi32(l.w));
    let off_image = _mm256_set1_epi32(-1);
    // Positions in the level and table entries of the inside texels.
    let mut at = [0i32; RUN + 8];
    let mut entry = [0i32; RUN + 8];
    let mut n = 0usize;
    let mut add_run = |n: usize, at: &[i32; RUN + 8], entry: &[i32; RUN + 8]| {
        for k in 0..n {
            let weight = weights[entry[k] as usize];
            let texel = match at[k] {
                -1 => T::ZERO,
                i => l.texels[i as usize],
            };
            sum = sum.add(texel.scale(weight));
            sum_w += weight;
        }
    };
    for it in t0..=t1 {
        let tt = it as f32 - e.st.y;
        let ctt = e.c * tt * tt;
        let (tt, ctt) = (_mm256_set1_ps(tt), _mm256_set1_ps(ctt));
        let row = match wrap {
            Wrap::Repeat => (it & h_mask) * l.w,
            Wrap::Clamp => it.clamp(0, h_mask) * l.w,
            Wrap::Black => it.wrapping_mul(l.w),
        };
        let row_v = _mm256_set1_epi32(row);
        let row_inside = (0..l.h).contains(&it);
        let mut first = s0;
        loop {
            // Columns first..first + 8, of which `lanes_in` are in the box
            // (the lanes past it may wrap around i32 and are masked off).
            let count = s1 as i64 - first as i64 + 1;
            if count <= 0 {
                break;
            }
            let lanes_in = count.min(8) as u32;
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
            let mask = _mm256_movemask_ps(inside) as u32 & ((1u32 << lanes_in) - 1);
            // `as usize` truncates and takes negative values to 0; the
            // plain code then clamps to the table's last entry.
            let i = _mm256_cvttps_epi32(_mm256_mul_ps(r2, table_size));
            let i = _mm256_min_epi32(_mm256_max_epi32(i, zero), last);
            let texel = match wrap {
                Wrap::Repeat => _mm256_add_epi32(row_v, _mm256_and_si256(is, w_mask_v)),
                Wrap::Clamp => _mm256_add_epi32(
                    row_v,
                    _mm256_min_epi32(_mm256_max_epi32(is, zero), w_mask_v),
                ),
                Wrap::Black => {
                    // 0 ≤ is < w, on a row of the image.
                    let on = _mm256_andnot_si256(
                        _mm256_cmpgt_epi32(zero, is),
                        _mm256_cmpgt_epi32(width, is),
                    );
                    let on = if row_inside { on } else { zero };
                    _mm256_blendv_epi8(off_image, _mm256_add_epi32(row_v, is), on)
                }
            };
            let pack = _mm256_cvtepu8_epi32(_mm_loadl_epi64(
                PACK.as_ptr().add(mask as usize) as *const __m128i
            ));
            // n ≤ RUN - 8 here, and the arrays have RUN + 8 entries.
            _mm256_storeu_si256(
                entry.as_mut_ptr().add(n) as *mut __m256i,
                _mm256_permutevar8x32_epi32(i, pack),
            );
            _mm256_storeu_si256(
                at.as_mut_ptr().add(n) as *mut __m256i,
                _mm256_permutevar8x32_epi32(texel, pack),
            );
            n += mask.count_ones() as usize;
            if n > RUN - 8 {
                add_run(n, &at, &entry);
                n = 0;
            }
            if count <= 8 {
                break;
            }
            first += 8;
        }
    }
    add_run(n, &at, &entry);
    (sum, sum_w)
}
