//! pbrt-v3's `StratifiedSampler` (a `PixelSampler`): per pixel, jittered
//! strata for the first few 1D and 2D dimensions, shuffled independently per
//! dimension; array samples stratified (1D) or Latin hypercube (2D); then
//! independent uniform values. Tables are regenerated whenever the pixel
//! changes, from a stream seeded by (pixel, seed); a pixel's arrays are made
//! when a sample first reads them (the stream steps past the unread ones).

use super::random::{stream_rng, SampleStream};
use super::{count, ArrayStore, SamplerKindEntry, DIMENSIONS, MAX_SAMPLES};
use crate::sampling::bounded_fast::{BoundedDraws, Jumps};
use crate::sampling::rng::{Pcg32, ONE_MINUS_EPSILON};
use crate::scene::{ParamSpec, ParamValues, Report, SamplerDesc, SamplerKind, Support};
use glam::{IVec2, Vec2};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::boolean("jitter", true, "jitter each sample within its stratum"),
    ParamSpec::int(
        "xsamples",
        4,
        "strata in x (samples per pixel: xsamples × ysamples)",
    ),
    ParamSpec::int("ysamples", 4, "strata in y"),
    DIMENSIONS,
];

pub const KIND: SamplerKindEntry = SamplerKindEntry {
    name: "stratified",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "pbrt-v3's StratifiedSampler: jittered strata per pixel, Latin hypercube arrays",
    build,
};

/// Samples per pixel are xsamples × ysamples, at most [`MAX_SAMPLES`].
fn build(p: &ParamValues, r: &mut dyn Report) -> SamplerDesc {
    let jitter = p.boolean("jitter");
    let xs = count(p, "xsamples", 4, r);
    let ys = count(p, "ysamples", 4, r);
    let total = xs as u64 * ys as u64;
    let (xsamples, ysamples) = if total > MAX_SAMPLES as u64 {
        r.error(
            None,
            format!("stratified sampler: xsamples × ysamples = {total} exceeds {MAX_SAMPLES}"),
            "too many samples",
        );
        (4, 4)
    } else {
        (xs, ys)
    };
    SamplerDesc {
        kind: SamplerKind::Stratified {
            jitter,
            xsamples,
            ysamples,
        },
        pixel_samples: xsamples * ysamples,
        sample_pixel_center: false,
    }
}

/// pbrt-v3's default `dimensions` for the stratified sampler.
const SAMPLED_DIMENSIONS: usize = 4;

#[derive(Clone, Debug)]
pub struct StratifiedSampler {
    xs: u32,
    ys: u32,
    jitter: bool,
    seed: u64,
    samples_1d: Vec<Vec<f32>>,
    samples_2d: Vec<Vec<Vec2>>,
    pub(super) arrays: ArrayStore,
    pixel: Option<IVec2>,
    sample_index: u32,
    dim_1d: usize,
    dim_2d: usize,
    /// Values past the tables.
    rng: SampleStream,
    /// The shuffles' draws below every count up to the largest table.
    draws: BoundedDraws,
}

fn shuffle<T>(s: &mut [T], rng: &mut Pcg32, draws: &BoundedDraws) {
    let n = s.len();
    for i in 0..n {
        let other = i + draws.below(rng, (n - i) as u32) as usize;
        s.swap(i, other);
    }
}

/// The stream stepped past a 1D array's draws ([`stratified_1d`] and
/// [`shuffle`], `copies` times `n` values).
fn skip_1d(n: usize, copies: usize, rng: &mut Pcg32, jitter: bool, draws: &BoundedDraws) {
    let jumps = Jumps::of(rng);
    for _ in 0..copies {
        if jitter {
            rng.advance(n as i64);
        }
        draws.skip(rng, &jumps, n);
    }
}

/// The stream stepped past a 2D array's draws ([`latin_hypercube_2d`],
/// `copies` times `n` values).
fn skip_2d(n: usize, copies: usize, rng: &mut Pcg32, draws: &BoundedDraws) {
    let jumps = Jumps::of(rng);
    for _ in 0..copies {
        rng.advance(2 * n as i64);
        draws.skip(rng, &jumps, n);
        draws.skip(rng, &jumps, n);
    }
}

fn stratified_1d(s: &mut [f32], rng: &mut Pcg32, jitter: bool) {
    let inv = 1.0 / s.len() as f32;
    for (i, v) in s.iter_mut().enumerate() {
        let d = if jitter { rng.uniform_f32() } else { 0.5 };
        *v = ((i as f32 + d) * inv).min(ONE_MINUS_EPSILON);
    }
}

fn stratified_2d(s: &mut [Vec2], nx: u32, ny: u32, rng: &mut Pcg32, jitter: bool) {
    let (dx, dy) = (1.0 / nx as f32, 1.0 / ny as f32);
    let mut k = 0;
    for y in 0..ny {
        for x in 0..nx {
            let jx = if jitter { rng.uniform_f32() } else { 0.5 };
            let jy = if jitter { rng.uniform_f32() } else { 0.5 };
            s[k] = Vec2::new(
                ((x as f32 + jx) * dx).min(ONE_MINUS_EPSILON),
                ((y as f32 + jy) * dy).min(ONE_MINUS_EPSILON),
            );
            k += 1;
        }
    }
}

fn latin_hypercube_2d(s: &mut [Vec2], rng: &mut Pcg32, draws: &BoundedDraws) {
    let n = s.len();
    let inv = 1.0 / n as f32;
    for (i, v) in s.iter_mut().enumerate() {
        let x = ((i as f32 + rng.uniform_f32()) * inv).min(ONE_MINUS_EPSILON);
        let y = ((i as f32 + rng.uniform_f32()) * inv).min(ONE_MINUS_EPSILON);
        *v = Vec2::new(x, y);
    }
    // Shuffle each axis independently (pbrt-v3's LatinHypercube).
    for j in 0..n {
        let other = j + draws.below(rng, (n - j) as u32) as usize;
        let (a, b) = (s[j].x, s[other].x);
        s[j].x = b;
        s[other].x = a;
    }
    for j in 0..n {
        let other = j + draws.below(rng, (n - j) as u32) as usize;
        let (a, b) = (s[j].y, s[other].y);
        s[j].y = b;
        s[other].y = a;
    }
}

/// A pixel's 1D array of `n` values per sample: stratified and shuffled.
fn make_1d(data: &mut [f32], n: u32, rng: &mut Pcg32, jitter: bool, draws: &BoundedDraws) {
    for chunk in data.chunks_exact_mut(n.max(1) as usize) {
        stratified_1d(chunk, rng, jitter);
        shuffle(chunk, rng, draws);
    }
}

/// A pixel's 2D array of `n` values per sample: Latin hypercubes.
fn make_2d(data: &mut [Vec2], n: u32, rng: &mut Pcg32, draws: &BoundedDraws) {
    for chunk in data.chunks_exact_mut(n.max(1) as usize) {
        latin_hypercube_2d(chunk, rng, draws);
    }
}

impl StratifiedSampler {
    /// `xs × ys` strata; if their product is not `spp` (the caller overrode the
    /// sample count), a near-square factorisation of `spp` is used instead.
    pub fn new(xs: u32, ys: u32, spp: u32, jitter: bool, seed: u64) -> Self {
        let spp = spp.max(1);
        let (xs, ys) = if xs.max(1) * ys.max(1) == spp {
            (xs.max(1), ys.max(1))
        } else {
            let mut x = (spp as f64).sqrt() as u32;
            while x > 1 && !spp.is_multiple_of(x) {
                x -= 1;
            }
            let x = x.max(1);
            (spp / x, x)
        };
        let n = (xs * ys) as usize;
        Self {
            xs,
            ys,
            jitter,
            seed,
            samples_1d: vec![vec![0.0; n]; SAMPLED_DIMENSIONS],
            samples_2d: vec![vec![Vec2::ZERO; n]; SAMPLED_DIMENSIONS],
            arrays: ArrayStore::default(),
            pixel: None,
            sample_index: 0,
            dim_1d: 0,
            dim_2d: 0,
            rng: SampleStream::new(),
            draws: BoundedDraws::new(n as u32),
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        self.xs * self.ys
    }

    pub fn request_1d_array(&mut self, n: u32) {
        self.draws.cover(n);
        self.arrays.request_1d(n, self.samples_per_pixel());
        self.pixel = None;
    }

    pub fn request_2d_array(&mut self, n: u32) {
        self.draws.cover(n);
        self.arrays.request_2d(n, self.samples_per_pixel());
        self.pixel = None;
    }

    fn generate_pixel(&mut self, pixel: IVec2) {
        self.generate_pixel_with(pixel, false);
    }

    /// The tables of `pixel`; its arrays made now if `eager` (the tests'
    /// reference), else when a sample first reads them.
    fn generate_pixel_with(&mut self, pixel: IVec2, eager: bool) {
        let mut rng = stream_rng(pixel, u32::MAX, self.seed, 2);
        let (xs, ys, jitter) = (self.xs, self.ys, self.jitter);
        let draws = &self.draws;
        for s in &mut self.samples_1d {
            stratified_1d(s, &mut rng, jitter);
            shuffle(s, &mut rng, draws);
        }
        for s in &mut self.samples_2d {
            stratified_2d(s, xs, ys, &mut rng, jitter);
            shuffle(s, &mut rng, draws);
        }
        let copies = (xs * ys) as usize;
        let a = &mut self.arrays;
        for (i, &n) in a.sizes_1d.iter().enumerate() {
            if eager {
                make_1d(&mut a.data_1d[i], n, &mut rng, jitter, draws);
                a.unmade_1d[i] = None;
            } else {
                a.unmade_1d[i] = Some(rng);
                skip_1d(n.max(1) as usize, copies, &mut rng, jitter, draws);
            }
        }
        for (i, &n) in a.sizes_2d.iter().enumerate() {
            if eager {
                make_2d(&mut a.data_2d[i], n, &mut rng, draws);
                a.unmade_2d[i] = None;
            } else {
                a.unmade_2d[i] = Some(rng);
                skip_2d(n.max(1) as usize, copies, &mut rng, draws);
            }
        }
        self.pixel = Some(pixel);
    }

    pub fn start_pixel_sample(&mut self, pixel: IVec2, sample_index: u32) {
        if self.pixel != Some(pixel) {
            self.generate_pixel(pixel);
        }
        self.sample_index = sample_index;
        self.dim_1d = 0;
        self.dim_2d = 0;
        self.rng.start(pixel, sample_index);
        self.arrays.reset();
    }

    /// The stream of values past the tables.
    #[inline]
    fn rng(&mut self) -> &mut Pcg32 {
        self.rng.rng(self.seed, 3)
    }

    #[inline]
    fn in_table(&self) -> bool {
        self.sample_index < self.samples_per_pixel()
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        if self.dim_1d < SAMPLED_DIMENSIONS && self.in_table() {
            let v = self.samples_1d[self.dim_1d][self.sample_index as usize];
            self.dim_1d += 1;
            v
        } else {
            self.rng().uniform_f32()
        }
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        if self.dim_2d < SAMPLED_DIMENSIONS && self.in_table() {
            let v = self.samples_2d[self.dim_2d][self.sample_index as usize];
            self.dim_2d += 1;
            v
        } else {
            let rng = self.rng();
            let x = rng.uniform_f32();
            Vec2::new(x, rng.uniform_f32())
        }
    }

    #[inline]
    pub fn get_1d_array(&mut self, n: u32) -> Option<&[f32]> {
        if !self.in_table() {
            return None;
        }
        if let Some((data, mut rng)) = self.arrays.unmade_1d(n) {
            make_1d(data, n, &mut rng, self.jitter, &self.draws);
        }
        self.arrays.get_1d(n, self.sample_index as usize)
    }

    #[inline]
    pub fn get_2d_array(&mut self, n: u32) -> Option<&[Vec2]> {
        if !self.in_table() {
            return None;
        }
        if let Some((data, mut rng)) = self.arrays.unmade_2d(n) {
            make_2d(data, n, &mut rng, &self.draws);
        }
        self.arrays.get_2d(n, self.sample_index as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Arrays read at some samples of some pixels only (the others stepped
    /// past) equal the arrays made at once, and the tables are unchanged.
    #[test]
    fn lazy_arrays_equal_arrays_made_at_once() {
        for jitter in [true, false] {
            let make = || {
                let mut s = StratifiedSampler::new(2, 3, 6, jitter, 7);
                s.request_1d_array(5);
                s.request_2d_array(9);
                s.request_1d_array(1);
                s.request_2d_array(64);
                s
            };
            let (mut lazy, mut eager) = (make(), make());
            for k in 0..40 {
                let p = IVec2::new(k % 7, k / 7);
                eager.generate_pixel_with(p, true);
                let sample = (k % 6) as u32;
                lazy.start_pixel_sample(p, sample);
                let i = sample as usize;
                let a = &eager.arrays;
                // Every array at most pixels, the first two or none at others.
                if k % 3 != 1 || k % 2 == 0 {
                    assert_eq!(
                        lazy.get_1d_array(5).unwrap(),
                        &a.data_1d[0][5 * i..5 * i + 5]
                    );
                    assert_eq!(
                        lazy.get_2d_array(9).unwrap(),
                        &a.data_2d[0][9 * i..9 * i + 9]
                    );
                }
                if k % 3 != 1 {
                    assert_eq!(lazy.get_1d_array(1).unwrap(), &a.data_1d[1][i..i + 1]);
                    assert_eq!(
                        lazy.get_2d_array(64).unwrap(),
                        &a.data_2d[1][64 * i..64 * i + 64]
                    );
                }
                assert_eq!(lazy.samples_2d, eager.samples_2d);
                assert_eq!(lazy.samples_1d, eager.samples_1d);
            }
        }
    }
}
