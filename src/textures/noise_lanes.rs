//! pbrt-v3's Perlin noise in the lanes of AVX2 vectors, two ways:
//!
//! - [`noise`]: one point, its eight lattice corners in the lanes of one
//!   vector: the corners' hashes are looked up as in
//!   [`super::noise::noise_plain`] (sharing the chain's common steps), then
//!   every corner's offsets and gradient, and the four interpolations along
//!   x, run as lane-wise vector operations.
//! - [`fbm`] and [`turbulence`]: the octaves of a sum, eight points (octave
//!   k's point is `1.99^k · p`) in the lanes, each lane the whole noise of
//!   its point: the lattice cell, the permutation table's hashes (gathers),
//!   the eight corners' gradients one after the other, and the
//!   interpolations. The octaves are independent, so their chains run side
//!   by side instead of one noise after the other; the sum then adds them
//!   in pbrt-v3's order.
//!
//! Each lane performs the plain code's operations on its corner or point in
//! the same order (a negation as a flip of the sign bit, as `-u` is), so the
//! values are the plain code's bit for bit (tested in [`super::noise`]).
//! Points whose coordinates a vector's integer conversion would read
//! differently from Rust's `as i32` (NaN, ±∞, beyond ±2³¹) take the plain
//! noise. Builds without AVX2 use the plain code.

use super::noise::{lerp, noise3, perm, smooth_step, weight};
use glam::Vec3;

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

/// Octave k's frequency `1.99^k` as `fbm`'s loop makes it (one product
/// after the other, from 1), for the most octaves a texture sums
/// ([`super::noise::MAX_OCTAVES`]) and its partial octave, with room for a
/// last vector's unused lanes.
static LAMBDA: [f32; LAMBDAS] = {
    let mut t = [0.0f32; LAMBDAS];
    let mut lambda = 1.0f32;
    let mut k = 0;
    while k < LAMBDAS {
        t[k] = lambda;
        lambda *= 1.99;
        k += 1;
    }
    t
};
const LAMBDAS: usize = SUMMED + 7;
/// The most octaves a sum reads: [`super::noise::MAX_OCTAVES`] and the
/// partial one.
const SUMMED: usize = super::noise::MAX_OCTAVES as usize + 1;

/// The noise of octaves `first..first + 8` of `p` (octave k at
/// `LAMBDA[k] · p`) into `out`, those from `first + live` on left as they
/// are.
#[inline]
fn octave_noises(p: Vec3, first: usize, live: usize, out: &mut [f32; 8]) {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        // SAFETY: AVX2 is enabled at compile time; `first + 8 <= LAMBDAS`
        // (the callers' octaves are at most MAX_OCTAVES + 1).
        if unsafe { octave_noises_avx2(p, first, live, out) } {
            return;
        }
    }
    for (k, o) in out[..live].iter_mut().enumerate() {
        *o = noise3(LAMBDA[first + k] * p);
    }
}

/// [`super::noise::fbm`]'s sum for `n` octaves, `n_int` of them whole.
/// (This loop and [`turbulence`]'s are written out in each: one loop
/// shared through a closure took 1.05 of the time on rs_pbrt's `fbm`.)
#[inline]
pub fn fbm(p: Vec3, omega: f32, n: f32, n_int: i32) -> f32 {
    let whole = n_int.max(0) as usize;
    if whole + 1 > SUMMED {
        return super::noise::fbm_sum(p, omega, n, n_int);
    }
    let (mut sum, mut o) = (0.0f32, 1.0f32);
    let mut values = [0.0f32; 8];
    let mut first = 0;
    while first <= whole {
        let live = (whole + 1 - first).min(8);
        octave_noises(p, first, live, &mut values);
        for (k, &v) in (first..).zip(&values[..live]) {
            if k < whole {
                sum += o * v;
                o *= omega;
            } else {
                let partial = n - n_int as f32;
                sum += o * smooth_step(0.3, 0.7, partial) * v;
            }
        }
        first += 8;
    }
    sum
}

/// [`super::noise::turbulence`]'s sum for `n` octaves, `n_int` of them
/// whole, of at most `max_octaves`.
#[inline]
pub fn turbulence(p: Vec3, omega: f32, n: f32, n_int: i32, max_octaves: i32) -> f32 {
    let whole = n_int.max(0) as usize;
    if whole + 1 > SUMMED {
        return super::noise::turbulence_sum(p, omega, n, n_int, max_octaves);
    }
    let (mut sum, mut o) = (0.0f32, 1.0f32);
    let mut values = [0.0f32; 8];
    let mut first = 0;
    while first <= whole {
        let live = (whole + 1 - first).min(8);
        octave_noises(p, first, live, &mut values);
        for (k, &v) in (first..).zip(&values[..live]) {
            if k < whole {
                sum += o * v.abs();
                o *= omega;
            } else {
                let partial = n - n_int as f32;
                sum += o * lerp(smooth_step(0.3, 0.7, partial), 0.2, v.abs());
            }
        }
        first += 8;
    }
    for _ in n_int..max_octaves {
        sum += o * 0.2;
        o *= omega;
    }
    sum
}

/// Pbrt-v3's permutation as 32-bit entries, for gathers.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
static PERM32: [i32; 256] = {
    let mut t = [0i32; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = super::noise::PERM[i] as i32;
        i += 1;
    }
    t
};

/// [`octave_noises`] in lanes; false (nothing written) if a live lane's
/// point has a coordinate that is NaN or outside [−2³¹, 2³¹), where the
/// vector conversion to an integer differs from `as i32`.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline]
unsafe fn octave_noises_avx2(p: Vec3, first: usize, live: usize, out: &mut [f32; 8]) -> bool {
    use std::arch::x86_64::*;
    // Unused lanes at the origin, so that they cannot fail the range test.
    const LIVE: [i32; 16] = [-1, -1, -1, -1, -1, -1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0];
    let mask = _mm256_loadu_si256(LIVE.as_ptr().add(8 - live) as *const __m256i);
    let lambda = _mm256_and_ps(
        _mm256_loadu_ps(LAMBDA.as_ptr().add(first)),
        _mm256_castsi256_ps(mask),
    );
    let x = _mm256_mul_ps(lambda, _mm256_set1_ps(p.x));
    let y = _mm256_mul_ps(lambda, _mm256_set1_ps(p.y));
    let z = _mm256_mul_ps(lambda, _mm256_set1_ps(p.z));
    let (lo, hi) = (_mm256_set1_ps(-2147483648.0), _mm256_set1_ps(2147483648.0));
    let in_range = |v: __m256| {
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(v, lo),
            _mm256_cmp_ps::<_CMP_LT_OQ>(v, hi),
        )
    };
    let ok = _mm256_and_ps(in_range(x), _mm256_and_ps(in_range(y), in_range(z)));
    if _mm256_movemask_ps(ok) != 0xff {
        return false;
    }
    _mm256_storeu_ps(out.as_mut_ptr(), noise8(x, y, z));
    true
}

/// pbrt-v3's `Noise` of eight points (lanes), each lane
/// [`super::noise::noise_plain`]'s operations on its point; every
/// coordinate in [−2³¹, 2³¹).
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline]
unsafe fn noise8(
    x: std::arch::x86_64::__m256,
    y: std::arch::x86_64::__m256,
    z: std::arch::x86_64::__m256,
) -> std::arch::x86_64::__m256 {
    use std::arch::x86_64::*;
    // floor as i32, and the offset in the cell `v − (floor as f32)`.
    let cell = |v: __m256| {
        let i = _mm256_cvttps_epi32(_mm256_floor_ps(v));
        (i, _mm256_sub_ps(v, _mm256_cvtepi32_ps(i)))
    };
    let (ix, dx) = cell(x);
    let (iy, dy) = cell(y);
    let (iz, dz) = cell(z);
    let m255 = _mm256_set1_epi32(255);
    let one_i = _mm256_set1_epi32(1);
    let (ix, iy, iz) = (
        _mm256_and_si256(ix, m255),
        _mm256_and_si256(iy, m255),
        _mm256_and_si256(iz, m255),
    );
    let perm = |i: __m256i| _mm256_i32gather_epi32::<4>(PERM32.as_ptr(), _mm256_and_si256(i, m255));
    let add = |a: __m256i, b: __m256i| _mm256_add_epi32(a, b);
    let px0 = perm(ix);
    let px1 = perm(add(ix, one_i));
    let (a0, a1) = (add(px0, iy), add(px1, iy));
    let p00 = perm(a0);
    let p10 = perm(a1);
    let p01 = perm(add(a0, one_i));
    let p11 = perm(add(a1, one_i));
    let iz1 = add(iz, one_i);
    let m15 = _mm256_set1_epi32(15);
    let hash = |pxy: __m256i, z: __m256i| _mm256_and_si256(perm(add(pxy, z)), m15);
    // The corners' offsets: d or d − 1 per axis.
    let one = _mm256_set1_ps(1.0);
    let (dx1, dy1, dz1) = (
        _mm256_sub_ps(dx, one),
        _mm256_sub_ps(dy, one),
        _mm256_sub_ps(dz, one),
    );
    // pbrt-v3's `Grad`: u is the x offset for h < 8, 12 and 13, else y; v
    // is y for h < 4, 12 and 13, else z; bits 0 and 1 negate them.
    let grad = |h: __m256i, gx: __m256, gy: __m256, gz: __m256| {
        let eq = |k: i32| _mm256_cmpeq_epi32(h, _mm256_set1_epi32(k));
        let below = |k: i32| _mm256_cmpgt_epi32(_mm256_set1_epi32(k), h);
        let twelve_thirteen = _mm256_or_si256(eq(12), eq(13));
        let use_x = _mm256_castsi256_ps(_mm256_or_si256(below(8), twelve_thirteen));
        let use_y = _mm256_castsi256_ps(_mm256_or_si256(below(4), twelve_thirteen));
        let u = _mm256_blendv_ps(gy, gx, use_x);
        let v = _mm256_blendv_ps(gz, gy, use_y);
        let sign_u = _mm256_castsi256_ps(_mm256_slli_epi32::<31>(_mm256_and_si256(h, one_i)));
        let sign_v = _mm256_castsi256_ps(_mm256_slli_epi32::<30>(_mm256_and_si256(
            h,
            _mm256_set1_epi32(2),
        )));
        _mm256_add_ps(_mm256_xor_ps(u, sign_u), _mm256_xor_ps(v, sign_v))
    };
    let w000 = grad(hash(p00, iz), dx, dy, dz);
    let w100 = grad(hash(p10, iz), dx1, dy, dz);
    let w010 = grad(hash(p01, iz), dx, dy1, dz);
    let w110 = grad(hash(p11, iz), dx1, dy1, dz);
    let w001 = grad(hash(p00, iz1), dx, dy, dz1);
    let w101 = grad(hash(p10, iz1), dx1, dy, dz1);
    let w011 = grad(hash(p01, iz1), dx, dy1, dz1);
    let w111 = grad(hash(p11, iz1), dx1, dy1, dz1);
    // The quintic fade 6t⁵ − 15t⁴ + 10t³, as `weight`.
    let fade = |t: __m256| {
        let t3 = _mm256_mul_ps(_mm256_mul_ps(t, t), t);
        let t4 = _mm256_mul_ps(t3, t);
        _mm256_add_ps(
            _mm256_sub_ps(
                _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(6.0), t4), t),
                _mm256_mul_ps(_mm256_set1_ps(15.0), t4),
            ),
            _mm256_mul_ps(_mm256_set1_ps(10.0), t3),
        )
    };
    let (wx, wy, wz) = (fade(dx), fade(dy), fade(dz));
    // (1 − t)·a + t·b, as `lerp`.
    let lerp8 = |t: __m256, a: __m256, b: __m256| {
        _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(one, t), a), _mm256_mul_ps(t, b))
    };
    let x00 = lerp8(wx, w000, w100);
    let x10 = lerp8(wx, w010, w110);
    let x01 = lerp8(wx, w001, w101);
    let x11 = lerp8(wx, w011, w111);
    let y0 = lerp8(wy, x00, x10);
    let y1 = lerp8(wy, x01, x11);
    lerp8(wz, y0, y1)
}
