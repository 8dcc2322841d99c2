//! pbrt-v3's `HaltonSampler` (samplers/halton.cpp) with `GlobalSampler`'s
//! dimension and array handling (core/sampler.cpp).

use super::lowdiscrepancy::{
    inverse_radical_inverse, multiplicative_inverse, radical_inverse_base2, radical_inverse_base3,
    DigitBase, PermutationTables, BLOCK_DIM_END, BLOCK_LANES, PRIME_TABLE_SIZE,
};
use super::{
    count, global_1d_array, global_2d_array, past_arrays, ArrayStore, GlobalSequence,
    SamplerKindEntry, PIXELSAMPLES_16,
};
use crate::geometry::Bounds2i;
use crate::sampling::rng::{hash_to_unit, mix64};
use crate::scene::{ParamSpec, SamplerDesc, SamplerKind, Support};
use glam::{IVec2, Vec2};
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    PIXELSAMPLES_16,
    ParamSpec::boolean(
        "samplepixelcenter",
        false,
        "every sample at the pixel's centre (no antialiasing)",
    ),
];

pub const KIND: SamplerKindEntry = SamplerKindEntry {
    name: "halton",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "pbrt-v3's global Halton sequence with its random digit permutations (past pbrt-v3's 1000 dimensions, hashed values)",
    build: |p, r| SamplerDesc {
        kind: SamplerKind::Halton,
        pixel_samples: count(p, "pixelsamples", 16, r),
        sample_pixel_center: p.boolean("samplepixelcenter"),
    },
};

/// Resolution at which the pixel-position dimensions repeat (pbrt-v3's kMaxResolution).
const MAX_RESOLUTION: i32 = 128;
/// First dimension used by sample arrays (GlobalSampler's arrayStartDim).
const ARRAY_START_DIM: u32 = 5;

#[derive(Clone, Debug)]
pub struct HaltonSampler {
    tables: Arc<PermutationTables>,
    spp: u32,
    seed_hash: u64,
    sample_at_pixel_center: bool,
    base_scales: [u64; 2],
    /// `base_scales[1]` for fast division; `None` when it is 1 (a film one
    /// pixel high), which `DigitBase` does not take.
    scale1: Option<DigitBase>,
    base_exponents: [u32; 2],
    sample_stride: u64,
    mult_inverse: [u64; 2],
    // Per-pixel cache of GetIndexForSample's offset.
    pixel_for_offset: Option<IVec2>,
    offset_for_pixel: u64,
    // Current sample.
    sample_index: u32,
    interval_index: u64,
    dimension: u32,
    array_end_dim: u32,
    pub(super) arrays: ArrayStore,
    /// Dimensions `block_dim ..` of index `block_index`, computed
    /// `BLOCK_LANES` at a time (`block_len` of them valid; 0 when empty).
    block: [f32; BLOCK_LANES],
    block_dim: u32,
    block_len: u32,
    block_index: u64,
}

impl HaltonSampler {
    pub fn new(spp: u32, sample_bounds: Bounds2i, sample_at_pixel_center: bool, seed: u64) -> Self {
        let res = sample_bounds.max - sample_bounds.min;
        let mut base_scales = [1u64; 2];
        let mut base_exponents = [0u32; 2];
        for i in 0..2 {
            let base = if i == 0 { 2 } else { 3 };
            let (mut scale, mut exp) = (1i32, 0u32);
            while scale < res[i].min(MAX_RESOLUTION) {
                scale *= base;
                exp += 1;
            }
            base_scales[i] = scale as u64;
            base_exponents[i] = exp;
        }
        let sample_stride = base_scales[0] * base_scales[1];
        let mult_inverse = [
            multiplicative_inverse(base_scales[1] as i64, base_scales[0] as i64),
            multiplicative_inverse(base_scales[0] as i64, base_scales[1] as i64),
        ];
        Self {
            tables: PermutationTables::shared(seed),
            spp: spp.max(1),
            seed_hash: mix64(seed ^ 0x4a61_6c74_6f6e_5f68),
            sample_at_pixel_center,
            base_scales,
            scale1: (base_scales[1] > 1).then(|| DigitBase::new(base_scales[1] as u32)),
            base_exponents,
            sample_stride,
            mult_inverse,
            pixel_for_offset: None,
            offset_for_pixel: 0,
            sample_index: 0,
            interval_index: 0,
            dimension: 0,
            array_end_dim: ARRAY_START_DIM,
            arrays: ArrayStore::default(),
            block: [0.0; BLOCK_LANES],
            block_dim: 0,
            block_len: 0,
            block_index: 0,
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

    /// pbrt-v3's `GetIndexForSample`: the global index of sample `sample_num`
    /// of the current pixel.
    #[inline]
    fn index_for_sample(&self, sample_num: u64) -> u64 {
        self.offset_for_pixel + sample_num * self.sample_stride
    }

    fn compute_pixel_offset(&mut self, pixel: IVec2) {
        let mut offset = 0u64;
        if self.sample_stride > 1 {
            let pm = [
                pixel.x.rem_euclid(MAX_RESOLUTION),
                pixel.y.rem_euclid(MAX_RESOLUTION),
            ];
            for (i, &pm_i) in pm.iter().enumerate() {
                let base = if i == 0 { 2 } else { 3 };
                let dim_offset = inverse_radical_inverse(base, pm_i as u64, self.base_exponents[i]);
                offset +=
                    dim_offset * (self.sample_stride / self.base_scales[i]) * self.mult_inverse[i];
            }
            offset %= self.sample_stride;
        }
        self.offset_for_pixel = offset;
        self.pixel_for_offset = Some(pixel);
    }

    /// pbrt-v3's `SampleDimension`, extended past the last prime with
    /// hashed values.
    #[inline]
    fn sample_dimension(&mut self, index: u64, dim: u32) -> f32 {
        if self.sample_at_pixel_center && dim < 2 {
            return 0.5;
        }
        match dim {
            0 => radical_inverse_base2(index >> self.base_exponents[0]),
            1 => radical_inverse_base3(self.scale1.as_ref().map_or(index, |s| s.div(index))),
            d if (d as usize) < PRIME_TABLE_SIZE => self.scrambled(index, d),
            d => hash_to_unit(mix64(
                mix64(index ^ self.seed_hash)
                    .wrapping_add((d as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)),
            )),
        }
    }

    /// Scrambled dimension `dim` (2 ..< PRIME_TABLE_SIZE) at `index`, from
    /// the block of `BLOCK_LANES` consecutive dimensions computed together
    /// (the dimensions of one sample are used in order, so a block serves
    /// the next several calls); bit-identical to `tables.scrambled`. Only
    /// the current sample's own index uses blocks: array entries past the
    /// first have indices of their own and take one dimension each.
    #[inline]
    fn scrambled(&mut self, index: u64, dim: u32) -> f32 {
        let k = dim.wrapping_sub(self.block_dim);
        if k < self.block_len && index == self.block_index {
            return self.block[k as usize];
        }
        if (dim as usize) < BLOCK_DIM_END
            && index == self.interval_index
            && index <= u32::MAX as u64
        {
            self.tables
                .scrambled_block(dim as usize, index, &mut self.block);
            self.block_dim = dim;
            self.block_len = (BLOCK_DIM_END - dim as usize).min(BLOCK_LANES) as u32;
            self.block_index = index;
            return self.block[0];
        }
        self.tables.scrambled(dim as usize, index)
    }

    /// Dimensions `dim` and `dim + 1` at `index` (one call for both).
    #[inline(never)]
    fn sample_2d_dimensions(&mut self, index: u64, dim: u32) -> Vec2 {
        if dim >= 2 && ((dim + 1) as usize) < PRIME_TABLE_SIZE {
            Vec2::new(self.scrambled(index, dim), self.scrambled(index, dim + 1))
        } else {
            Vec2::new(
                self.sample_dimension(index, dim),
                self.sample_dimension(index, dim + 1),
            )
        }
    }

    /// Takes `other`'s cached pixel offset (a copy of the same sampler).
    #[inline]
    pub fn take_pixel_offset(&mut self, other: &HaltonSampler) {
        self.pixel_for_offset = other.pixel_for_offset;
        self.offset_for_pixel = other.offset_for_pixel;
    }

    pub fn start_pixel_sample(&mut self, pixel: IVec2, sample_index: u32) {
        if self.pixel_for_offset != Some(pixel) {
            self.compute_pixel_offset(pixel);
        }
        self.sample_index = sample_index;
        self.dimension = 0;
        self.interval_index = self.index_for_sample(sample_index as u64);
        // Arrays are filled when asked for (integrators request arrays for
        // every depth, but most paths end long before using them all).
        self.arrays.reset();
    }

    /// Consumes `n` dimensions below the array dimensions without computing
    /// them.
    #[inline]
    pub fn skip(&mut self, n: u32) {
        debug_assert!(self.dimension + n <= ARRAY_START_DIM);
        self.dimension += n;
    }

    /// Consumes the dimensions `get_2d` would, without computing them.
    #[inline]
    pub fn skip_2d(&mut self) {
        self.dimension = past_arrays(self.dimension, 2, ARRAY_START_DIM, self.array_end_dim);
        self.dimension += 2;
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
        let p = self.sample_2d_dimensions(self.interval_index, self.dimension);
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

    /// `get_2d_array` written into `out` (cleared first) without going
    /// through the array store; false (and `out` empty) where it gives None.
    #[inline]
    pub fn fill_2d_array(&mut self, n: u32, out: &mut Vec<Vec2>) -> bool {
        out.clear();
        let Some((dim, first)) = self.next_2d_array(n) else {
            return false;
        };
        out.resize(n as usize, Vec2::ZERO);
        self.array_2d_values(dim, first, out);
        true
    }

    /// `fill_2d_array(1, ..)`'s value without the vector.
    #[inline]
    pub fn get_2d_array1(&mut self) -> Option<Vec2> {
        let (dim, first) = self.next_2d_array(1)?;
        Some(self.sample_2d_dimensions(self.index_for_sample(first), dim))
    }

    /// The next `out.len()` requested 2D arrays' values, if each of them
    /// has one entry: the same values, in the same order, as that many
    /// `get_2d_array1` calls, computed together (their dimensions are
    /// consecutive, so one block of eight dimensions serves four arrays).
    /// False, with nothing consumed, if any of them is missing or larger.
    #[inline]
    pub fn get_2d_arrays1(&mut self, out: &mut [Vec2]) -> bool {
        let i = self.arrays.next_2d;
        let n = out.len();
        if !self
            .arrays
            .sizes_2d
            .get(i..i + n)
            .is_some_and(|s| s.iter().all(|&k| k == 1))
        {
            return false;
        }
        self.arrays.next_2d += n;
        let dim = ARRAY_START_DIM + self.arrays.sizes_1d.len() as u32 + 2 * i as u32;
        // Entry 0 of each array is the current sample's own index.
        let index = self.interval_index;
        if 2 * n <= BLOCK_LANES
            && dim >= 2
            && dim as usize + 2 * n <= BLOCK_DIM_END
            && index <= u32::MAX as u64
        {
            let mut block = [0.0; BLOCK_LANES];
            self.tables.scrambled_block(dim as usize, index, &mut block);
            for (k, v) in out.iter_mut().enumerate() {
                *v = Vec2::new(block[2 * k], block[2 * k + 1]);
            }
        } else {
            for (k, v) in out.iter_mut().enumerate() {
                *v = self.sample_2d_dimensions(index, dim + 2 * k as u32);
            }
        }
        true
    }

    /// Consumes the next requested 2D array if it has `n` entries: its
    /// first dimension and the pixel sample number of its first entry.
    #[inline]
    fn next_2d_array(&mut self, n: u32) -> Option<(u32, u64)> {
        let i = self.arrays.next_2d;
        if i >= self.arrays.sizes_2d.len() || self.arrays.sizes_2d[i] != n {
            return None;
        }
        self.arrays.next_2d += 1;
        let dim = ARRAY_START_DIM + self.arrays.sizes_1d.len() as u32 + 2 * i as u32;
        Some((dim, self.sample_index as u64 * n as u64))
    }

    /// The global Halton index of the current sample (for tests and debugging).
    pub fn global_index(&self) -> u64 {
        self.interval_index
    }

    /// The current dimension (next one `get_1d` would use, before array skipping).
    pub fn dimension(&self) -> u32 {
        self.dimension
    }
}

impl GlobalSequence for HaltonSampler {
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
        HaltonSampler::index_for_sample(self, sample_num)
    }
    #[inline]
    fn sample_dimension(&mut self, index: u64, dim: u32) -> f32 {
        HaltonSampler::sample_dimension(self, index, dim)
    }

    /// The 2D array entries at dimensions `dim`, `dim + 1` of the sample
    /// indices `index_for_sample(first + k)` into `out[k]`: bit for bit
    /// `sample_2d_dimensions` entry by entry, with four entries' indices in
    /// the SIMD lanes of each dimension where the dimensions are block
    /// dimensions and the indices fit 32 bits.
    fn array_2d_values(&mut self, dim: u32, first: u64, out: &mut [Vec2]) {
        let n = out.len() as u64;
        let lanes = n >= 2
            && dim >= 2
            && (dim as usize + 1) < BLOCK_DIM_END
            && self.index_for_sample(first + n - 1) <= u32::MAX as u64;
        if !lanes {
            for (k, v) in out.iter_mut().enumerate() {
                *v = self.sample_2d_dimensions(self.index_for_sample(first + k as u64), dim);
            }
            return;
        }
        // Four entries at a time, both dimensions in one call (the last
        // group's spare lanes repeat its last index).
        let dims = [dim as usize, dim as usize + 1];
        let mut v = [0f32; BLOCK_LANES];
        for (c, group) in out.chunks_mut(BLOCK_LANES / 2).enumerate() {
            let k0 = first + (c * BLOCK_LANES / 2) as u64;
            let last = group.len() as u64 - 1;
            let a: [u32; BLOCK_LANES] = std::array::from_fn(|j| {
                self.index_for_sample(k0 + ((j % (BLOCK_LANES / 2)) as u64).min(last)) as u32
            });
            self.tables.scrambled_indices(dims, &a, &mut v);
            for (j, e) in group.iter_mut().enumerate() {
                *e = Vec2::new(v[j], v[BLOCK_LANES / 2 + j]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2D array's entries computed in lanes are, bit for bit, the
    /// entries one by one (`sample_2d_dimensions` at each entry's index):
    /// arrays of 1 to 37 entries after 1D arrays, small films (indices in
    /// 32 bits, the lanes) and a huge one (indices past 2^32, one by one),
    /// both seeds' tables.
    #[test]
    fn arrays_in_lanes_are_the_entries_one_by_one() {
        let sizes = [1u32, 2, 3, 4, 5, 8, 13, 37];
        for (res, spp, seed) in [(24, 16, 0u64), (300, 64, 5), (1 << 16, 4096, 0)] {
            let bounds = Bounds2i::new(IVec2::ZERO, IVec2::splat(res));
            let mut s = HaltonSampler::new(spp, bounds, false, seed);
            s.request_1d_array(3);
            for &n in &sizes {
                s.request_2d_array(n);
            }
            let mut wide = 0;
            for (pixel, index) in [(0, 0), (7, 1), (res - 1, spp - 1), (res / 3, spp / 2)] {
                let pixel = IVec2::new(pixel, res - 1 - pixel);
                s.start_pixel_sample(pixel, index);
                let _ = s.get_1d_array(3);
                for (i, &n) in sizes.iter().enumerate() {
                    let dim = ARRAY_START_DIM + 1 + 2 * i as u32;
                    let first = index as u64 * n as u64;
                    let mut one = s.clone();
                    let expected: Vec<Vec2> = (0..n as u64)
                        .map(|k| one.sample_2d_dimensions(one.index_for_sample(first + k), dim))
                        .collect();
                    wide += usize::from(s.index_for_sample(first + n as u64 - 1) > u32::MAX as u64);
                    let got = s.get_2d_array(n).expect("requested").to_vec();
                    let bits = |v: &[Vec2]| {
                        v.iter()
                            .map(|p| (p.x.to_bits(), p.y.to_bits()))
                            .collect::<Vec<_>>()
                    };
                    assert_eq!(
                        bits(&got),
                        bits(&expected),
                        "res {res} pixel {pixel} sample {index} n {n}"
                    );
                }
            }
            assert_eq!(
                wide > 0,
                res == 1 << 16,
                "indices past 32 bits at res {res}"
            );
        }
    }
}
