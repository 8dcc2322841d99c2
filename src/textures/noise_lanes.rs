//! pbrt-v3's Perlin noise with its eight lattice corners in the lanes of
//! one AVX2 vector: the corners' hashes are looked up as in
//! [`super::noise::noise_plain`] (sharing the chain's common steps), then
//! every corner's offsets and gradient, and the four interpolations along
//! x, run as lane-wise vector operations. Each lane performs the plain
//! code's operations on its corner in the same order (a negation as a flip
//! of the sign bit, as `-u` is), so the value is the plain code's bit for
//! bit (tested there). Builds without AVX2 use the plain code.

use super::noise::{perm, weight};

/// pbrt-v3's `Noise(x, y, z)` (see [`super::noise::noise_plain`]).
#[inline]
pub fn noise(x: f32, y: f32, z: f32) -> f32 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        // SAFETY: AVX2 is enabled at compile time.
        unsafe { noise_avx2(x, y, z) }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    {
        super::noise::noise_plain(x, y, z)
    }
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline]
unsafe fn noise_avx2(x: f32, y: f32, z: f32) -> f32 {
    use std::arch::x86_64::*;
    let (ix, iy, iz) = (x.floor() as i32, y.floor() as i32, z.floor() as i32);
    let (dx, dy, dz) = (x - ix as f32, y - iy as f32, z - iz as f32);
    let (ix, iy, iz) = (ix & 255, iy & 255, iz & 255);
    // Lane k is the corner with x + 1 if bit 0 of k is set, y + 1 for bit
    // 1 and z + 1 for bit 2: the order in which the interpolation pairs
    // them (x fastest).
    let px = [perm(ix), perm(ix + 1)];
    let pxy = [
        perm(px[0] + iy),
        perm(px[1] + iy),
        perm(px[0] + iy + 1),
        perm(px[1] + iy + 1),
    ];
    let h = _mm256_setr_epi32(
        perm(pxy[0] + iz),
        perm(pxy[1] + iz),
        perm(pxy[2] + iz),
        perm(pxy[3] + iz),
        perm(pxy[0] + iz + 1),
        perm(pxy[1] + iz + 1),
        perm(pxy[2] + iz + 1),
        perm(pxy[3] + iz + 1),
    );
    let h = _mm256_and_si256(h, _mm256_set1_epi32(15));
    // The corners' offsets: d or d − 1 per axis.
    let one = _mm256_set1_ps(1.0);
    let offset = |d: f32, lanes: __m256| {
        let d = _mm256_set1_ps(d);
        _mm256_blendv_ps(d, _mm256_sub_ps(d, one), lanes)
    };
    let x_lanes = _mm256_castsi256_ps(_mm256_setr_epi32(0, -1, 0, -1, 0, -1, 0, -1));
    let y_lanes = _mm256_castsi256_ps(_mm256_setr_epi32(0, 0, -1, -1, 0, 0, -1, -1));
    let z_lanes = _mm256_castsi256_ps(_mm256_setr_epi32(0, 0, 0, 0, -1, -1, -1, -1));
    let ox = offset(dx, x_lanes);
    let oy = offset(dy, y_lanes);
    let oz = offset(dz, z_lanes);
    // pbrt-v3's `Grad`: u is the x offset for h < 8, 12 and 13, else y; v
    // is y for h < 4, 12 and 13, else z; bits 0 and 1 negate them.
    let eq = |k: i32| _mm256_cmpeq_epi32(h, _mm256_set1_epi32(k));
    let below = |k: i32| _mm256_cmpgt_epi32(_mm256_set1_epi32(k), h);
    let twelve_thirteen = _mm256_or_si256(eq(12), eq(13));
    let use_x = _mm256_castsi256_ps(_mm256_or_si256(below(8), twelve_thirteen));
    let use_y = _mm256_castsi256_ps(_mm256_or_si256(below(4), twelve_thirteen));
    let u = _mm256_blendv_ps(oy, ox, use_x);
    let v = _mm256_blendv_ps(oz, oy, use_y);
    let sign_u = _mm256_castsi256_ps(_mm256_slli_epi32::<31>(_mm256_and_si256(
        h,
        _mm256_set1_epi32(1),
    )));
    let sign_v = _mm256_castsi256_ps(_mm256_slli_epi32::<30>(_mm256_and_si256(
        h,
        _mm256_set1_epi32(2),
    )));
    let g = _mm256_add_ps(_mm256_xor_ps(u, sign_u), _mm256_xor_ps(v, sign_v));
    let (wx, wy, wz) = (weight(dx), weight(dy), weight(dz));
    // Along x: (1 − wx)·g[2k] + wx·g[2k + 1], in the even lanes.
    let a = _mm256_mul_ps(_mm256_set1_ps(1.0 - wx), g);
    let b = _mm256_mul_ps(_mm256_set1_ps(wx), g);
    let b = _mm256_permute_ps::<0b11_11_11_01>(b);
    let gx = _mm256_add_ps(a, b);
    let mut l = [0.0f32; 8];
    _mm256_storeu_ps(l.as_mut_ptr(), gx);
    let y0 = (1.0 - wy) * l[0] + wy * l[2];
    let y1 = (1.0 - wy) * l[4] + wy * l[6];
    (1.0 - wz) * y0 + wz * y1
}
