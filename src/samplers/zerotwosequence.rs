//! pbrt-v3's `ZeroTwoSequenceSampler` (samplers/zerotwosequence.cpp), also
//! named `lowdiscrepancy`: a pixel sampler ([`super::pixel`]) whose 1D
//! values are the scrambled van der Corput sequence and whose 2D values
//! are the scrambled Sobol' (0,2)-sequence, shuffled per pixel; samples per
//! pixel and array sizes are rounded up to powers of two.

use super::pixel::{Pattern, PixelSampler};
use super::{count, SamplerKindEntry, PIXELSAMPLES_16};
use crate::geometry::Bounds2i;
use crate::scene::{ParamSpec, ParamValues, Report, SamplerDesc, SamplerKind, Support};

/// The most `dimensions` a pixel sampler takes (each is a table of
/// `pixelsamples` values per pixel).
pub const MAX_DIMENSIONS: i32 = 1024;

pub const DIMENSIONS: ParamSpec = ParamSpec::int(
    "dimensions",
    4,
    "1D and 2D dimensions taken from the sampler's pattern (later ones are independent uniform values)",
);

pub const PARAMS: &[ParamSpec] = &[PIXELSAMPLES_16, DIMENSIONS];

pub const KIND: SamplerKindEntry = SamplerKindEntry {
    name: "02sequence",
    aliases: &["lowdiscrepancy"],
    support: Support::Supported,
    params: PARAMS,
    doc: "pbrt-v3's ZeroTwoSequenceSampler: per pixel, scrambled van der Corput (1D) and Sobol' (0,2)-sequence (2D) values, shuffled; pixelsamples and array sizes rounded up to powers of two",
    build,
};

/// The most table entries (`pixelsamples × dimensions`) a pixel sampler
/// makes per pixel (each 1D and 2D, 12 bytes, in every thread's copy).
pub const MAX_TABLE: u64 = 1 << 26;

/// The `dimensions` parameter, checked to be in `min..=MAX_DIMENSIONS` and
/// to keep `spp × dimensions` within [`MAX_TABLE`] (errors otherwise).
pub(super) fn dimensions(p: &ParamValues, min: i32, spp: u32, r: &mut dyn Report) -> u32 {
    let d = p.int("dimensions");
    if !(min..=MAX_DIMENSIONS).contains(&d) {
        r.error(
            Some("dimensions"),
            format!("\"dimensions\" is {d}: it must be between {min} and {MAX_DIMENSIONS}"),
            "out of range",
        );
        return 4;
    }
    if spp as u64 * d as u64 > MAX_TABLE {
        r.error(
            Some("dimensions"),
            format!(
                "pixelsamples × dimensions = {} exceeds {MAX_TABLE} (the per-pixel tables)",
                spp as u64 * d as u64
            ),
            "too many samples",
        );
        return (MAX_TABLE / spp as u64).clamp(1, 4) as u32;
    }
    d as u32
}

fn build(p: &ParamValues, r: &mut dyn Report) -> SamplerDesc {
    let n = count(p, "pixelsamples", 16, r);
    let spp = n.next_power_of_two();
    if spp != n {
        r.warn(
            Some("pixelsamples"),
            format!("Pixel samples being rounded up to power of 2 (from {n} to {spp})."),
            "rounded up",
        );
    }
    SamplerDesc {
        kind: SamplerKind::ZeroTwoSequence {
            dimensions: dimensions(p, 0, spp, r),
        },
        pixel_samples: spp,
        sample_pixel_center: false,
    }
}

/// The sampler for `spp` samples per pixel (rounded up to a power of two).
pub fn sampler(spp: u32, dimensions: u32, sample_bounds: Bounds2i, seed: u64) -> PixelSampler {
    let spp = spp.max(1).next_power_of_two();
    PixelSampler::new(Pattern::ZeroTwo, spp, dimensions, sample_bounds, seed)
}
