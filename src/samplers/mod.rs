//! Samplers: where the sample values of every pixel sample come from.
//!
//! [`Sampler`] is an enum (no dynamic dispatch per sample), `Clone + Send`:
//! each tile clones one. Positioning is stateless: after
//! [`Sampler::start_pixel_sample`]`(pixel, index)` the values returned are a
//! function of (pixel, index, seed) and of the calls made since, never of
//! earlier pixels or of the thread. Every value is in `[0, 1)`.
//!
//! Halton and Sobol' follow pbrt-v3's `GlobalSampler`: one global sequence
//! over the image whose first two dimensions are the pixel position.
//! `02sequence` and `maxmindist` are pbrt-v3's pixel samplers
//! ([`pixel`]), whose per-pixel tables are pbrt-v3's for every pixel.

pub mod halton;
pub mod lowdiscrepancy;
pub mod maxmindist;
pub mod mlt;
pub mod pixel;
pub mod radical_fast;
pub mod random;
pub mod sobol;
pub mod sobol_fast;
pub mod sobolmatrices;
pub mod stratified;
pub mod zerotwosequence;

pub use halton::HaltonSampler;
pub use mlt::MltSampler;
pub use pixel::PixelSampler;
pub use random::RandomSampler;
pub use sobol::SobolSampler;
pub use stratified::StratifiedSampler;

use crate::geometry::Bounds2i;
use crate::sampling::rng::Pcg32;
use crate::scene::{Kind, ParamSpec, ParamValues, Report, SamplerDesc, SamplerKind};
use glam::{IVec2, Vec2};

/// What a sampler kind builds from its parameters: the sampler's settings
/// (a typed struct, since the command line edits them: `--spp`, `--quick`).
pub type SamplerBuild = fn(&ParamValues, &mut dyn Report) -> SamplerDesc;

/// One sampler kind: its pbrt-v3 name, its parameters, its builder.
pub type SamplerKindEntry = Kind<SamplerBuild>;

/// Every sampler pbrt-v3's `MakeSampler` knows (an unknown one is an error).
pub static SAMPLERS: &[SamplerKindEntry] = &[
    halton::KIND,
    random::KIND,
    stratified::KIND,
    sobol::KIND,
    zerotwosequence::KIND,
    maxmindist::KIND,
];

/// The most samples per pixel pbrs takes (each sample index must fit the
/// samplers' 32-bit arithmetic with room to spare).
pub const MAX_SAMPLES: i64 = 1 << 24;

/// A sample count parameter, checked to be in 1..=[`MAX_SAMPLES`]
/// (an error otherwise, and the default).
pub fn count(p: &ParamValues, name: &'static str, default: u32, report: &mut dyn Report) -> u32 {
    let v = p.int(name) as i64;
    if !(1..=MAX_SAMPLES).contains(&v) {
        report.error(
            Some(name),
            format!("sample count \"{name}\" is {v}: it must be between 1 and {MAX_SAMPLES}"),
            "out of range",
        );
        return default;
    }
    v as u32
}

const PIXELSAMPLES_16: ParamSpec = ParamSpec::int("pixelsamples", 16, "samples per pixel");
const DIMENSIONS: ParamSpec = ParamSpec::int(
    "dimensions",
    4,
    "dimensions sampled with the sampler's own pattern (read; pbrs's samplers use their pattern for every dimension)",
);

/// What a camera needs to generate a ray.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct CameraSample {
    /// Position on the film in raster coordinates (pixel + offset in [0,1)).
    pub p_film: Vec2,
    pub p_lens: Vec2,
    pub time: f32,
}

#[derive(Clone, Debug)]
pub enum Sampler {
    Halton(HaltonSampler),
    Random(RandomSampler),
    Stratified(StratifiedSampler),
    Sobol(SobolSampler),
    ZeroTwoSequence(PixelSampler),
    MaxMinDist(PixelSampler),
    /// The `mlt` integrator's primary sample space (no `Sampler` kind).
    Mlt(MltSampler),
}

macro_rules! dispatch {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Sampler::Halton($s) => $e,
            Sampler::Random($s) => $e,
            Sampler::Stratified($s) => $e,
            Sampler::Sobol($s) => $e,
            Sampler::ZeroTwoSequence($s) => $e,
            Sampler::MaxMinDist($s) => $e,
            Sampler::Mlt($s) => $e,
        }
    };
}

/// The array size a sampler of `desc` takes for `n` wanted values
/// (pbrt-v3's `RoundCount`, as [`Sampler::round_count`]).
pub fn round_count(desc: &SamplerDesc, n: u32) -> u32 {
    match desc.kind {
        SamplerKind::ZeroTwoSequence { .. } | SamplerKind::MaxMinDist { .. } => {
            n.max(1).next_power_of_two()
        }
        _ => n,
    }
}

/// Sets the samples per pixel that `--spp` asks for, as the sampler kind
/// takes them: the pixel samplers and `sobol` round up to a power of two
/// (`maxmindist` at most [`maxmindist::MAX_SPP`]). The warning pbrt-v3's
/// constructor gives when the count changes, if it does.
pub fn override_spp(desc: &mut SamplerDesc, n: u32) -> Option<String> {
    let n = n.max(1);
    let (spp, warning) = match desc.kind {
        SamplerKind::Sobol => {
            let p = n.next_power_of_two();
            (p, format!("Non power-of-two sample count rounded up to {p} for SobolSampler."))
        }
        SamplerKind::ZeroTwoSequence { .. } => {
            let p = n.next_power_of_two();
            (p, format!("Pixel samples being rounded up to power of 2 (from {n} to {p})."))
        }
        SamplerKind::MaxMinDist { .. } if n > maxmindist::MAX_SPP => (
            maxmindist::MAX_SPP,
            format!("No more than {} samples per pixel are supported with MaxMinDistSampler. Rounding down.", maxmindist::MAX_SPP),
        ),
        SamplerKind::MaxMinDist { .. } => {
            let p = n.next_power_of_two();
            (p, format!("Non power-of-two sample count rounded up to {p} for MaxMinDistSampler."))
        }
        _ => (n, String::new()),
    };
    desc.pixel_samples = spp;
    (spp != n).then_some(warning)
}

impl Sampler {
    /// Builds the sampler for `desc`. `sample_bounds` is the film's sample
    /// bounds; `seed` changes scrambling and random streams (seed 0 is
    /// pbrt-v3's own values: Halton's permutations, Sobol' unscrambled, the
    /// pixel samplers' tile RNGs).
    pub fn new(desc: &SamplerDesc, sample_bounds: Bounds2i, seed: u64) -> Sampler {
        let spp = desc.pixel_samples.max(1);
        match desc.kind {
            SamplerKind::Random => Sampler::Random(RandomSampler::new(spp, seed)),
            SamplerKind::Stratified {
                jitter,
                xsamples,
                ysamples,
            } => Sampler::Stratified(StratifiedSampler::new(
                xsamples, ysamples, spp, jitter, seed,
            )),
            SamplerKind::Halton => Sampler::Halton(HaltonSampler::new(
                spp,
                sample_bounds,
                desc.sample_pixel_center,
                seed,
            )),
            SamplerKind::Sobol => Sampler::Sobol(SobolSampler::new(spp, sample_bounds, seed)),
            SamplerKind::ZeroTwoSequence { dimensions } => Sampler::ZeroTwoSequence(
                zerotwosequence::sampler(spp, dimensions, sample_bounds, seed),
            ),
            SamplerKind::MaxMinDist { dimensions } => {
                Sampler::MaxMinDist(maxmindist::sampler(spp, dimensions, sample_bounds, seed))
            }
        }
    }

    pub fn samples_per_pixel(&self) -> u32 {
        dispatch!(self, s => s.samples_per_pixel())
    }

    /// Bytes this copy of the sampler holds on the heap (its array store
    /// and the pixel samplers' tables; Halton's permutation tables and the
    /// Sobol' matrices are shared and not counted).
    pub fn heap_bytes(&self) -> usize {
        let a = dispatch!(self, s => &s.arrays);
        let tables = match self {
            Sampler::ZeroTwoSequence(s) | Sampler::MaxMinDist(s) => s.table_bytes(),
            _ => 0,
        };
        a.data_1d.iter().map(|v| v.len() * 4).sum::<usize>()
            + a.data_2d.iter().map(|v| v.len() * 8).sum::<usize>()
            + tables
    }

    /// Asks for an array of `n` 1D values per sample. Call before rendering,
    /// in the same order as the later `get_1d_array` calls.
    pub fn request_1d_array(&mut self, n: u32) {
        dispatch!(self, s => s.request_1d_array(n))
    }

    pub fn request_2d_array(&mut self, n: u32) {
        dispatch!(self, s => s.request_2d_array(n))
    }

    /// The array size to request for `n` wanted values (pbrt-v3's
    /// `RoundCount`: a power of two for the pixel samplers, `n` otherwise).
    pub fn round_count(&self, n: u32) -> u32 {
        match self {
            Sampler::ZeroTwoSequence(s) | Sampler::MaxMinDist(s) => s.round_count(n),
            _ => n,
        }
    }

    /// Positions the sampler at sample `sample_index` of `pixel`.
    #[inline]
    pub fn start_pixel_sample(&mut self, pixel: IVec2, sample_index: u32) {
        dispatch!(self, s => s.start_pixel_sample(pixel, sample_index))
    }

    /// `start_pixel_sample`, taking what the sampler computes once per
    /// pixel from `at_pixel`, a sampler of the same kind already started at
    /// `pixel` (so that the lanes of a batch do not each compute it again).
    #[inline]
    pub fn start_pixel_sample_from(&mut self, at_pixel: &Sampler, pixel: IVec2, sample_index: u32) {
        if let (Sampler::Halton(h), Sampler::Halton(p)) = (&mut *self, at_pixel) {
            h.take_pixel_offset(p);
        }
        self.start_pixel_sample(pixel, sample_index)
    }

    /// Whether lanes of a batch can each have a copy of this sampler at a
    /// modest cost per pixel: not the stratified and pixel samplers, which
    /// compute every sample of a pixel when they start one.
    pub fn batches_well(&self) -> bool {
        !matches!(
            self,
            Sampler::Stratified(_) | Sampler::ZeroTwoSequence(_) | Sampler::MaxMinDist(_)
        )
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        dispatch!(self, s => s.get_1d())
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        dispatch!(self, s => s.get_2d())
    }

    /// Consumes a 2D sample whose value is not needed (a BSDF with no lobe
    /// that would read it): the sampler is left where `get_2d` leaves it.
    #[inline]
    pub fn skip_2d(&mut self) {
        match self {
            Sampler::Halton(h) => h.skip_2d(),
            Sampler::ZeroTwoSequence(p) | Sampler::MaxMinDist(p) => p.skip_2d(),
            _ => {
                let _ = self.get_2d();
            }
        }
    }

    /// pbrt-v3's order: `p_film = pixel + get_2d()`, `time = get_1d()`,
    /// `p_lens = get_2d()`. Call right after `start_pixel_sample`.
    #[inline]
    pub fn get_camera_sample(&mut self, pixel: IVec2) -> CameraSample {
        self.camera_sample(pixel, true)
    }

    /// As `get_camera_sample`; with `lens == false` the time and lens
    /// dimensions are consumed (later dimensions are the same) but their
    /// values are not computed (Halton, Sobol') and read 0.5: for a pinhole
    /// camera without motion, which never reads them.
    #[inline(always)]
    pub fn camera_sample(&mut self, pixel: IVec2, lens: bool) -> CameraSample {
        let base = pixel.as_vec2();
        // Keep p_film inside the pixel even when `pixel + offset` rounds up.
        let top = Vec2::new(next_below(base.x + 1.0), next_below(base.y + 1.0));
        let p_film = (base + self.get_2d()).min(top);
        let (time, p_lens) = match self {
            Sampler::Halton(h) if !lens => {
                h.skip(3);
                (0.5, Vec2::splat(0.5))
            }
            Sampler::Sobol(h) if !lens => {
                h.skip(3);
                (0.5, Vec2::splat(0.5))
            }
            _ => {
                let time = self.get_1d();
                (time, self.get_2d())
            }
        };
        CameraSample {
            p_film,
            p_lens,
            time,
        }
    }

    /// The next requested 1D array, if it has `n` entries; `None` once all
    /// requested arrays were consumed for this sample (or on a size mismatch).
    #[inline]
    pub fn get_1d_array(&mut self, n: u32) -> Option<&[f32]> {
        dispatch!(self, s => s.get_1d_array(n))
    }

    #[inline]
    pub fn get_2d_array(&mut self, n: u32) -> Option<&[Vec2]> {
        dispatch!(self, s => s.get_2d_array(n))
    }

    /// The next requested 2D array's one value, if the next array has one
    /// entry (as `get_2d_array(1)`, without a copy: Halton computes it
    /// straight away).
    #[inline]
    pub fn get_2d_array1(&mut self) -> Option<Vec2> {
        if let Sampler::Halton(h) = self {
            return h.get_2d_array1();
        }
        self.get_2d_array(1).map(|a| a[0])
    }

    /// The next `out.len()` requested 2D arrays' values if each has one
    /// entry (what as many `get_2d_array1` calls give, Halton's computed
    /// together); false, with nothing consumed, otherwise (and always for
    /// the other samplers, whose callers then take them one by one).
    #[inline]
    pub fn get_2d_arrays1(&mut self, out: &mut [Vec2]) -> bool {
        match self {
            Sampler::Halton(h) => h.get_2d_arrays1(out),
            _ => false,
        }
    }

    /// Consumes the next requested 2D array as [`Sampler::fill_2d_array`]
    /// does, for a caller that does not read its values (a delta light's
    /// sample): the same answer and the sampler left in the same state, but
    /// the pixel samplers do not make the array (their RNG has already
    /// stepped past it); the other samplers fill `out` as `fill_2d_array`.
    #[inline]
    pub fn skip_2d_array(&mut self, n: u32, out: &mut Vec<Vec2>) -> bool {
        match self {
            Sampler::ZeroTwoSequence(p) | Sampler::MaxMinDist(p) => p.skip_2d_array(n),
            _ => self.fill_2d_array_apart(n, out),
        }
    }

    /// [`Sampler::fill_2d_array`] out of line, so that `skip_2d_array`'s
    /// callers stay small.
    #[inline(never)]
    fn fill_2d_array_apart(&mut self, n: u32, out: &mut Vec<Vec2>) -> bool {
        self.fill_2d_array(n, out)
    }

    /// `get_2d_array` copied into `out` (cleared first): true if there was
    /// an array, else `out` stays empty. Halton computes the values straight
    /// into `out`.
    #[inline]
    pub fn fill_2d_array(&mut self, n: u32, out: &mut Vec<Vec2>) -> bool {
        if let Sampler::Halton(h) = self {
            return h.fill_2d_array(n, out);
        }
        out.clear();
        match self.get_2d_array(n) {
            Some(a) => {
                out.extend_from_slice(a);
                true
            }
            None => false,
        }
    }
}

/// The largest `f32` below `x` (for finite, positive-step values).
#[inline]
fn next_below(x: f32) -> f32 {
    if x > 0.0 {
        f32::from_bits(x.to_bits() - 1)
    } else if x == 0.0 {
        -f32::from_bits(1)
    } else {
        f32::from_bits(x.to_bits() + 1)
    }
}

/// pbrt-v3's `GlobalSampler`, for the sample arrays: a sequence whose values
/// are indexed by a global sample number, where entry k of the current
/// sample's array of n values is the pixel's sample `sample_index · n + k`
/// (as `GlobalSampler::StartPixel` lays them out), at the array's
/// dimensions from `ARRAY_START_DIM` on (the 1D arrays first, then two
/// dimensions per 2D array). Halton and Sobol' answer it.
pub(crate) trait GlobalSequence {
    /// The first dimension of the sample arrays (pbrt-v3's `arrayStartDim`).
    const ARRAY_START_DIM: u32;
    fn arrays(&mut self) -> &mut ArrayStore;
    /// The index of the current sample in its pixel.
    fn sample_index(&self) -> u32;
    /// The global index of the pixel's sample `sample_num`.
    fn index_for_sample(&self, sample_num: u64) -> u64;
    /// Dimension `dim` of the global sample `index`.
    fn sample_dimension(&mut self, index: u64, dim: u32) -> f32;
    /// The 2D array entries at dimensions `dim`, `dim + 1` of the samples
    /// `index_for_sample(first + k)` into `out[k]` (a sequence may compute
    /// several at once, with these values).
    #[inline]
    fn array_2d_values(&mut self, dim: u32, first: u64, out: &mut [Vec2]) {
        for (k, v) in out.iter_mut().enumerate() {
            let index = self.index_for_sample(first + k as u64);
            *v = Vec2::new(
                self.sample_dimension(index, dim),
                self.sample_dimension(index, dim + 1),
            );
        }
    }
}

/// The current sample's next 1D array of `n` values of a global sequence.
#[inline]
pub(crate) fn global_1d_array<S: GlobalSequence>(s: &mut S, n: u32) -> Option<&[f32]> {
    let i = s.arrays().next_1d;
    if s.arrays().sizes_1d.get(i) == Some(&n) {
        let mut data = std::mem::take(&mut s.arrays().data_1d[i]);
        let first = s.sample_index() as u64 * n as u64;
        for (k, v) in data.iter_mut().enumerate() {
            let index = s.index_for_sample(first + k as u64);
            *v = s.sample_dimension(index, S::ARRAY_START_DIM + i as u32);
        }
        s.arrays().data_1d[i] = data;
    }
    s.arrays().get_1d(n, 0)
}

/// The current sample's next 2D array of `n` values of a global sequence.
#[inline]
pub(crate) fn global_2d_array<S: GlobalSequence>(s: &mut S, n: u32) -> Option<&[Vec2]> {
    let i = s.arrays().next_2d;
    if s.arrays().sizes_2d.get(i) == Some(&n) {
        let mut data = std::mem::take(&mut s.arrays().data_2d[i]);
        let dim = S::ARRAY_START_DIM + s.arrays().sizes_1d.len() as u32 + 2 * i as u32;
        let first = s.sample_index() as u64 * n as u64;
        s.array_2d_values(dim, first, &mut data);
        s.arrays().data_2d[i] = data;
    }
    s.arrays().get_2d(n, 0)
}

/// pbrt-v3's `GlobalSampler::Get1D`/`Get2D`: the dimension at which the
/// next `width` (1 or 2) values start, moved past the sample arrays'
/// dimensions `[start, end)` when they would overlap them.
#[inline(always)]
pub(crate) fn past_arrays(dimension: u32, width: u32, start: u32, end: u32) -> u32 {
    if dimension + width > start && dimension < end {
        end
    } else {
        dimension
    }
}

/// Requested sample arrays and their current contents.
#[derive(Clone, Debug, Default)]
pub(crate) struct ArrayStore {
    pub sizes_1d: Vec<u32>,
    pub sizes_2d: Vec<u32>,
    /// Each holds `size * copies` values: `copies` is 1 for samplers that fill
    /// arrays per sample, `spp` for those that fill them per pixel.
    pub data_1d: Vec<Vec<f32>>,
    pub data_2d: Vec<Vec<Vec2>>,
    pub next_1d: usize,
    pub next_2d: usize,
    /// For samplers that make a pixel's arrays when a sample first reads
    /// them: each array's RNG where its values begin, while not made yet.
    pub unmade_1d: Vec<Option<Pcg32>>,
    pub unmade_2d: Vec<Option<Pcg32>>,
}

impl ArrayStore {
    /// The dimensions the requested arrays take: one per 1D array, two
    /// per 2D array.
    pub fn dimensions(&self) -> u32 {
        self.sizes_1d.len() as u32 + 2 * self.sizes_2d.len() as u32
    }

    pub fn request_1d(&mut self, n: u32, copies: u32) {
        self.sizes_1d.push(n);
        self.unmade_1d.push(None);
        self.data_1d.push(vec![0.0; n as usize * copies as usize]);
    }

    pub fn request_2d(&mut self, n: u32, copies: u32) {
        self.sizes_2d.push(n);
        self.unmade_2d.push(None);
        self.data_2d
            .push(vec![Vec2::ZERO; n as usize * copies as usize]);
    }

    /// The next 1D array, if it has `n` values and is not made yet: its
    /// storage and the RNG to make it with.
    #[inline]
    pub fn unmade_1d(&mut self, n: u32) -> Option<(&mut [f32], Pcg32)> {
        let i = self.next_1d;
        if self.sizes_1d.get(i) != Some(&n) {
            return None;
        }
        let rng = self.unmade_1d[i].take()?;
        Some((&mut self.data_1d[i], rng))
    }

    /// The next 2D array, if it has `n` values and is not made yet.
    #[inline]
    pub fn unmade_2d(&mut self, n: u32) -> Option<(&mut [Vec2], Pcg32)> {
        let i = self.next_2d;
        if self.sizes_2d.get(i) != Some(&n) {
            return None;
        }
        let rng = self.unmade_2d[i].take()?;
        Some((&mut self.data_2d[i], rng))
    }

    #[inline]
    pub fn reset(&mut self) {
        self.next_1d = 0;
        self.next_2d = 0;
    }

    #[inline]
    pub fn get_1d(&mut self, n: u32, copy: usize) -> Option<&[f32]> {
        let i = self.next_1d;
        if i >= self.sizes_1d.len() || self.sizes_1d[i] != n {
            return None;
        }
        self.next_1d += 1;
        let start = copy * n as usize;
        self.data_1d[i].get(start..start + n as usize)
    }

    #[inline]
    pub fn get_2d(&mut self, n: u32, copy: usize) -> Option<&[Vec2]> {
        let i = self.next_2d;
        if i >= self.sizes_2d.len() || self.sizes_2d[i] != n {
            return None;
        }
        self.next_2d += 1;
        let start = copy * n as usize;
        self.data_2d[i].get(start..start + n as usize)
    }

    /// [`ArrayStore::get_2d`]'s answer (whether it would give values) and
    /// its step to the next array, without reading the array.
    #[inline]
    pub fn skip_2d(&mut self, n: u32, copy: usize) -> bool {
        let i = self.next_2d;
        if i >= self.sizes_2d.len() || self.sizes_2d[i] != n {
            return false;
        }
        self.next_2d += 1;
        let start = copy * n as usize;
        start + n as usize <= self.data_2d[i].len()
    }
}
