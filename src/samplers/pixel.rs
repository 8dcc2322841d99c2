//! pbrt-v3's `PixelSampler` (core/sampler.cpp) as `ZeroTwoSequenceSampler`
//! and `MaxMinDistSampler` use it: at each pixel, tables of every sample's
//! values for the first `dimensions` 1D and 2D dimensions and for the
//! requested arrays, made with the sampler's RNG: 1D values by the
//! scrambled van der Corput sequence, 2D values by the scrambled Sobol'
//! (0,2)-sequence (the first two Sobol' matrices, made from Joe and Kuo's
//! direction numbers), each shuffled (core/lowdiscrepancy.h's
//! `VanDerCorput`, `Sobol2D`); the max-min-distance sampler takes its
//! first 2D dimension from its own generator matrix instead.
//!
//! pbrt-v3 clones the sampler for each 16×16 tile of the sample bounds
//! with its RNG at sequence `tile.y * nTiles.x + tile.x`
//! (`SamplerIntegrator::Render`), and the RNG advances through the
//! tile's pixels in row order. This sampler does the same: the tables of a
//! pixel are those pbrt-v3 makes, whatever thread, tile or region renders
//! it, because a pixel reached out of that order replays the RNG from its
//! tile's first pixel. Values past the tables (pbrt-v3 draws them from
//! the same RNG, so that they depend on how many earlier pixels of the
//! tile used) come from an independent stream seeded by (pixel, sample,
//! seed), so that images do not depend on threads or tiling.

use super::random::{stream_rng, SampleStream};
use super::sobolmatrices::{sobol_matrices, to_unit, SOBOL_MATRIX_SIZE};
use super::ArrayStore;
use crate::geometry::Bounds2i;
use crate::sampling::bounded_fast::{BoundedDraws, Jumps, Stride};
use crate::sampling::rng::{mix64, Pcg32};
use glam::{IVec2, Vec2};

/// pbrt-v3's tile size in `SamplerIntegrator::Render`.
pub const TILE_SIZE: i32 = 16;

/// Which pattern the first 2D dimension takes.
#[derive(Clone, Copy, Debug)]
pub enum Pattern {
    /// `ZeroTwoSequenceSampler`: the (0,2)-sequence.
    ZeroTwo,
    /// `MaxMinDistSampler`: `(i / spp, C · i)` for the generator matrix `C`
    /// (columns, bit 31 the first digit), shuffled.
    MaxMinDist(&'static [u32; 32]),
}

#[derive(Clone, Debug)]
pub struct PixelSampler {
    pattern: Pattern,
    spp: u32,
    /// The van der Corput and second Sobol' matrices (32 columns each).
    c0: &'static [u32],
    c1: &'static [u32],
    samples_1d: Vec<Vec<f32>>,
    samples_2d: Vec<Vec<Vec2>>,
    /// The RNG where each dimension's table starts, while the table is not
    /// made (made when a sample first reads it, as the arrays).
    unmade_1d: Vec<Option<Pcg32>>,
    unmade_2d: Vec<Option<Pcg32>>,
    pub(super) arrays: ArrayStore,
    bounds: Bounds2i,
    tiles_x: i32,
    /// Added to the tile number for the RNG's sequence (0 for seed 0).
    seed_offset: u64,
    seed: u64,
    /// The tile RNG, just after making the tables of `generated`.
    rng: Pcg32,
    generated: Option<IVec2>,
    pixel: IVec2,
    sample_index: u32,
    dim_1d: usize,
    dim_2d: usize,
    /// Values past the tables.
    extra: SampleStream,
    /// The shuffles' draws below every count up to the largest of `spp`
    /// and the arrays' sizes.
    draws: BoundedDraws,
    /// The fixed steps of the stream of the tables last made.
    steps: Steps,
}

/// The fixed steps a pixel's tables take on one RNG stream, made once per
/// stream (a tile's), not per table.
#[derive(Clone, Copy, Debug)]
struct Steps {
    /// The stream's increment (`Pcg32::parts().1`).
    inc: u64,
    jumps: Jumps,
    /// `spp` steps: the shuffles within runs of one value.
    spp: Stride,
    /// 1 + `spp` and 2 + `spp` steps: a table of one value per pixel
    /// sample whose values are not made (its scrambles and those shuffles).
    past: [Stride; 2],
}

impl Steps {
    fn new(rng: &Pcg32, spp: usize) -> Self {
        Self {
            inc: rng.parts().1,
            jumps: Jumps::of(rng),
            spp: Stride::new(rng, spp as u64),
            past: [1, 2].map(|s| Stride::new(rng, s + spp as u64)),
        }
    }

    /// The steps of `rng`'s stream (made anew if they are another's).
    #[inline]
    fn of(&mut self, rng: &Pcg32, spp: usize) -> &Steps {
        if self.inc != rng.parts().1 {
            *self = Steps::new(rng, spp);
        }
        self
    }
}

/// pbrt-v3's `Shuffle(samp, count, nDimensions, rng)`: blocks of `n` values
/// (the plain method, which [`shuffle`] equals).
#[cfg(test)]
fn shuffle_plain<T>(s: &mut [T], count: usize, n: usize, rng: &mut Pcg32) {
    for i in 0..count {
        let other = i + rng.uniform_u32_below((count - i) as u32) as usize;
        for j in 0..n {
            s.swap(n * i + j, n * other + j);
        }
    }
}

/// pbrt-v3's `Shuffle(samp, count, nDimensions, rng)`: blocks of `n` values,
/// with the draws of `draws` (the same values and RNG state as
/// [`Pcg32::uniform_u32_below`]).
#[inline]
fn shuffle<T>(s: &mut [T], count: usize, n: usize, rng: &mut Pcg32, draws: &BoundedDraws) {
    if n == 1 {
        let s = &mut s[..count];
        for i in 0..count {
            let other = i + draws.below(rng, (count - i) as u32) as usize;
            s.swap(i, other);
        }
        return;
    }
    for i in 0..count {
        let other = i + draws.below(rng, (count - i) as u32) as usize;
        if other != i {
            let (a, b) = s.split_at_mut(n * other);
            a[n * i..n * i + n].swap_with_slice(&mut b[..n]);
        }
    }
}

/// pbrt-v3's shuffle of each of a pixel's `spp` runs of `per_sample` values
/// within itself. A run of one value stays as it is after one draw below 1,
/// so the RNG skips those draws in one step.
#[inline]
fn shuffle_within<T>(
    out: &mut [T],
    per_sample: usize,
    spp: usize,
    rng: &mut Pcg32,
    draws: &BoundedDraws,
    steps: &Steps,
) {
    if per_sample == 1 {
        steps.spp.apply(rng);
        return;
    }
    for i in 0..spp {
        shuffle(&mut out[i * per_sample..], per_sample, 1, rng, draws);
    }
}

/// The RNG stepped past the draws that [`van_der_corput`] (`scrambles` 1)
/// or [`sobol_2d`] (`scrambles` 2) make, without the values or the swaps.
fn skip_table(
    scrambles: usize,
    per_sample: usize,
    spp: usize,
    rng: &mut Pcg32,
    draws: &BoundedDraws,
    steps: &Steps,
) {
    if per_sample == 1 {
        steps.past[scrambles - 1].apply(rng);
    } else {
        rng.advance(scrambles as i64);
        draws.skip_runs(rng, &steps.jumps, spp, per_sample);
    }
    draws.skip(rng, &steps.jumps, spp);
}

/// pbrt-v3's `GrayCodeSample` (one dimension) and `VanDerCorput`: the
/// scrambled van der Corput values in Gray-code order, shuffled within each
/// pixel sample's `per_sample` values, then the pixel samples shuffled.
fn van_der_corput(
    per_sample: usize,
    spp: usize,
    out: &mut [f32],
    c: &[u32],
    rng: &mut Pcg32,
    draws: &BoundedDraws,
    steps: &Steps,
) {
    let mut v = rng.uniform_u32();
    for (i, o) in out.iter_mut().enumerate().take(per_sample * spp) {
        *o = to_unit(v);
        v ^= c[(i as u32 + 1).trailing_zeros() as usize];
    }
    shuffle_within(out, per_sample, spp, rng, draws, steps);
    shuffle(out, spp, per_sample, rng, draws);
}

/// pbrt-v3's `Sobol2D`: the scrambled (0,2)-sequence in Gray-code order,
/// shuffled as [`van_der_corput`].
fn sobol_2d(
    per_sample: usize,
    spp: usize,
    out: &mut [Vec2],
    c: [&[u32]; 2],
    rng: &mut Pcg32,
    draws: &BoundedDraws,
    steps: &Steps,
) {
    let mut v = [rng.uniform_u32(), rng.uniform_u32()];
    for (i, o) in out.iter_mut().enumerate().take(per_sample * spp) {
        *o = Vec2::new(to_unit(v[0]), to_unit(v[1]));
        let k = (i as u32 + 1).trailing_zeros() as usize;
        v[0] ^= c[0][k];
        v[1] ^= c[1][k];
    }
    shuffle_within(out, per_sample, spp, rng, draws, steps);
    shuffle(out, spp, per_sample, rng, draws);
}

/// pbrt-v3's `MultiplyGenerator`.
#[inline]
pub fn multiply_generator(c: &[u32], mut a: u32) -> u32 {
    let mut v = 0;
    let mut i = 0;
    while a != 0 {
        if a & 1 == 1 {
            v ^= c[i];
        }
        a >>= 1;
        i += 1;
    }
    v
}

impl PixelSampler {
    /// `spp` must be a power of two (the kinds round it).
    pub fn new(
        pattern: Pattern,
        spp: u32,
        dimensions: u32,
        sample_bounds: Bounds2i,
        seed: u64,
    ) -> Self {
        let spp = spp.max(1);
        let m = &sobol_matrices().m32;
        let d = sample_bounds.max - sample_bounds.min;
        Self {
            pattern,
            spp,
            c0: &m[0..32],
            c1: &m[SOBOL_MATRIX_SIZE..SOBOL_MATRIX_SIZE + 32],
            samples_1d: vec![vec![0.0; spp as usize]; dimensions as usize],
            samples_2d: vec![vec![Vec2::ZERO; spp as usize]; dimensions as usize],
            unmade_1d: vec![None; dimensions as usize],
            unmade_2d: vec![None; dimensions as usize],
            arrays: ArrayStore::default(),
            bounds: sample_bounds,
            tiles_x: ((d.x + TILE_SIZE - 1) / TILE_SIZE).max(1),
            seed_offset: if seed == 0 {
                0
            } else {
                mix64(seed ^ 0x5069_7865_6c53_616d)
            },
            seed,
            rng: Pcg32::new(),
            generated: None,
            pixel: IVec2::ZERO,
            sample_index: 0,
            dim_1d: 0,
            dim_2d: 0,
            extra: SampleStream::new(),
            draws: BoundedDraws::new(spp),
            steps: Steps::new(&Pcg32::new(), spp as usize),
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    /// Bytes of the per-dimension tables (not the array store).
    pub fn table_bytes(&self) -> usize {
        self.samples_1d.iter().map(|v| v.len() * 4).sum::<usize>()
            + self.samples_2d.iter().map(|v| v.len() * 8).sum::<usize>()
    }

    /// pbrt-v3's `RoundCount`: array sizes are powers of two.
    pub fn round_count(&self, n: u32) -> u32 {
        n.max(1).next_power_of_two()
    }

    pub fn request_1d_array(&mut self, n: u32) {
        self.draws.cover(n);
        self.arrays.request_1d(n, self.spp);
        self.generated = None;
    }

    pub fn request_2d_array(&mut self, n: u32) {
        self.draws.cover(n);
        self.arrays.request_2d(n, self.spp);
        self.generated = None;
    }

    /// The tables of the current pixel made by pbrt-v3's `StartPixel` with
    /// the RNG as it is.
    fn generate(&mut self) {
        self.generate_with(false);
    }

    /// [`PixelSampler::generate`], with the tables and arrays made now if
    /// `eager` (the tests' reference), else when first read.
    fn generate_with(&mut self, eager: bool) {
        let spp = self.spp as usize;
        let rng = &mut self.rng;
        let draws = &self.draws;
        let steps = self.steps.of(rng, spp);
        let (c0, c1) = (self.c0, self.c1);
        let mut rest_2d = &mut self.unmade_2d[..];
        if let Pattern::MaxMinDist(c) = self.pattern {
            if let (Some(first), Some((u, rest))) = (
                self.samples_2d.first_mut(),
                std::mem::take(&mut rest_2d).split_first_mut(),
            ) {
                let inv = 1.0 / self.spp as f32;
                for (i, v) in first.iter_mut().enumerate() {
                    *v = Vec2::new(i as f32 * inv, to_unit(multiply_generator(c, i as u32)));
                }
                shuffle(first, spp, 1, rng, draws);
                *u = None;
                rest_2d = rest;
            }
        }
        // The dimensions' tables, as the arrays below, are made when a
        // sample first reads them (directlighting's and whitted's third and
        // fourth 2D dimensions are the camera vertex's specular bounces'
        // samples, which a BSDF without specular lobes never reads): here
        // the RNG only steps past their draws.
        for u in &mut self.unmade_1d {
            *u = Some(*rng);
            skip_table(1, 1, spp, rng, draws, steps);
        }
        for u in rest_2d {
            *u = Some(*rng);
            skip_table(2, 1, spp, rng, draws, steps);
        }
        if eager {
            for (s, u) in self.samples_1d.iter_mut().zip(&mut self.unmade_1d) {
                if let Some(mut r) = u.take() {
                    van_der_corput(1, spp, s, c0, &mut r, draws, steps);
                }
            }
            for (s, u) in self.samples_2d.iter_mut().zip(&mut self.unmade_2d) {
                if let Some(mut r) = u.take() {
                    sobol_2d(1, spp, s, [c0, c1], &mut r, draws, steps);
                }
            }
            let a = &mut self.arrays;
            for (&n, data) in a.sizes_1d.iter().zip(a.data_1d.iter_mut()) {
                van_der_corput(n as usize, spp, data, c0, rng, draws, steps);
            }
            for (&n, data) in a.sizes_2d.iter().zip(a.data_2d.iter_mut()) {
                sobol_2d(n as usize, spp, data, [c0, c1], rng, draws, steps);
            }
            a.unmade_1d.iter_mut().for_each(|u| *u = None);
            a.unmade_2d.iter_mut().for_each(|u| *u = None);
            return;
        }
        // The arrays are made when a sample first reads them (most of
        // directlighting's, one per light and bounce, never are): here the
        // RNG only steps past their draws.
        let a = &mut self.arrays;
        for (&n, unmade) in a.sizes_1d.iter().zip(a.unmade_1d.iter_mut()) {
            *unmade = Some(*rng);
            skip_table(1, n as usize, spp, rng, draws, steps);
        }
        for (&n, unmade) in a.sizes_2d.iter().zip(a.unmade_2d.iter_mut()) {
            *unmade = Some(*rng);
            skip_table(2, n as usize, spp, rng, draws, steps);
        }
    }

    /// The number of `pixel`'s tile (pbrt-v3's numbering) and the pixel's
    /// place in the tile's row order; `None` outside the sample bounds.
    fn tile_of(&self, pixel: IVec2) -> Option<(u64, usize)> {
        let b = self.bounds;
        if pixel.x < b.min.x || pixel.y < b.min.y || pixel.x >= b.max.x || pixel.y >= b.max.y {
            return None;
        }
        let t = (pixel - b.min) / TILE_SIZE;
        let x0 = b.min.x + t.x * TILE_SIZE;
        let y0 = b.min.y + t.y * TILE_SIZE;
        let w = (x0 + TILE_SIZE).min(b.max.x) - x0;
        let tile = (t.y as i64 * self.tiles_x as i64 + t.x as i64) as u64;
        Some((tile, ((pixel.y - y0) * w + pixel.x - x0) as usize))
    }

    /// Makes the tables of `pixel` with the RNG pbrt-v3's tile sampler has
    /// there: continuing from the last pixel made if it is earlier in the
    /// same tile, else replaying from the tile's start.
    fn start_pixel(&mut self, pixel: IVec2) {
        let Some((tile, k)) = self.tile_of(pixel) else {
            // Not a pixel pbrt-v3 samples: a stream of its own.
            self.rng = stream_rng(pixel, u32::MAX, self.seed, 5);
            self.generate();
            self.generated = None;
            return;
        };
        let start = match self.generated.and_then(|g| self.tile_of(g)) {
            Some((t, j)) if t == tile && j < k => j + 1,
            _ => {
                self.rng.set_sequence(tile.wrapping_add(self.seed_offset));
                0
            }
        };
        for _ in start..=k {
            self.generate();
        }
        self.generated = Some(pixel);
    }

    pub fn start_pixel_sample(&mut self, pixel: IVec2, sample_index: u32) {
        if self.generated != Some(pixel) {
            self.start_pixel(pixel);
        }
        self.pixel = pixel;
        self.sample_index = sample_index;
        self.dim_1d = 0;
        self.dim_2d = 0;
        self.extra.start(pixel, sample_index);
        self.arrays.reset();
    }

    #[inline]
    fn in_table(&self) -> bool {
        self.sample_index < self.spp
    }

    /// The stream of values past the tables.
    #[inline]
    fn extra(&mut self) -> &mut Pcg32 {
        self.extra.rng(self.seed, 4)
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        let d = self.dim_1d;
        if d < self.samples_1d.len() && self.in_table() {
            if let Some(mut rng) = self.unmade_1d[d].take() {
                let spp = self.spp as usize;
                let steps = self.steps.of(&rng, spp);
                let s = &mut self.samples_1d[d];
                van_der_corput(1, spp, s, self.c0, &mut rng, &self.draws, steps);
            }
            let v = self.samples_1d[d][self.sample_index as usize];
            self.dim_1d += 1;
            v
        } else {
            self.extra().uniform_f32()
        }
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        let d = self.dim_2d;
        if d < self.samples_2d.len() && self.in_table() {
            if let Some(mut rng) = self.unmade_2d[d].take() {
                let spp = self.spp as usize;
                let steps = self.steps.of(&rng, spp);
                let c = [self.c0, self.c1];
                let s = &mut self.samples_2d[d];
                sobol_2d(1, spp, s, c, &mut rng, &self.draws, steps);
            }
            let v = self.samples_2d[d][self.sample_index as usize];
            self.dim_2d += 1;
            v
        } else {
            let extra = self.extra();
            let x = extra.uniform_f32();
            Vec2::new(x, extra.uniform_f32())
        }
    }

    /// Consumes a 2D value as [`PixelSampler::get_2d`] does, without
    /// making its dimension's table.
    #[inline]
    pub fn skip_2d(&mut self) {
        if self.dim_2d < self.samples_2d.len() && self.in_table() {
            self.dim_2d += 1;
        } else {
            let extra = self.extra();
            extra.uniform_f32();
            extra.uniform_f32();
        }
    }

    #[inline]
    pub fn get_1d_array(&mut self, n: u32) -> Option<&[f32]> {
        if !self.in_table() {
            return None;
        }
        if let Some((data, mut rng)) = self.arrays.unmade_1d(n) {
            let spp = self.spp as usize;
            let steps = self.steps.of(&rng, spp);
            van_der_corput(n as usize, spp, data, self.c0, &mut rng, &self.draws, steps);
        }
        self.arrays.get_1d(n, self.sample_index as usize)
    }

    #[inline]
    pub fn get_2d_array(&mut self, n: u32) -> Option<&[Vec2]> {
        if !self.in_table() {
            return None;
        }
        if let Some((data, mut rng)) = self.arrays.unmade_2d(n) {
            let c = [self.c0, self.c1];
            let spp = self.spp as usize;
            let steps = self.steps.of(&rng, spp);
            sobol_2d(n as usize, spp, data, c, &mut rng, &self.draws, steps);
        }
        self.arrays.get_2d(n, self.sample_index as usize)
    }

    /// `get_2d_array(n).is_some()` without making the array: its values
    /// are left unmade (the tile's RNG stepped past them when the pixel
    /// started), for a later sample that reads them.
    #[inline]
    pub fn skip_2d_array(&mut self, n: u32) -> bool {
        self.in_table() && self.arrays.skip_2d(n, self.sample_index as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shuffles_equal_pbrt_v3s() {
        let draws = BoundedDraws::new(64);
        let cases = [
            (1usize, 1usize),
            (2, 1),
            (64, 1),
            (64, 3),
            (16, 8),
            (7, 2),
            (100, 1),
        ];
        for &(count, n) in &cases {
            let mut a: Vec<u32> = (0..(count * n) as u32).collect();
            let mut b = a.clone();
            let mut ra = Pcg32::new();
            ra.set_sequence(count as u64 * 31 + n as u64);
            let mut rb = ra;
            shuffle(&mut a, count, n, &mut ra, &draws);
            shuffle_plain(&mut b, count, n, &mut rb);
            assert_eq!(a, b, "count {count} n {n}");
            assert_eq!(ra.uniform_u32(), rb.uniform_u32());
            // The runs of one pixel sample each, shuffled within themselves.
            let (spp, per) = (count, n);
            let steps = Steps::new(&ra, spp);
            shuffle_within(&mut a, per, spp, &mut ra, &draws, &steps);
            for i in 0..spp {
                shuffle_plain(&mut b[i * per..], per, 1, &mut rb);
            }
            assert_eq!(a, b, "within: spp {spp} per sample {per}");
            assert_eq!(ra.uniform_u32(), rb.uniform_u32());
        }
    }

    /// Arrays left unread at some pixels (stepped past, not made) leave the
    /// RNG where making them does: a pixel's arrays read lazily, after
    /// earlier pixels of its tile left theirs unread, equal the arrays made
    /// at once at every pixel from the tile's start.
    /// Every `n`th pixel of `b` in row order, with its number (from 1).
    fn every_nth_pixel(b: Bounds2i, n: usize) -> impl Iterator<Item = (usize, IVec2)> {
        (b.min.y..b.max.y)
            .flat_map(move |y| (b.min.x..b.max.x).map(move |x| IVec2::new(x, y)))
            .enumerate()
            .map(|(i, p)| (i + 1, p))
            .filter(move |(k, _)| k % n == 0)
    }

    /// Sample `k % 8` of pixel `p` started by `lazy`, and by `eager` the
    /// reference: the tables and arrays of every pixel of `p`'s tile up to
    /// `p` made at once, as pbrt-v3's `StartPixel` makes them. The sample.
    fn start_both(lazy: &mut PixelSampler, eager: &mut PixelSampler, p: IVec2, k: usize) -> usize {
        let (tile, index) = eager.tile_of(p).unwrap();
        eager.rng.set_sequence(tile.wrapping_add(eager.seed_offset));
        for _ in 0..=index {
            eager.generate_with(true);
        }
        lazy.start_pixel_sample(p, (k % 8) as u32);
        k % 8
    }

    #[test]
    fn unread_arrays_step_the_rng_as_made_ones() {
        let bounds = Bounds2i::new(IVec2::new(-2, -2), IVec2::new(30, 20));
        let make = || {
            let mut s = PixelSampler::new(Pattern::ZeroTwo, 8, 2, bounds, 0);
            s.request_1d_array(3);
            s.request_2d_array(16);
            s.request_2d_array(1);
            s.request_1d_array(1);
            s
        };
        let mut lazy = make();
        let mut eager = make();
        for (k, p) in every_nth_pixel(bounds, 5) {
            let i = start_both(&mut lazy, &mut eager, p, k);
            let a = &eager.arrays;
            assert_eq!(
                lazy.get_1d_array(3).unwrap(),
                &a.data_1d[0][3 * i..3 * i + 3]
            );
            assert_eq!(
                lazy.get_2d_array(16).unwrap(),
                &a.data_2d[0][16 * i..16 * i + 16]
            );
            assert_eq!(lazy.get_2d_array(1).unwrap(), &a.data_2d[1][i..i + 1]);
            assert_eq!(lazy.get_1d_array(1).unwrap(), &a.data_1d[1][i..i + 1]);
        }
    }

    /// Dimensions whose tables are made only when read (or stepped past
    /// by `skip_2d`) give the values of tables made at once, whatever was
    /// read at earlier pixels and samples.
    #[test]
    fn unread_dimensions_step_as_made_ones() {
        let bounds = Bounds2i::new(IVec2::new(-3, 0), IVec2::new(29, 21));
        for maxmin in [false, true] {
            let make = || {
                let mut s = if maxmin {
                    crate::samplers::maxmindist::sampler(8, 3, bounds, 3)
                } else {
                    PixelSampler::new(Pattern::ZeroTwo, 8, 3, bounds, 3)
                };
                s.request_2d_array(2);
                s
            };
            let (mut lazy, mut eager) = (make(), make());
            for (k, p) in every_nth_pixel(bounds, 3) {
                let i = start_both(&mut lazy, &mut eager, p, k);
                let sample = i as u32;
                if k % 2 == 0 {
                    lazy.skip_2d();
                } else {
                    assert_eq!(lazy.get_2d(), eager.samples_2d[0][i]);
                }
                assert_eq!(lazy.get_1d(), eager.samples_1d[0][i]);
                lazy.skip_2d();
                assert_eq!(lazy.get_2d(), eager.samples_2d[2][i]);
                assert_eq!(
                    lazy.get_2d_array(2).unwrap(),
                    &eager.arrays.data_2d[0][2 * i..2 * i + 2]
                );
                assert_eq!(lazy.get_1d(), eager.samples_1d[1][i]);
                assert_eq!(lazy.get_1d(), eager.samples_1d[2][i]);
                // A later sample of the pixel reads the dimension skipped.
                lazy.start_pixel_sample(p, (sample + 1) % 8);
                let i = (sample as usize + 1) % 8;
                assert_eq!(lazy.get_2d(), eager.samples_2d[0][i]);
                assert_eq!(lazy.get_1d(), eager.samples_1d[0][i]);
                assert_eq!(lazy.get_2d(), eager.samples_2d[1][i]);
            }
        }
    }

    /// A 2D array stepped past unread (a delta light's) answers as a read
    /// one, leaves the next arrays and values where reading would, and is
    /// still made right when a later sample of the pixel reads it.
    #[test]
    fn skipped_arrays_answer_and_step_as_read_ones() {
        let bounds = Bounds2i::new(IVec2::new(0, 0), IVec2::new(20, 18));
        let make = |maxmin: bool| {
            let mut s = if maxmin {
                crate::samplers::maxmindist::sampler(4, 2, bounds, 7)
            } else {
                PixelSampler::new(Pattern::ZeroTwo, 4, 2, bounds, 7)
            };
            s.request_2d_array(1);
            s.request_2d_array(1);
            s.request_2d_array(4);
            s.request_1d_array(2);
            s.request_2d_array(1);
            s
        };
        for maxmin in [false, true] {
            let (mut read, mut skip) = (make(maxmin), make(maxmin));
            for y in 0..18 {
                for x in 0..20 {
                    let p = IVec2::new(x, y);
                    // Samples 4 and 5 are past the table (no arrays).
                    for sample in 0..6u32 {
                        read.start_pixel_sample(p, sample);
                        skip.start_pixel_sample(p, sample);
                        let which = (x + 3 * y + sample as i32) % 4;
                        for (k, n) in [1u32, 1, 4].into_iter().enumerate() {
                            let r = read.get_2d_array(n).map(|a| a.to_vec());
                            if k as i32 == which {
                                assert_eq!(skip.skip_2d_array(n), r.is_some());
                            } else {
                                assert_eq!(skip.get_2d_array(n).map(|a| a.to_vec()), r);
                            }
                        }
                        // A mismatched size answers no and steps nowhere.
                        assert!(!skip.skip_2d_array(3));
                        assert_eq!(skip.get_1d_array(2), read.get_1d_array(2));
                        assert_eq!(skip.get_2d_array(1), read.get_2d_array(1));
                        assert_eq!(skip.get_2d(), read.get_2d());
                    }
                }
            }
        }
    }
}
