//! Independent uniform values from PCG32, seeded per (pixel, sample, seed) so
//! that they do not depend on which thread renders what.

use super::{count, ArrayStore, SamplerKindEntry};
use crate::sampling::rng::{hash_words, Pcg32};
use crate::scene::{ParamSpec, SamplerDesc, SamplerKind, Support};
use glam::{IVec2, Vec2};

pub const PARAMS: &[ParamSpec] = &[ParamSpec::int("pixelsamples", 4, "samples per pixel")];

pub const KIND: SamplerKindEntry = SamplerKindEntry {
    name: "random",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "independent uniform values",
    build: |p, r| SamplerDesc {
        kind: SamplerKind::Random,
        pixel_samples: count(p, "pixelsamples", 4, r),
        sample_pixel_center: false,
    },
};

#[derive(Clone, Debug)]
pub struct RandomSampler {
    spp: u32,
    seed: u64,
    rng: Pcg32,
    pub(super) arrays: ArrayStore,
}

/// PCG32 stream for a (pixel, sample, seed, purpose) tuple.
#[inline]
pub(crate) fn stream_rng(pixel: IVec2, sample_index: u32, seed: u64, purpose: u64) -> Pcg32 {
    let key = [
        pixel.x as u32 as u64 | ((pixel.y as u32 as u64) << 32),
        sample_index as u64,
        seed,
        purpose,
    ];
    let h = hash_words(&key);
    let mut r = Pcg32::new();
    r.seed(h, hash_words(&[h, 0x5eed]));
    r
}

/// A sample's [`stream_rng`] for one purpose, seeded when first drawn from
/// (hashing the key for every sample costs more than most samples draw).
#[derive(Clone, Debug)]
pub(crate) struct SampleStream {
    rng: Pcg32,
    pixel: IVec2,
    sample_index: u32,
    seeded: bool,
}

impl SampleStream {
    pub fn new() -> Self {
        Self {
            rng: Pcg32::new(),
            pixel: IVec2::ZERO,
            sample_index: 0,
            seeded: false,
        }
    }

    /// Starts the stream of `(pixel, sample_index)`.
    #[inline]
    pub fn start(&mut self, pixel: IVec2, sample_index: u32) {
        self.pixel = pixel;
        self.sample_index = sample_index;
        self.seeded = false;
    }

    /// The stream `stream_rng(pixel, sample_index, seed, purpose)`, at the
    /// value after those already drawn.
    #[inline]
    pub fn rng(&mut self, seed: u64, purpose: u64) -> &mut Pcg32 {
        if !self.seeded {
            self.rng = stream_rng(self.pixel, self.sample_index, seed, purpose);
            self.seeded = true;
        }
        &mut self.rng
    }
}

impl RandomSampler {
    pub fn new(spp: u32, seed: u64) -> Self {
        Self {
            spp: spp.max(1),
            seed,
            rng: Pcg32::new(),
            arrays: ArrayStore::default(),
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    pub fn request_1d_array(&mut self, n: u32) {
        self.arrays.request_1d(n, 1);
    }

    pub fn request_2d_array(&mut self, n: u32) {
        self.arrays.request_2d(n, 1);
    }

    pub fn start_pixel_sample(&mut self, pixel: IVec2, sample_index: u32) {
        self.rng = stream_rng(pixel, sample_index, self.seed, 0);
        if !self.arrays.sizes_1d.is_empty() || !self.arrays.sizes_2d.is_empty() {
            let mut r = stream_rng(pixel, sample_index, self.seed, 1);
            for data in &mut self.arrays.data_1d {
                for v in data.iter_mut() {
                    *v = r.uniform_f32();
                }
            }
            for data in &mut self.arrays.data_2d {
                for v in data.iter_mut() {
                    *v = Vec2::new(r.uniform_f32(), r.uniform_f32());
                }
            }
        }
        self.arrays.reset();
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        self.rng.uniform_f32()
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        let x = self.rng.uniform_f32();
        Vec2::new(x, self.rng.uniform_f32())
    }

    #[inline]
    pub fn get_1d_array(&mut self, n: u32) -> Option<&[f32]> {
        self.arrays.get_1d(n, 0)
    }

    #[inline]
    pub fn get_2d_array(&mut self, n: u32) -> Option<&[Vec2]> {
        self.arrays.get_2d(n, 0)
    }
}
