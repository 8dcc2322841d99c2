//! pbrt-v3's `MaxMinDistSampler` (samplers/maxmin.{h,cpp}): the pixel
//! sampler of `02sequence` ([`super::pixel`]) whose first 2D dimension is
//! `(i / spp, C · i)` for Grünschloß and Keller's max-min-distance
//! generator matrix `C` of the sample count, shuffled; samples per pixel
//! rounded up to a power of two, at most 2^16.
//!
//! The matrices are from L. Grünschloß, J. Hanika, R. Schwede and
//! A. Keller, "(t, m, s)-Nets and Maximized Minimum Distance" (Monte Carlo
//! and Quasi-Monte Carlo Methods 2006, Springer 2008), as pbrt-v3
//! transcribed them (core/lowdiscrepancy.cpp `CMaxMinDist`: columns of the
//! published matrices, each column's bits reversed so that bit 31 is the
//! first digit). No published machine-readable source of the matrices other
//! than pbrt-v3's file was found, so these are pbrt-v3's values (see
//! `data/README.md`); matrix 1 (2 samples) is pbrt-v3's as it is, with its
//! only column set in position 31.

use super::pixel::{Pattern, PixelSampler};
use super::zerotwosequence::{dimensions, DIMENSIONS};
use super::{count, SamplerKindEntry, PIXELSAMPLES_16};
use crate::geometry::Bounds2i;
use crate::scene::{ParamSpec, ParamValues, Report, SamplerDesc, SamplerKind, Support};

pub const PARAMS: &[ParamSpec] = &[PIXELSAMPLES_16, DIMENSIONS];

pub const KIND: SamplerKindEntry = SamplerKindEntry {
    name: "maxmindist",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "pbrt-v3's MaxMinDistSampler: Grünschloß and Keller's max-min-distance matrices for the first 2D dimension, as 02sequence otherwise; pixelsamples rounded up to a power of two, at most 65536",
    build,
};

/// The most samples per pixel (one matrix per power of two up to 2^16).
pub const MAX_SPP: u32 = 1 << (MATRICES.len() - 1);

fn build(p: &ParamValues, r: &mut dyn Report) -> SamplerDesc {
    let mut n = count(p, "pixelsamples", 16, r);
    if n > MAX_SPP {
        r.warn(
            Some("pixelsamples"),
            format!("No more than {MAX_SPP} samples per pixel are supported with MaxMinDistSampler. Rounding down."),
            "rounded down",
        );
        n = MAX_SPP;
    }
    let spp = n.next_power_of_two();
    if spp != n {
        r.warn(
            Some("pixelsamples"),
            format!("Non power-of-two sample count rounded up to {spp} for MaxMinDistSampler."),
            "rounded up",
        );
    }
    SamplerDesc {
        kind: SamplerKind::MaxMinDist {
            dimensions: dimensions(p, 1, spp, r),
        },
        pixel_samples: spp,
        sample_pixel_center: false,
    }
}

/// The sampler for `spp` samples per pixel (rounded up to a power of two,
/// at most [`MAX_SPP`]) and at least one dimension.
pub fn sampler(spp: u32, dimensions: u32, sample_bounds: Bounds2i, seed: u64) -> PixelSampler {
    let spp = spp.clamp(1, MAX_SPP).next_power_of_two();
    let c = &MATRICES[spp.trailing_zeros() as usize];
    PixelSampler::new(
        Pattern::MaxMinDist(c),
        spp,
        dimensions.max(1),
        sample_bounds,
        seed,
    )
}

/// 32 columns from the listed first ones (the rest zero).
const fn cols(c: &[u32]) -> [u32; 32] {
    let mut out = [0u32; 32];
    let mut i = 0;
    while i < c.len() {
        out[i] = c[i];
        i += 1;
    }
    out
}

/// `MATRICES[k]`: the generator matrix for `2^k` samples, by columns.
pub static MATRICES: [[u32; 32]; 17] = [
    cols(&[]),
    cols(&[
        0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000,
        0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000,
        0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000,
        0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000, 0x00000000,
        0x00000000, 0x00000000, 0x00000000, 0x80000000,
    ]),
    cols(&[0xc0000000, 0x80000000]),
    cols(&[0xa0000000, 0x40000000, 0x80000000]),
    cols(&[0xc0000000, 0x50000000, 0x20000000, 0x30000000]),
    cols(&[0x88000000, 0x58000000, 0x20000000, 0x40000000, 0x80000000]),
    cols(&[
        0xe0000000, 0x60000000, 0x28000000, 0x10000000, 0x18000000, 0x04000000,
    ]),
    cols(&[
        0x82000000, 0x44000000, 0x2c000000, 0x10000000, 0x20000000, 0x40000000, 0x80000000,
    ]),
    cols(&[
        0x80000000, 0x70000000, 0x30000000, 0x14000000, 0x08000000, 0x0c000000, 0x02000000,
        0x01000000,
    ]),
    cols(&[
        0xc0000000, 0x41000000, 0x22000000, 0x16000000, 0x08000000, 0x10000000, 0x20000000,
        0x40800000, 0x80000000,
    ]),
    cols(&[
        0x80000000, 0x40000000, 0x20000000, 0x18000000, 0x08000000, 0x1c000000, 0x1e000000,
        0x03000000, 0x00800000, 0x00400000,
    ]),
    cols(&[
        0x80000000, 0x60400000, 0x20800000, 0x11000000, 0x0b000000, 0x04000000, 0x08000000,
        0x10000000, 0x20000000, 0x40000000, 0x00200000,
    ]),
    cols(&[
        0x80000000, 0x40000000, 0x20000000, 0x1c000000, 0x0c000000, 0x05000000, 0x02000000,
        0x03000000, 0x00800000, 0x00400000, 0x00200000, 0x00100000,
    ]),
    cols(&[
        0x80000000, 0x40000000, 0x30200000, 0x10400000, 0x08800000, 0x05800000, 0x02000000,
        0x04000000, 0x08000000, 0x10000000, 0x20000000, 0x00100000, 0x00080000,
    ]),
    cols(&[
        0x80000000, 0x40000000, 0x20000000, 0x10000000, 0x0e000000, 0x06000000, 0x02800000,
        0x01000000, 0x01800000, 0x00400000, 0x00200000, 0x00100000, 0x00080000, 0x00040000,
    ]),
    cols(&[
        0x80000000, 0x40000000, 0x20000000, 0x18100000, 0x08200000, 0x04400000, 0x02c00000,
        0x01000000, 0x02000000, 0x04000000, 0x08000000, 0x10000000, 0x00080000, 0x00040000,
        0x00020000,
    ]),
    cols(&[
        0x80000000, 0x40000000, 0x20000000, 0x10000000, 0x08000000, 0x07000000, 0x03000000,
        0x01400000, 0x00800000, 0x00c00000, 0x00200000, 0x00100000, 0x00080000, 0x00040000,
        0x00020000, 0x00010000,
    ]),
];
