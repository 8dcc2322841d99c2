//! pbrt-v3's MIP map (core/mipmap.h): an image pyramid with trilinear and
//! EWA (elliptically weighted average) filtering.
//!
//! Construction as pbrt-v3: an image whose sides are not powers of two is
//! first resampled up to the next powers of two, separably, with four-tap
//! Lanczos (τ = 2) weights normalised per texel, honouring the wrap mode,
//! and clamped to non-negative values after the second pass; each coarser
//! level is the box average of 2×2 texels of the finer one (read through
//! the wrap mode, so a side of 1 averages with its wrapped neighbour),
//! down to 1×1.
//!
//! Lookups: `trilinear` blends the bilinear lookups of the two levels
//! around log₂ of the widest differential; EWA filters an ellipse spanned
//! by the differentials (its eccentricity limited by `maxanisotropy`) with
//! pbrt-v3's 128-entry Gaussian weight table, at the level of the minor
//! axis and the next coarser one. Without differentials both reduce to a
//! bilinear lookup at the finest level.

use super::noise::log2;
use super::{lerp, TexValue};
use glam::Vec2;
use std::f32::consts::PI;
use std::sync::OnceLock;

/// Texel addressing outside the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Wrap {
    Repeat,
    Black,
    Clamp,
}

pub(super) const WEIGHT_LUT_SIZE: usize = 128;

/// pbrt-v3's EWA weights: exp(−2r²) − exp(−2) at r² = i/127.
pub fn ewa_weights() -> &'static [f32; WEIGHT_LUT_SIZE] {
    static LUT: OnceLock<[f32; WEIGHT_LUT_SIZE]> = OnceLock::new();
    LUT.get_or_init(|| {
        let mut w = [0.0f32; WEIGHT_LUT_SIZE];
        for (i, w) in w.iter_mut().enumerate() {
            let alpha = 2.0f32;
            let r2 = i as f32 / (WEIGHT_LUT_SIZE - 1) as f32;
            *w = (-alpha * r2).exp() - (-alpha).exp();
        }
        w
    })
}

/// Most texels a MIP map's finest level may have after resampling to powers
/// of two (a bound on memory; pbrt-v3 has none): the image reader's bound,
/// 2²⁷ (1.5 GiB of RGB, 2 GiB with the coarser levels).
pub const MAX_TEXELS: usize = 1 << 27;

/// One level of the pyramid; its sides are powers of two.
pub(super) struct Level<T> {
    pub(super) w: i32,
    pub(super) h: i32,
    pub(super) texels: Vec<T>,
}

/// A MIP map of values `T`.
pub struct MipMap<T> {
    levels: Vec<Level<T>>,
    trilinear: bool,
    max_anisotropy: f32,
    wrap: Wrap,
    weights: &'static [f32; WEIGHT_LUT_SIZE],
}

/// pbrt-v3's `Lanczos(x, τ)` windowed sinc.
pub fn lanczos(x: f32, tau: f32) -> f32 {
    let mut x = x.abs();
    if x < 1e-5 {
        return 1.0;
    }
    if x > 1.0 {
        return 0.0;
    }
    x *= PI;
    let s = (x * tau).sin() / (x * tau);
    let l = x.sin() / x;
    s * l
}

/// One output texel's resampling taps.
#[derive(Clone, Copy, Debug)]
pub struct ResampleWeight {
    pub first: i32,
    pub weight: [f32; 4],
}

/// pbrt-v3's `resampleWeights` from `old` texels to `new` (≥ old).
pub fn resample_weights(old: i32, new: i32) -> Vec<ResampleWeight> {
    let filter_width = 2.0f32;
    (0..new)
        .map(|i| {
            let center = (i as f32 + 0.5) * old as f32 / new as f32;
            let first = ((center - filter_width) + 0.5).floor() as i32;
            let mut weight = [0.0f32; 4];
            for (j, w) in weight.iter_mut().enumerate() {
                let pos = (first + j as i32) as f32 + 0.5;
                *w = lanczos((pos - center) / filter_width, 2.0);
            }
            let inv = 1.0 / (weight[0] + weight[1] + weight[2] + weight[3]);
            for w in &mut weight {
                *w *= inv;
            }
            ResampleWeight { first, weight }
        })
        .collect()
}

/// pbrt-v3's `Mod` for integers (non-negative result).
#[inline(always)]
fn wrap_mod(a: i32, b: i32) -> i32 {
    a.rem_euclid(b)
}

/// The tap index after the wrap mode, `None` outside the image.
#[inline(always)]
fn wrap_index(i: i32, n: i32, wrap: Wrap) -> Option<i32> {
    let i = match wrap {
        Wrap::Repeat => wrap_mod(i, n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Black => i,
    };
    (0..n).contains(&i).then_some(i)
}

/// 2^⌈log₂ v⌉ for v ≥ 1.
fn round_up_pow2(v: i32) -> i32 {
    (v as u32).next_power_of_two() as i32
}

/// pbrt-v3's EWA footprint on a level: the texel-space centre, the
/// ellipse's coefficients (r² = a·s² + b·s·t + c·t²) and the bounding box of
/// texels to scan (`s0..=s1`, `t0..=t1`, as floats before the area check).
pub(super) struct Ellipse {
    pub(super) st: Vec2,
    pub(super) a: f32,
    pub(super) b: f32,
    pub(super) c: f32,
    s0: f32,
    s1: f32,
    t0: f32,
    t1: f32,
}

impl Ellipse {
    fn new<T>(l: &Level<T>, st: Vec2, dst0: Vec2, dst1: Vec2) -> Ellipse {
        let (w, h) = (l.w as f32, l.h as f32);
        let st = Vec2::new(st.x * w - 0.5, st.y * h - 0.5);
        let d0 = Vec2::new(dst0.x * w, dst0.y * h);
        let d1 = Vec2::new(dst1.x * w, dst1.y * h);
        let mut a = d0.y * d0.y + d1.y * d1.y + 1.0;
        let mut b = -2.0 * (d0.x * d0.y + d1.x * d1.y);
        let mut c = d0.x * d0.x + d1.x * d1.x + 1.0;
        let inv_f = 1.0 / (a * c - b * b * 0.25);
        a *= inv_f;
        b *= inv_f;
        c *= inv_f;
        let det = -b * b + 4.0 * a * c;
        let inv_det = 1.0 / det;
        let u_sqrt = (det * c).sqrt();
        let v_sqrt = (a * det).sqrt();
        Ellipse {
            st,
            a,
            b,
            c,
            s0: (st.x - 2.0 * inv_det * u_sqrt).ceil(),
            s1: (st.x + 2.0 * inv_det * u_sqrt).floor(),
            t0: (st.y - 2.0 * inv_det * v_sqrt).ceil(),
            t1: (st.y + 2.0 * inv_det * v_sqrt).floor(),
        }
    }
}

impl<T: TexValue> MipMap<T> {
    /// Builds the pyramid of a `w`×`h` image (row `t` = 0 at the bottom, as
    /// texture space has it). `None` if the image is empty or its
    /// power-of-two size exceeds [`MAX_TEXELS`].
    pub fn new(
        w: usize,
        h: usize,
        texels: Vec<T>,
        trilinear: bool,
        max_anisotropy: f32,
        wrap: Wrap,
    ) -> Option<MipMap<T>> {
        if w == 0 || h == 0 || texels.len() != w * h || w > 1 << 30 || h > 1 << 30 {
            return None;
        }
        let (w, h) = (w as i32, h as i32);
        let (pw, ph) = (round_up_pow2(w), round_up_pow2(h));
        if (pw as usize).checked_mul(ph as usize)? > MAX_TEXELS {
            return None;
        }
        let base = if (pw, ph) != (w, h) {
            resample(w, h, &texels, pw, ph, wrap)
        } else {
            texels
        };
        let mut levels = vec![Level {
            w: pw,
            h: ph,
            texels: base,
        }];
        let n_levels = 1 + (pw.max(ph) as u32).ilog2() as usize;
        let mut mip = MipMap {
            levels: Vec::new(),
            trilinear,
            max_anisotropy,
            wrap,
            weights: ewa_weights(),
        };
        for _ in 1..n_levels {
            let prev = levels.last().expect("level 0");
            let (sw, th) = ((prev.w / 2).max(1), (prev.h / 2).max(1));
            let mut next = Vec::with_capacity((sw * th) as usize);
            for t in 0..th {
                for s in 0..sw {
                    let a = texel_of(prev, 2 * s, 2 * t, wrap);
                    let b = texel_of(prev, 2 * s + 1, 2 * t, wrap);
                    let c = texel_of(prev, 2 * s, 2 * t + 1, wrap);
                    let d = texel_of(prev, 2 * s + 1, 2 * t + 1, wrap);
                    next.push(a.add(b).add(c).add(d).scale(0.25));
                }
            }
            levels.push(Level {
                w: sw,
                h: th,
                texels: next,
            });
        }
        mip.levels = levels;
        Some(mip)
    }

    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Width and height of a level.
    pub fn level_size(&self, level: usize) -> (usize, usize) {
        let l = &self.levels[level];
        (l.w as usize, l.h as usize)
    }

    /// A texel with the wrap mode applied (pbrt-v3's `Texel`).
    #[inline]
    pub fn texel(&self, level: usize, s: i32, t: i32) -> T {
        texel_of(&self.levels[level], s, t, self.wrap)
    }

    /// Bilinear interpolation at `st` on one level (pbrt-v3's `triangle`).
    pub fn bilerp(&self, level: usize, st: Vec2) -> T {
        let level = level.min(self.levels.len() - 1);
        let l = &self.levels[level];
        let s = st.x * l.w as f32 - 0.5;
        let t = st.y * l.h as f32 - 0.5;
        let (s0, t0) = (s.floor() as i32, t.floor() as i32);
        let (ds, dt) = (s - s0 as f32, t - t0 as f32);
        if s0 >= 0 && s0 < l.w - 1 && t0 >= 0 && t0 < l.h - 1 {
            // All four texels inside: every wrap mode leaves them as they are.
            let i = (t0 * l.w + s0) as usize;
            let row = l.w as usize;
            let tx = &l.texels;
            return tx[i]
                .scale((1.0 - ds) * (1.0 - dt))
                .add(tx[i + row].scale((1.0 - ds) * dt))
                .add(tx[i + 1].scale(ds * (1.0 - dt)))
                .add(tx[i + row + 1].scale(ds * dt));
        }
        let w = self.wrap;
        texel_of(l, s0, t0, w)
            .scale((1.0 - ds) * (1.0 - dt))
            .add(texel_of(l, s0, t0.wrapping_add(1), w).scale((1.0 - ds) * dt))
            .add(texel_of(l, s0.wrapping_add(1), t0, w).scale(ds * (1.0 - dt)))
            .add(texel_of(l, s0.wrapping_add(1), t0.wrapping_add(1), w).scale(ds * dt))
    }

    /// pbrt-v3's trilinear `Lookup(st, width)`.
    pub fn lookup_width(&self, st: Vec2, width: f32) -> T {
        let n = self.levels.len();
        let level = (n - 1) as f32 + log2(max(width, 1e-8));
        if level < 0.0 {
            self.bilerp(0, st)
        } else if level >= (n - 1) as f32 || level.is_nan() {
            // (A NaN width: pbrt-v3 converts NaN to an integer level here.)
            self.texel(n - 1, 0, 0)
        } else {
            let i = level.floor();
            let delta = level - i;
            let i = (i as usize).min(n - 2);
            lerp(delta, self.bilerp(i, st), self.bilerp(i + 1, st))
        }
    }

    /// pbrt-v3's `Lookup(st, dst0, dst1)`: trilinear or EWA by the map's
    /// setting.
    pub fn lookup(&self, st: Vec2, dst0: Vec2, dst1: Vec2) -> T {
        if self.trilinear {
            let width = max(
                max(dst0.x.abs(), dst0.y.abs()),
                max(dst1.x.abs(), dst1.y.abs()),
            );
            return self.lookup_width(st, width);
        }
        let (mut dst0, mut dst1) = (dst0, dst1);
        if dst0.length_squared() < dst1.length_squared() {
            std::mem::swap(&mut dst0, &mut dst1);
        }
        let major = dst0.length();
        let mut minor = dst1.length();
        if minor * self.max_anisotropy < major && minor > 0.0 {
            let scale = major / (minor * self.max_anisotropy);
            dst1 *= scale;
            minor *= scale;
        }
        if minor == 0.0 {
            return self.bilerp(0, st);
        }
        let lod = max(0.0, (self.levels.len() - 1) as f32 + log2(minor));
        if !lod.is_finite() {
            return self.texel(self.levels.len() - 1, 0, 0);
        }
        let ilod = lod.floor();
        let i = ilod as usize;
        lerp(
            lod - ilod,
            self.ewa(i, st, dst0, dst1),
            self.ewa(i + 1, st, dst0, dst1),
        )
    }

    /// pbrt-v3's `EWA` on one level.
    fn ewa(&self, level: usize, st: Vec2, dst0: Vec2, dst1: Vec2) -> T {
        if level >= self.levels.len() {
            return self.texel(self.levels.len() - 1, 0, 0);
        }
        let l = &self.levels[level];
        let e = Ellipse::new(l, st, dst0, dst1);
        // Non-finite differentials or an absurd `maxanisotropy` would make
        // the scan meaningless or endless: fall back to the bilinear value.
        let area = (e.s1 - e.s0 + 1.0) * (e.t1 - e.t0 + 1.0);
        if !(area.is_finite() && area <= (1 << 22) as f32) {
            return self.bilerp(level, st);
        }
        let (sum, sum_w) = super::ewa_lanes::scan(l, &e, self.weights, self.wrap);
        sum.div(sum_w)
    }
}

impl Ellipse {
    /// The texels to scan: columns `s0..=s1` of rows `t0..=t1`.
    pub(super) fn texel_box(&self) -> (i32, i32, i32, i32) {
        (
            self.s0 as i32,
            self.s1 as i32,
            self.t0 as i32,
            self.t1 as i32,
        )
    }
}

/// EWA's sums over a footprint's texels, one texel at a time: the weighted
/// texels and the weights, each added in the order of the rows and of the
/// texels in a row ([`super::ewa_lanes::scan`] computes the same sums).
#[cfg_attr(all(target_arch = "x86_64", target_feature = "avx2"), allow(dead_code))]
pub(super) fn ewa_scan_plain<T: TexValue>(
    l: &Level<T>,
    e: &Ellipse,
    weights: &[f32; WEIGHT_LUT_SIZE],
    wrap: Wrap,
) -> (T, f32) {
    let &Ellipse { st, a, b, c, .. } = e;
    let (s0, s1, t0, t1) = e.texel_box();
    let mut sum = T::ZERO;
    let mut sum_w = 0.0f32;
    // The texels of one row in turn: for `repeat`, the wrapped column
    // steps along with `is` (no remainder per texel).
    let repeat = wrap == Wrap::Repeat;
    let s_first = if repeat { wrap_mod(s0, l.w) } else { s0 };
    for it in t0..=t1 {
        let tt = it as f32 - st.y;
        // The last term of r², the same for the whole row.
        let ctt = c * tt * tt;
        let row = if repeat { wrap_mod(it, l.h) * l.w } else { 0 };
        let mut sw = s_first;
        for is in s0..=s1 {
            let ss = is as f32 - st.x;
            let r2 = a * ss * ss + b * ss * tt + ctt;
            if r2 < 1.0 {
                let index = ((r2 * WEIGHT_LUT_SIZE as f32) as usize).min(WEIGHT_LUT_SIZE - 1);
                let weight = weights[index];
                let texel = if repeat {
                    l.texels[(row + sw) as usize]
                } else {
                    texel_of(l, is, it, wrap)
                };
                sum = sum.add(texel.scale(weight));
                sum_w += weight;
            }
            if repeat {
                sw += 1;
                if sw == l.w {
                    sw = 0;
                }
            }
        }
    }
    (sum, sum_w)
}

/// std::max(a, b): `b` if `a < b`, else `a`.
#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a < b {
        b
    } else {
        a
    }
}

#[inline(always)]
pub(super) fn texel_of<T: TexValue>(l: &Level<T>, s: i32, t: i32, wrap: Wrap) -> T {
    let (s, t) = match wrap {
        Wrap::Repeat => (wrap_mod(s, l.w), wrap_mod(t, l.h)),
        Wrap::Clamp => (s.clamp(0, l.w - 1), t.clamp(0, l.h - 1)),
        Wrap::Black => {
            if s < 0 || s >= l.w || t < 0 || t >= l.h {
                return T::ZERO;
            }
            (s, t)
        }
    };
    l.texels[(t * l.w + s) as usize]
}

/// Resamples `w`×`h` texels to `pw`×`ph` (powers of two, not smaller), as
/// pbrt-v3: along s, then along t with the result clamped to ≥ 0.
fn resample<T: TexValue>(w: i32, h: i32, img: &[T], pw: i32, ph: i32, wrap: Wrap) -> Vec<T> {
    use rayon::prelude::*;
    let sw = resample_weights(w, pw);
    // Rows 0..h of the s-zoomed image, pw wide.
    let mut zoomed = vec![T::ZERO; (pw * h) as usize];
    zoomed
        .par_chunks_mut(pw as usize)
        .enumerate()
        .for_each(|(t, row)| {
            let src = &img[t * w as usize..(t + 1) * w as usize];
            for (s, out) in row.iter_mut().enumerate() {
                let r = &sw[s];
                let mut acc = T::ZERO;
                for (j, &wt) in r.weight.iter().enumerate() {
                    if let Some(i) = wrap_index(r.first + j as i32, w, wrap) {
                        acc = acc.add(src[i as usize].scale(wt));
                    }
                }
                *out = acc;
            }
        });
    let tw = resample_weights(h, ph);
    let mut out = vec![T::ZERO; (pw * ph) as usize];
    out.par_chunks_mut(pw as usize)
        .enumerate()
        .for_each(|(t, row)| {
            let r = &tw[t];
            for (s, o) in row.iter_mut().enumerate() {
                let mut acc = T::ZERO;
                for (j, &wt) in r.weight.iter().enumerate() {
                    if let Some(i) = wrap_index(r.first + j as i32, h, wrap) {
                        acc = acc.add(zoomed[(i * pw) as usize + s].scale(wt));
                    }
                }
                *o = acc.clamp_non_negative();
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng::Pcg32;
    use glam::Vec3;

    /// pbrt-v3's `EWA` scan as written there: every texel through `Texel`.
    fn ewa_plain<T: TexValue>(m: &MipMap<T>, level: usize, st: Vec2, dst0: Vec2, dst1: Vec2) -> T {
        let l = &m.levels[level];
        let Ellipse {
            st,
            a,
            b,
            c,
            s0,
            s1,
            t0,
            t1,
        } = Ellipse::new(l, st, dst0, dst1);
        let (s0, s1, t0, t1) = (s0 as i32, s1 as i32, t0 as i32, t1 as i32);
        let mut sum = T::ZERO;
        let mut sum_w = 0.0f32;
        for it in t0..=t1 {
            let tt = it as f32 - st.y;
            for is in s0..=s1 {
                let ss = is as f32 - st.x;
                let r2 = a * ss * ss + b * ss * tt + c * tt * tt;
                if r2 < 1.0 {
                    let index = ((r2 * WEIGHT_LUT_SIZE as f32) as usize).min(WEIGHT_LUT_SIZE - 1);
                    let weight = m.weights[index];
                    sum = sum.add(texel_of(l, is, it, m.wrap).scale(weight));
                    sum_w += weight;
                }
            }
        }
        sum.div(sum_w)
    }

    /// pbrt-v3's `triangle` as written there: every texel through `Texel`.
    fn bilerp_plain<T: TexValue>(m: &MipMap<T>, level: usize, st: Vec2) -> T {
        let l = &m.levels[level];
        let s = st.x * l.w as f32 - 0.5;
        let t = st.y * l.h as f32 - 0.5;
        let (s0, t0) = (s.floor() as i32, t.floor() as i32);
        let (ds, dt) = (s - s0 as f32, t - t0 as f32);
        m.texel(level, s0, t0)
            .scale((1.0 - ds) * (1.0 - dt))
            .add(
                m.texel(level, s0, t0.wrapping_add(1))
                    .scale((1.0 - ds) * dt),
            )
            .add(
                m.texel(level, s0.wrapping_add(1), t0)
                    .scale(ds * (1.0 - dt)),
            )
            .add(
                m.texel(level, s0.wrapping_add(1), t0.wrapping_add(1))
                    .scale(ds * dt),
            )
    }

    /// The bilinear lookup's inside shortcut gives the plain lookup's
    /// values bit for bit, at every level (down to 1 × 1), in every wrap
    /// mode, inside the image, across its edges and far outside.
    #[test]
    fn bilerp_equals_the_plain_lookup() {
        let mut rng = Pcg32::new();
        let (w, h) = (37usize, 16usize);
        let texels: Vec<f32> = (0..w * h).map(|_| rng.uniform_f32() * 2.0 - 0.25).collect();
        for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Black] {
            let m = MipMap::new(w, h, texels.clone(), false, 8.0, wrap).unwrap();
            for level in 0..m.levels() {
                for k in 0..4000 {
                    let spread = [1.0, 1.2, 7.0][k % 3];
                    let st = Vec2::new(rng.uniform_f32(), rng.uniform_f32()) * spread
                        - Vec2::splat(0.5 * (spread - 1.0));
                    let fast = m.bilerp(level, st);
                    let plain = bilerp_plain(&m, level, st);
                    assert_eq!(
                        fast.to_bits(),
                        plain.to_bits(),
                        "{wrap:?} level {level} st {st}"
                    );
                }
            }
        }
    }

    /// A random EWA footprint: centres inside the image, across its edges
    /// and far outside; differentials from none to a few dozen texels, so
    /// that rows are shorter and longer than eight texels.
    fn footprint(rng: &mut Pcg32, levels: usize) -> (usize, Vec2, Vec2, Vec2) {
        let level = rng.uniform_u32_below(levels as u32) as usize;
        let spread = [3.0, 3.0, 40.0][rng.uniform_u32_below(3) as usize];
        let st = Vec2::new(rng.uniform_f32(), rng.uniform_f32()) * spread
            - Vec2::splat(0.5 * (spread - 1.0));
        let scale = [0.2, 0.2, 1.5][rng.uniform_u32_below(3) as usize] * rng.uniform_f32().powi(3);
        let d0 = Vec2::new(rng.uniform_f32() - 0.5, rng.uniform_f32() - 0.5) * scale;
        let d1 = Vec2::new(rng.uniform_f32() - 0.5, rng.uniform_f32() - 0.5) * scale;
        (level, st, d0, d1)
    }

    /// `ewa` (whose scan runs in lanes where AVX2 is enabled) gives
    /// pbrt-v3's scan as written, bit for bit, for float and RGB maps in
    /// every wrap mode; and the scan's two sums are the plain scan's.
    fn ewa_matches<T: TexValue>(texel: impl Fn(&mut Pcg32) -> T, bits: impl Fn(T) -> Vec<u32>) {
        let mut rng = Pcg32::new();
        for (w, h) in [(37usize, 16usize), (3, 70), (1, 1)] {
            let texels: Vec<T> = (0..w * h).map(|_| texel(&mut rng)).collect();
            for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Black] {
                let m = MipMap::new(w, h, texels.clone(), false, 8.0, wrap).unwrap();
                for _ in 0..3000 {
                    let (level, st, d0, d1) = footprint(&mut rng, m.levels());
                    let fast = m.ewa(level, st, d0, d1);
                    let plain = ewa_plain(&m, level, st, d0, d1);
                    let at = format!("{w}x{h} {wrap:?} level {level} st {st} d {d0} {d1}");
                    assert_eq!(bits(fast), bits(plain), "{at}");
                    let l = &m.levels[level];
                    let e = Ellipse::new(l, st, d0, d1);
                    let (sum, sum_w) = crate::textures::ewa_lanes::scan(l, &e, m.weights, wrap);
                    let (sum_p, sum_w_p) = ewa_scan_plain(l, &e, m.weights, wrap);
                    assert_eq!(
                        (bits(sum), sum_w.to_bits()),
                        (bits(sum_p), sum_w_p.to_bits()),
                        "{at}"
                    );
                }
            }
        }
    }

    #[test]
    fn ewa_equals_the_plain_scan() {
        // Negative texels too (Lanczos resampling's ringing is clamped,
        // but a power-of-two image keeps its values).
        ewa_matches(|r| r.uniform_f32() * 2.0 - 0.25, |v| vec![v.to_bits()]);
        ewa_matches(
            |r| {
                Vec3::new(
                    r.uniform_f32(),
                    r.uniform_f32() * 3.0,
                    r.uniform_f32() - 0.5,
                )
            },
            |v| v.to_array().map(f32::to_bits).to_vec(),
        );
    }
}
