//! pbrt-v3's `SobolSampler` (samplers/sobol.{h,cpp}) with `GlobalSampler`'s
//! dimension and array handling (core/sampler.cpp): one Sobol' sequence
//! over the image, its first two dimensions scaled by the image resolution
//! rounded up to a power of two, a pixel's samples found by
//! `SobolIntervalToIndex`; samples per pixel rounded up to a power of two.
//! The generator matrices are made from Joe and Kuo's direction numbers
//! ([`super::sobolmatrices`]). With seed 0 the values are pbrt-v3's
//! (unscrambled); another seed XOR-scrambles each dimension with a hashed
//! word. Past pbrt-v3's 1024 dimensions (where pbrt-v3 stops with a fatal
//! error) values are hashed.

use super::sobolmatrices::{
    sobol_interval_to_index, sobol_matrices, sobol_sample, SobolMatrices, MAX_LOG2_RESOLUTION,
    NUM_SOBOL_DIMENSIONS,
};
use super::{
    count, global_1d_array, global_2d_array, past_arrays, ArrayStore, GlobalSequence,
    SamplerKindEntry, PIXELSAMPLES_16,
};
use crate::geometry::Bounds2i;
use crate::sampling::rng::{hash_to_unit, mix64, ONE_MINUS_EPSILON};
use crate::scene::{ParamSpec, ParamValues, Report, SamplerDesc, SamplerKind, Support};
use glam::{IVec2, Vec2};

pub const PARAMS: &[ParamSpec] = &[PIXELSAMPLES_16];

pub const KIND: SamplerKindEntry = SamplerKindEntry {
    name: "sobol",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "pbrt-v3's global Sobol' sequence (Joe and Kuo's direction numbers), pixelsamples rounded up to a power of two",
    build,
};

fn build(p: &ParamValues, r: &mut dyn Report) -> SamplerDesc {
    SamplerDesc {
        kind: SamplerKind::Sobol,
        pixel_samples: power_of_two(count(p, "pixelsamples", 16, r), "SobolSampler", r),
        sample_pixel_center: false,
    }
}

/// `n` rounded up to a power of two, with pbrt-v3's warning if it changes.
pub(super) fn power_of_two(n: u32, sampler: &str, r: &mut dyn Report) -> u32 {
    let p = n.next_power_of_two();
    if p != n {
        r.warn(
            Some("pixelsamples"),
            format!("Non power-of-two sample count rounded up to {p} for {sampler}."),
            "rounded up",
        );
    }
    p
}

/// First dimension used by sample arrays (GlobalSampler's arrayStartDim).
const ARRAY_START_DIM: u32 = 5;

#[derive(Clone, Debug)]
pub struct SobolSampler {
    t: &'static SobolMatrices,
    spp: u32,
    min: IVec2,
    resolution: i32,
    log2_resolution: u32,
    /// 0: pbrt-v3's unscrambled values.
    seed_hash: u64,
    pixel: IVec2,
    sample_index: u32,
    interval_index: u64,
    dimension: u32,
    array_end_dim: u32,
    pub(super) arrays: ArrayStore,
}

impl SobolSampler {
    /// `spp` is rounded up to a power of two (pbrt-v3's constructor).
    pub fn new(spp: u32, sample_bounds: Bounds2i, seed: u64) -> Self {
        let d = sample_bounds.max - sample_bounds.min;
        let resolution = (d.x.max(d.y).max(1) as u32).next_power_of_two();
        let log2_resolution = resolution.trailing_zeros().min(MAX_LOG2_RESOLUTION);
        Self {
            t: sobol_matrices(),
            spp: spp.max(1).next_power_of_two(),
            min: sample_bounds.min,
            resolution: 1 << log2_resolution,
            log2_resolution,
            seed_hash: if seed == 0 {
                0
            } else {
                mix64(seed ^ 0x536f_626f_6c5f_7363)
            },
            pixel: IVec2::ZERO,
            sample_index: 0,
            interval_index: 0,
            dimension: 0,
            array_end_dim: ARRAY_START_DIM,
            arrays: ArrayStore::default(),
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    pub fn request_1d_array(&mut self, n: u32) {
        self.arrays.request_1d(n, 1);
        self.update_array_end();
    }

    pub fn request_2d_array(&mut self, n: u32) {
        self.arrays.request_2d(n, 1);
        self.update_array_end();
    }

    fn update_array_end(&mut self) {
        self.array_end_dim = ARRAY_START_DIM + self.arrays.dimensions();
    }

    /// pbrt-v3's `GetIndexForSample`: the global index of sample
    /// `sample_num` of the current pixel.
    #[inline]
    pub fn index_for_sample(&self, sample_num: u64) -> u64 {
        let p = self.pixel - self.min;
        sobol_interval_to_index(
            self.t,
            self.log2_resolution,
            sample_num,
            (p.x as u32, p.y as u32),
        )
    }

    /// pbrt-v3's `SampleDimension`.
    #[inline]
    fn sample_dimension(&self, index: u64, dim: u32) -> f32 {
        if dim as usize >= NUM_SOBOL_DIMENSIONS {
            return hash_to_unit(mix64(
                mix64(index ^ self.seed_hash ^ 0x9e37_79b9)
                    .wrapping_add((dim as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)),
            ));
        }
        let scramble = if self.seed_hash == 0 {
            0
        } else {
            mix64(self.seed_hash.wrapping_add(dim as u64)) as u32
        };
        let s = sobol_sample(self.t, index, dim as usize, scramble);
        if dim < 2 {
            let d = dim as usize;
            let s = s * self.resolution as f32 + self.min[d] as f32;
            return (s - self.pixel[d] as f32).clamp(0.0, ONE_MINUS_EPSILON);
        }
        s
    }

    pub fn start_pixel_sample(&mut self, pixel: IVec2, sample_index: u32) {
        self.pixel = pixel;
        self.sample_index = sample_index;
        self.dimension = 0;
        self.interval_index = self.index_for_sample(sample_index as u64);
        self.arrays.reset();
    }

    /// Consumes `n` dimensions below the array dimensions without computing
    /// them.
    #[inline]
    pub fn skip(&mut self, n: u32) {
        debug_assert!(self.dimension + n <= ARRAY_START_DIM);
        self.dimension += n;
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        self.dimension = past_arrays(self.dimension, 1, ARRAY_START_DIM, self.array_end_dim);
        let v = self.sample_dimension(self.interval_index, self.dimension);
        self.dimension += 1;
        v
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        self.dimension = past_arrays(self.dimension, 2, ARRAY_START_DIM, self.array_end_dim);
        let p = Vec2::new(
            self.sample_dimension(self.interval_index, self.dimension),
            self.sample_dimension(self.interval_index, self.dimension + 1),
        );
        self.dimension += 2;
        p
    }

    #[inline]
    pub fn get_1d_array(&mut self, n: u32) -> Option<&[f32]> {
        global_1d_array(self, n)
    }

    #[inline]
    pub fn get_2d_array(&mut self, n: u32) -> Option<&[Vec2]> {
        global_2d_array(self, n)
    }
}

impl GlobalSequence for SobolSampler {
    const ARRAY_START_DIM: u32 = ARRAY_START_DIM;
    #[inline]
    fn arrays(&mut self) -> &mut ArrayStore {
        &mut self.arrays
    }
    #[inline]
    fn sample_index(&self) -> u32 {
        self.sample_index
    }
    #[inline]
    fn index_for_sample(&self, sample_num: u64) -> u64 {
        SobolSampler::index_for_sample(self, sample_num)
    }
    #[inline]
    fn sample_dimension(&mut self, index: u64, dim: u32) -> f32 {
        SobolSampler::sample_dimension(self, index, dim)
    }
}
