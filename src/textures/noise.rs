//! pbrt-v3's Perlin noise and its sums (core/texture.cpp): `noise`, `fbm`
//! (fractional Brownian motion) and `turbulence`, with the number of octaves
//! limited by the screen-space footprint (antialiasing).
//!
//! All in `f32` in pbrt-v3's operation order, so the values are pbrt-v3's
//! bit for bit (given the same point and `log`/`floor`).

use glam::Vec3;

/// Ken Perlin's permutation of 0..255, as pbrt-v3's `NoisePerm` (which
/// stores it twice; pbrs indexes it modulo 256 instead). Data from
/// mmp/pbrt-v3 @13d871f, src/core/texture.cpp.
#[rustfmt::skip]
pub(super) const PERM: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225,
    140, 36, 103, 30, 69, 142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148,
    247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32,
    57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122,
    60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54,
    65, 25, 63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169,
    200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186, 3, 64,
    52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212,
    207, 206, 59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213,
    119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9,
    129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104,
    218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162, 241,
    81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157,
    184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93,
    222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180,
];

#[inline(always)]
pub(super) fn perm(i: i32) -> i32 {
    PERM[(i & 255) as usize] as i32
}

#[inline(always)]
fn grad(x: i32, y: i32, z: i32, dx: f32, dy: f32, dz: f32) -> f32 {
    let h = perm(perm(perm(x) + y) + z) & 15;
    let u = if h < 8 || h == 12 || h == 13 { dx } else { dy };
    let v = if h < 4 || h == 12 || h == 13 { dy } else { dz };
    (if h & 1 != 0 { -u } else { u }) + (if h & 2 != 0 { -v } else { v })
}

/// The quintic fade 6t⁵ − 15t⁴ + 10t³.
#[inline(always)]
pub(super) fn weight(t: f32) -> f32 {
    let t3 = t * t * t;
    let t4 = t3 * t;
    6.0 * t4 * t - 15.0 * t4 + 10.0 * t3
}

#[inline(always)]
pub(super) fn lerp(t: f32, a: f32, b: f32) -> f32 {
    (1.0 - t) * a + t * b
}

/// pbrt-v3's `Noise(x, y, z)`: gradient noise in [−1, 1], zero at integer
/// lattice points. Computed with the corners in lanes
/// ([`super::noise_lanes`]), bit for bit [`noise_plain`].
#[inline]
pub fn noise(x: f32, y: f32, z: f32) -> f32 {
    super::noise_lanes::noise(x, y, z)
}

/// pbrt-v3's `Noise` corner by corner, as written there (the reference of
/// [`noise`]).
pub fn noise_plain(x: f32, y: f32, z: f32) -> f32 {
    // C++'s float-to-int conversion; out-of-range values (|x| ≥ 2³¹) give
    // meaningless noise in both.
    let (ix, iy, iz) = (x.floor() as i32, y.floor() as i32, z.floor() as i32);
    let (dx, dy, dz) = (x - ix as f32, y - iy as f32, z - iz as f32);
    let (ix, iy, iz) = (ix & 255, iy & 255, iz & 255);
    let w000 = grad(ix, iy, iz, dx, dy, dz);
    let w100 = grad(ix + 1, iy, iz, dx - 1.0, dy, dz);
    let w010 = grad(ix, iy + 1, iz, dx, dy - 1.0, dz);
    let w110 = grad(ix + 1, iy + 1, iz, dx - 1.0, dy - 1.0, dz);
    let w001 = grad(ix, iy, iz + 1, dx, dy, dz - 1.0);
    let w101 = grad(ix + 1, iy, iz + 1, dx - 1.0, dy, dz - 1.0);
    let w011 = grad(ix, iy + 1, iz + 1, dx, dy - 1.0, dz - 1.0);
    let w111 = grad(ix + 1, iy + 1, iz + 1, dx - 1.0, dy - 1.0, dz - 1.0);
    let (wx, wy, wz) = (weight(dx), weight(dy), weight(dz));
    let x00 = lerp(wx, w000, w100);
    let x10 = lerp(wx, w010, w110);
    let x01 = lerp(wx, w001, w101);
    let x11 = lerp(wx, w011, w111);
    let y0 = lerp(wy, x00, x10);
    let y1 = lerp(wy, x01, x11);
    lerp(wz, y0, y1)
}

#[inline]
pub fn noise3(p: Vec3) -> f32 {
    noise(p.x, p.y, p.z)
}

/// pbrt-v3's `Log2`: `ln(x) · (1/ln 2)` in `f32`.
#[inline]
pub fn log2(x: f32) -> f32 {
    // pbrt-v3's invLog2 rounds to the same f32 as LOG2_E.
    x.ln() * std::f32::consts::LOG2_E
}

/// pbrt-v3's `SmoothStep`.
#[inline]
pub fn smooth_step(min: f32, max: f32, value: f32) -> f32 {
    let v = clamp((value - min) / (max - min), 0.0, 1.0);
    v * v * (-2.0 * v + 3.0)
}

/// pbrt-v3's `Clamp`: NaN passes through.
#[inline]
pub fn clamp(v: f32, lo: f32, hi: f32) -> f32 {
    if v < lo {
        lo
    } else if v > hi {
        hi
    } else {
        v
    }
}

/// The octave count for a footprint (both sums): `clamp(−1 − ½·log₂(len²),
/// 0, max)`, all of them when there are no differentials.
#[inline]
fn octaves(dpdx: Vec3, dpdy: Vec3, max_octaves: i32) -> (f32, i32) {
    let (a, b) = (dpdx.length_squared(), dpdy.length_squared());
    // std::max(a, b).
    let len2 = if a < b { b } else { a };
    let n = clamp(-1.0 - 0.5 * log2(len2), 0.0, max_octaves as f32);
    (n, n.floor() as i32)
}

/// pbrt-v3's `FBm`: octaves of noise with frequency ×1.99 and amplitude
/// ×`omega` each, the last one faded in. The octaves' noise values are
/// computed eight at a time ([`super::noise_lanes`]), bit for bit
/// [`fbm_plain`]'s.
#[inline]
pub fn fbm(p: Vec3, dpdx: Vec3, dpdy: Vec3, omega: f32, max_octaves: i32) -> f32 {
    let (n, n_int) = octaves(dpdx, dpdy, max_octaves);
    super::noise_lanes::fbm(p, omega, n, n_int)
}

/// [`fbm`] octave by octave, as pbrt-v3 writes it (the reference).
pub fn fbm_plain(p: Vec3, dpdx: Vec3, dpdy: Vec3, omega: f32, max_octaves: i32) -> f32 {
    let (n, n_int) = octaves(dpdx, dpdy, max_octaves);
    fbm_sum(p, omega, n, n_int)
}

/// `fbm`'s sum for `n` octaves (`n_int` whole ones), octave by octave.
pub(super) fn fbm_sum(p: Vec3, omega: f32, n: f32, n_int: i32) -> f32 {
    let (mut sum, mut lambda, mut o) = (0.0f32, 1.0f32, 1.0f32);
    for _ in 0..n_int {
        sum += o * noise3(lambda * p);
        lambda *= 1.99;
        o *= omega;
    }
    let partial = n - n_int as f32;
    sum += o * smooth_step(0.3, 0.7, partial) * noise3(lambda * p);
    sum
}

/// pbrt-v3's `Turbulence`: as [`fbm`] with |noise|, the clamped octaves
/// replaced by their average 0.2 (pbrt-v3 does not advance the amplitude
/// after the partial octave; neither does pbrs). The noise values are
/// computed eight at a time, bit for bit [`turbulence_plain`]'s.
#[inline]
pub fn turbulence(p: Vec3, dpdx: Vec3, dpdy: Vec3, omega: f32, max_octaves: i32) -> f32 {
    let (n, n_int) = octaves(dpdx, dpdy, max_octaves);
    super::noise_lanes::turbulence(p, omega, n, n_int, max_octaves)
}

/// [`turbulence`] octave by octave, as pbrt-v3 writes it (the reference).
pub fn turbulence_plain(p: Vec3, dpdx: Vec3, dpdy: Vec3, omega: f32, max_octaves: i32) -> f32 {
    let (n, n_int) = octaves(dpdx, dpdy, max_octaves);
    turbulence_sum(p, omega, n, n_int, max_octaves)
}

/// `turbulence`'s sum for `n` octaves (`n_int` whole ones) of at most
/// `max_octaves`, octave by octave.
pub(super) fn turbulence_sum(p: Vec3, omega: f32, n: f32, n_int: i32, max_octaves: i32) -> f32 {
    let (mut sum, mut lambda, mut o) = (0.0f32, 1.0f32, 1.0f32);
    for _ in 0..n_int {
        sum += o * noise3(lambda * p).abs();
        lambda *= 1.99;
        o *= omega;
    }
    let partial = n - n_int as f32;
    sum += o * lerp(
        smooth_step(0.3, 0.7, partial),
        0.2,
        noise3(lambda * p).abs(),
    );
    for _ in n_int..max_octaves {
        sum += o * 0.2;
        o *= omega;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_vanishes_on_the_lattice_and_is_bounded() {
        for (x, y, z) in [(0.0, 0.0, 0.0), (3.0, -7.0, 12.0), (255.0, 256.0, -1.0)] {
            assert_eq!(noise(x, y, z), 0.0);
        }
        let mut max = 0.0f32;
        for i in 0..2000 {
            let f = i as f32 * 0.137;
            let v = noise(f, 0.5 * f + 0.3, 1.7 - f);
            assert!(v.abs() <= 1.0, "{v}");
            max = max.max(v.abs());
        }
        assert!(max > 0.3, "noise is nearly flat: {max}");
    }

    /// The lanes' noise is the plain code's bit for bit: inside cells, on
    /// the lattice, at negative and huge coordinates (the lattice index
    /// wraps at 256), and NaN for NaN.
    #[test]
    fn lanes_equal_the_plain_noise() {
        let mut rng = crate::sampling::rng::Pcg32::with_sequence(3);
        let check = |x: f32, y: f32, z: f32| {
            let (a, b) = (noise(x, y, z), noise_plain(x, y, z));
            assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "({x}, {y}, {z}): {a} against {b}"
            );
        };
        for k in 0..200_000 {
            let scale = [1.0, 10.0, 300.0, 1e6, 1e10][k % 5];
            let mut c = || (rng.uniform_f32() - 0.5) * 2.0 * scale;
            let (x, y, z) = (c(), c(), c());
            check(x, y, z);
            check(x.floor(), y, z.floor());
        }
        for v in [0.0, -0.0, 255.5, 256.0, -1e-30, f32::NAN, f32::INFINITY] {
            check(v, 0.25, -v);
        }
    }

    /// The sums with their octaves' noise in lanes are the octave-by-octave
    /// sums bit for bit: footprints from none (every octave) to wider than
    /// the texture (no whole octave), octave limits from −2 to 128 (several
    /// vectors of octaves, the partial octave in each lane position), points
    /// near the origin, far out (some octaves' points past 2³¹, which the
    /// lanes leave to the plain noise), on the lattice, ±∞ and NaN.
    #[test]
    fn octave_lanes_equal_the_plain_sums() {
        let mut rng = crate::sampling::rng::Pcg32::with_sequence(11);
        let same = |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        let mut counts = [0u32; 3];
        for k in 0..120_000 {
            let scale = [1.0, 10.0, 300.0, 1e6, 1e9][k % 5];
            let mut c = || (rng.uniform_f32() - 0.5) * 2.0 * scale;
            let mut p = Vec3::new(c(), c(), c());
            match k % 97 {
                0 => p = p.floor(),
                1 => p.y = f32::NAN,
                2 => p.x = f32::INFINITY,
                3 => p = Vec3::ZERO,
                _ => {}
            }
            // Footprint lengths 2^-40 .. 2^4, or none.
            let e = rng.uniform_f32() * 44.0 - 40.0;
            let len = if k % 11 == 0 { 0.0 } else { e.exp2() };
            let dpdx = Vec3::new(len, 0.0, 0.0);
            let dpdy = Vec3::new(0.0, 0.5 * len, 0.0);
            let max_octaves = [8, 3, 6, 16, 1, 0, -2, 9, 17, 40, 128][k % 11];
            let omega = [0.5, 0.75, 1.0, 0.1, 1.7][k % 5];
            let (n, n_int) = octaves(dpdx, dpdy, max_octaves);
            counts[(n_int.max(0) as usize / 8).min(2)] += 1;
            let (a, b) = (
                fbm(p, dpdx, dpdy, omega, max_octaves),
                fbm_plain(p, dpdx, dpdy, omega, max_octaves),
            );
            assert!(
                same(a, b),
                "fbm {p} {len} {max_octaves} {omega} ({n}): {a} against {b}"
            );
            let (a, b) = (
                turbulence(p, dpdx, dpdy, omega, max_octaves),
                turbulence_plain(p, dpdx, dpdy, omega, max_octaves),
            );
            assert!(
                same(a, b),
                "turbulence {p} {len} {max_octaves} {omega} ({n}): {a} against {b}"
            );
        }
        // Sums of one vector of octaves, of two, and of more.
        assert!(counts.iter().all(|&c| c > 1000), "{counts:?}");
    }
}

/// The most octaves `fbm`, `wrinkled` and `marble` sum (a larger
/// `octaves` is clamped, with the loader's warning): octave k has
/// frequency 1.99^k, which overflows a float past 128.
pub const MAX_OCTAVES: i32 = 128;

/// What `fbm` and `wrinkled` share: the 3D mapping, the most octaves, and
/// the amplitude factor per octave (their parameters, [`OCTAVE_PARAMS`]).
#[derive(Clone, Copy, Debug)]
pub struct Octaves {
    pub mapping: super::Mapping3D,
    pub octaves: i32,
    pub omega: f32,
}

/// The parameter table of `fbm` and `wrinkled`.
pub const OCTAVE_PARAMS: &[crate::scene::ParamSpec] = &[
    crate::scene::ParamSpec::int(
        "octaves",
        8,
        "most octaves (fewer where the footprint is large)",
    ),
    crate::scene::ParamSpec::float("roughness", 0.5, "amplitude factor per octave (ω)"),
];

impl Octaves {
    pub fn read(b: &super::TexBuilder) -> Octaves {
        Octaves {
            mapping: b.mapping3d,
            octaves: b.params.int("octaves").min(MAX_OCTAVES),
            omega: b.params.float("roughness"),
        }
    }

    /// `sum(p, dp/dx, dp/dy, ω, octaves)` at the mapped point.
    #[inline]
    pub fn eval(
        &self,
        sc: &crate::materials::ShadingContext,
        sum: impl Fn(Vec3, Vec3, Vec3, f32, i32) -> f32,
    ) -> f32 {
        let (p, dpdx, dpdy) = self.mapping.map(sc);
        sum(p, dpdx, dpdy, self.omega, self.octaves)
    }
}
