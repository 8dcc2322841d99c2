//! Speed only: the CDF search of [`Distribution1D`](super::Distribution1D)
//! narrowed by a guide table (Chen and Asau's cutpoint method, "On
//! generating random variates from an empirical distribution", 1974).
//! The unit interval is cut into K = 2^k equal cells, about one per 16
//! bins; the table keeps, for each cut j/K, the first CDF index whose
//! value exceeds it. A value u in cell j has its own first exceeding index
//! between those of j/K and (j + 1)/K (the CDF is non-decreasing), so the
//! bisection runs only between them: about four steps within a cache line
//! or two where the density is even, fewer where it is high (which is
//! where most samples go), instead of log2(n) steps across the whole CDF.
//! The index found is the plain bisection's bit for bit, so the mapping
//! from sample values to points is pbrt-v3's (`tests::equals_plain`).
//!
//! With K a power of two, u·K and j/K are exact, so the cell of u is
//! ⌊u·K⌋ with no rounding at the cuts.
//!
//! On the 2048×1024 sky of rs_pbrt's `caustic` (a `Distribution2D` of its
//! luminance, two searches per sample), cachegrind counts per sample 413
//! instructions and 9.6 first-level read misses with the plain bisection,
//! 341 and 4.1 with this table.

/// Bins per cell: the table is a sixteenth of the CDF's size, small
/// enough to stay in the cache beside the densities of a large
/// environment map, and a cell's bisection reads one or two cache lines of
/// the CDF (where the density is even; fewer where it is high).
const BINS_PER_CELL_LOG2: u32 = 4;

#[derive(Clone, Debug)]
pub struct GuideTable {
    /// K + 1 entries: `first[j]` is the first index of the CDF whose
    /// value exceeds j/K (the CDF's length if none does).
    first: Vec<u32>,
    /// K as a float.
    cells: f32,
}

impl GuideTable {
    /// The table of a non-decreasing CDF of `len` entries (at least two,
    /// the first 0, the last 1, none NaN), read through `cdf`.
    pub fn new(len: usize, cdf: impl Fn(usize) -> f32) -> GuideTable {
        let bins = len.saturating_sub(1).max(1);
        let k = bins
            .next_power_of_two()
            .trailing_zeros()
            .saturating_sub(BINS_PER_CELL_LOG2);
        let cells = 1usize << k;
        let mut first = Vec::with_capacity(cells + 1);
        let mut p = 0usize;
        for j in 0..=cells {
            let cut = j as f32 / cells as f32;
            while p < len && cdf(p) <= cut {
                p += 1;
            }
            first.push(p as u32);
        }
        GuideTable {
            first,
            cells: cells as f32,
        }
    }

    /// The range of CDF indices a search for `u` in [0, 1) bisects.
    #[inline]
    pub fn cell(&self, u: f32) -> (usize, usize) {
        let j = self.cell_index(u);
        (self.first[j] as usize, self.first[j + 1] as usize)
    }

    /// The guide cell `u` in [0, 1) falls in.
    #[inline]
    fn cell_index(&self, u: f32) -> usize {
        (u * self.cells) as usize
    }

    /// Asks for the cache line of the table entries `find_interval(.., u,
    /// ..)` reads (a hint).
    #[inline]
    pub fn prefetch(&self, u: f32) {
        crate::accel::prefetch(self.first.as_ptr().wrapping_add(self.cell_index(u)));
    }

    /// The index of the last entry of the CDF (the one the table was made
    /// from, `len` entries read through `cdf`) at or below `u` in [0, 1),
    /// at most `len - 2`: pbrt's `FindInterval`.
    #[inline]
    pub fn find_interval(&self, len: usize, u: f32, cdf: impl Fn(usize) -> f32) -> usize {
        self.find_interval_with(len, u, cdf, |_, _| {})
    }

    /// `find_interval`, calling `ahead(lo, hi)` with the range of CDF
    /// indices it will bisect before it reads any of them (for hints).
    #[inline]
    pub fn find_interval_with(
        &self,
        len: usize,
        u: f32,
        cdf: impl Fn(usize) -> f32,
        ahead: impl FnOnce(usize, usize),
    ) -> usize {
        debug_assert!((0.0..1.0).contains(&u));
        let (lo, hi) = self.cell(u);
        ahead(lo, hi);
        // The first index in [lo, hi] whose value exceeds u, by a bisection
        // whose steps are selects, not branches: a cell's few steps are
        // data-dependent coin flips that a branch predictor loses. The
        // index is somewhere in [base, base + size].
        let (mut base, mut size) = (lo, hi - lo);
        let first = if size == 0 {
            lo
        } else {
            while size > 1 {
                let half = size / 2;
                let mid = base + half;
                base = if cdf(mid) <= u { mid } else { base };
                size -= half;
            }
            base + (cdf(base) <= u) as usize
        };
        first.saturating_sub(1).min(len - 2)
    }
}

#[cfg(test)]
mod tests {
    use super::super::distribution::{find_interval_plain, Distribution1D};
    use super::super::rng::{Pcg32, ONE_MINUS_EPSILON};
    use super::*;

    fn check(f: &[f32], rng: &mut Pcg32) {
        let d = Distribution1D::new(f);
        let cdf = &d.cdf()[..];
        let g = GuideTable::new(cdf.len(), |i| cdf[i]);
        let mut us: Vec<f32> = (0..2000).map(|_| rng.uniform_f32()).collect();
        // Every CDF entry, the floats beside it, the cuts and the ends.
        for &c in cdf.iter() {
            for v in [
                c,
                f32::from_bits(c.to_bits().saturating_sub(1)),
                f32::from_bits(c.to_bits() + 1),
            ] {
                us.push(v);
            }
        }
        for j in 0..=64 {
            us.push(j as f32 / 64.0);
        }
        us.extend([0.0, ONE_MINUS_EPSILON, 1e-30, 0.5]);
        for u in us {
            if !(0.0..1.0).contains(&u) {
                continue;
            }
            assert_eq!(
                g.find_interval(cdf.len(), u, |i| cdf[i]),
                find_interval_plain(cdf, u),
                "u = {u:e}, {} bins",
                f.len()
            );
        }
    }

    #[test]
    fn equals_plain() {
        let mut rng = Pcg32::with_sequence(17);
        for n in [0, 1, 2, 3, 7, 64, 100, 1000, 4097] {
            // Smooth, peaked (a sun), sparse, all-zero and degenerate.
            let smooth: Vec<f32> = (0..n).map(|_| rng.uniform_f32()).collect();
            let peaked: Vec<f32> = (0..n)
                .map(|i| {
                    if i == n / 3 {
                        1e6
                    } else {
                        rng.uniform_f32() * 1e-3
                    }
                })
                .collect();
            let sparse: Vec<f32> = (0..n)
                .map(|_| {
                    if rng.uniform_f32() < 0.05 {
                        rng.uniform_f32()
                    } else {
                        0.0
                    }
                })
                .collect();
            let zero = vec![0.0; n];
            let odd: Vec<f32> = (0..n)
                .map(|i| [f32::NAN, -1.0, f32::INFINITY, f32::MAX, 1e-38, 2.0][i % 6])
                .collect();
            for f in [smooth, peaked, sparse, zero, odd] {
                check(&f, &mut rng);
            }
        }
        let long: Vec<f32> = (0..(1 << 20) + 12345)
            .map(|i| ((i % 977) as f32).powi(3))
            .collect();
        check(&long, &mut rng);
    }
}
