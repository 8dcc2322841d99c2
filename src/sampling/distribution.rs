//! Piecewise-constant 1D and 2D distributions (pbrt-v3 core/sampling.h),
//! made robust to degenerate input: negative or NaN values count as 0, and an
//! all-zero function samples uniformly (with the matching pdf) instead of
//! producing zero pdfs.

use super::distribution_guide::GuideTable;
use super::rng::ONE_MINUS_EPSILON;
use glam::Vec2;
use rayon::prelude::*;

/// Bins from which a 2D distribution builds its rows in parallel.
const PARALLEL_2D: usize = 1 << 16;

/// Piecewise-constant distribution over `[0, 1)` with `count()` equal bins.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    /// `count + 1` entries: the CDF (`[0].cdf == 0`, `[count].cdf == 1`)
    /// and each bin's density over `[0, 1]` (integrating to 1; the last
    /// entry's is 0 and unused), side by side, so that a sample's search
    /// ends reading its bin's density from the cache line of its CDF.
    bins: Vec<Bin>,
    /// Integral of the (sanitised) function over `[0, 1]`: `Σ f / n`.
    func_int: f32,
    /// Narrows the search of the CDF (to the plain bisection's result).
    guide: GuideTable,
}

/// A bin's CDF entry (at its start) and density.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Bin {
    cdf: f32,
    pdf: f32,
}

#[inline]
fn sanitise(v: f32) -> f32 {
    if v.is_finite() && v > 0.0 {
        v
    } else if v == f32::INFINITY {
        f32::MAX
    } else {
        0.0
    }
}

/// `u` clamped to `[0, 1)`; NaN becomes 0.
#[inline]
pub(crate) fn sanitise_u(u: f32) -> f32 {
    if u >= 0.0 {
        u.min(ONE_MINUS_EPSILON)
    } else {
        0.0
    }
}

/// Index of the last `i` in `[0, cdf.len() - 2]` with `cdf[i] <= u`
/// (pbrt's `FindInterval`) by bisection of the whole CDF: what
/// [`GuideTable::find_interval`] must find.
#[cfg(test)]
pub(crate) fn find_interval_plain(cdf: &[f32], u: f32) -> usize {
    find_interval_by(cdf.len(), u, |i| cdf[i])
}

/// `find_interval` over a non-decreasing CDF of `len` (at least 2) values
/// read through `cdf` (for CDFs not stored as an `f32` slice).
#[inline]
pub(crate) fn find_interval_by(len: usize, u: f32, cdf: impl Fn(usize) -> f32) -> usize {
    // Bisection for the first index where cdf > u.
    let (mut lo, mut hi) = (0usize, len);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if cdf(mid) <= u {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo.saturating_sub(1).min(len - 2)
}

/// `(offset + du) / n` strictly inside bin `offset` and strictly below 1, so
/// that `pdf(x)` finds the bin the sample came from.
#[inline]
pub(crate) fn point_in_bin(offset: usize, du: f32, n: usize) -> f32 {
    let nf = n as f32;
    let mut x = ((offset as f32 + du) / nf).min(ONE_MINUS_EPSILON);
    // Rounding can push x onto the next bin's edge: step down until it maps back.
    while x > 0.0 && ((x * nf) as usize).min(n - 1) > offset {
        x = f32::from_bits(x.to_bits() - 1);
    }
    x
}

impl Distribution1D {
    /// Builds the distribution. An empty slice behaves as a single zero bin.
    pub fn new(f: &[f32]) -> Self {
        let zero = [0.0f32];
        let f = if f.is_empty() { &zero[..] } else { f };
        let n = f.len();
        // The CDF as `DiscreteCdf` defines it (f64 prefix sums over their
        // total, so long distributions keep their precision), the sums made
        // twice in the same order instead of stored.
        let total = f.iter().fold(0.0f64, |acc, &v| acc + sanitise(v) as f64);
        let func_int = (total / n as f64) as f32;
        let mut bins = Vec::with_capacity(n + 1);
        if total > 0.0 && total.is_finite() {
            let inv = n as f64 / total;
            let mut acc = 0.0f64;
            bins.extend(f.iter().map(|&v| {
                let v = sanitise(v) as f64;
                let bin = Bin {
                    cdf: (acc / total) as f32,
                    pdf: (v * inv) as f32,
                };
                acc += v;
                bin
            }));
        } else {
            bins.extend((0..n).map(|i| Bin {
                cdf: i as f32 / n as f32,
                pdf: 1.0,
            }));
        }
        bins.push(Bin { cdf: 1.0, pdf: 0.0 });
        let guide = GuideTable::new(bins.len(), |i| bins[i].cdf);
        Self {
            bins,
            func_int,
            guide,
        }
    }

    /// The CDF entry at the start of bin `i` (`count()` for the end, 1).
    #[inline]
    fn cdf_at(&self, i: usize) -> f32 {
        self.bins[i].cdf
    }

    /// The search for the bin of `u` in `[0, 1)`: pbrt's `FindInterval`.
    #[inline]
    fn find(&self, u: f32) -> usize {
        self.find_with(u, |_, _| {})
    }

    /// Asks for the cache lines of the first, middle and last CDF entries
    /// of the guide cell `lo ..= hi` (a hint): the bisection's probes are
    /// dependent loads, so asked for together the cache misses of a big
    /// distribution's (an environment map's) overlap.
    #[inline]
    fn prefetch_cell(&self, lo: usize, hi: usize) {
        let bins = self.bins.as_ptr();
        for i in [lo, (lo + hi) / 2, hi] {
            crate::accel::prefetch(bins.wrapping_add(i.min(self.bins.len() - 1)));
        }
    }

    /// `find` without hints (for distributions that stay in the caches, or
    /// whose entries were asked for already).
    #[inline]
    fn find_unhinted(&self, u: f32) -> usize {
        self.guide
            .find_interval(self.bins.len(), u, |i| self.bins[i].cdf)
    }

    /// `find`, calling `ahead(lo, hi)` with the range of bins the search
    /// bisects (the result is within `lo - 1 ..= hi`) before it reads them.
    #[inline]
    fn find_with(&self, u: f32, ahead: impl FnOnce(usize, usize)) -> usize {
        self.guide.find_interval_with(
            self.bins.len(),
            u,
            |i| self.bins[i].cdf,
            |lo, hi| {
                self.prefetch_cell(lo, hi);
                ahead(lo, hi);
            },
        )
    }

    /// The CDF: `count() + 1` entries from 0 to 1.
    #[cfg(test)]
    pub(crate) fn cdf(&self) -> Vec<f32> {
        self.bins.iter().map(|b| b.cdf).collect()
    }

    /// Number of bins.
    #[inline]
    pub fn count(&self) -> usize {
        self.bins.len() - 1
    }

    /// Integral of the function over `[0, 1]` (0 for an all-zero function, which
    /// is nevertheless sampled uniformly).
    #[inline]
    pub fn func_int(&self) -> f32 {
        self.func_int
    }

    /// Samples `x` in `[0,1)`; returns `(x, pdf(x), bin index)`.
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        self.sample_continuous_with(u, |_, _| {})
    }

    /// `sample_continuous` without the search's hints (for callers that
    /// asked for its CDF entries already).
    #[inline]
    pub fn sample_continuous_unhinted(&self, u: f32) -> (f32, f32, usize) {
        let u = sanitise_u(u);
        self.point_of(u, self.find_unhinted(u))
    }

    /// `sample_continuous`, calling `ahead(lo, hi)` with the range of bins
    /// the sample will be within (`lo - 1 ..= hi`) before the search reads them
    /// (for hints about what the caller will read next).
    #[inline]
    pub fn sample_continuous_with(
        &self,
        u: f32,
        ahead: impl FnOnce(usize, usize),
    ) -> (f32, f32, usize) {
        let u = sanitise_u(u);
        let offset = self.find_with(u, ahead);
        self.point_of(u, offset)
    }

    /// The sample of `u` in bin `offset`: `(x, pdf(x), offset)`.
    #[inline]
    fn point_of(&self, u: f32, offset: usize) -> (f32, f32, usize) {
        let c0 = self.cdf_at(offset);
        let width = self.cdf_at(offset + 1) - c0;
        let mut du = u - c0;
        if width > 0.0 {
            du /= width;
        }
        let du = du.clamp(0.0, ONE_MINUS_EPSILON);
        let x = point_in_bin(offset, du, self.count());
        (x, self.bins[offset].pdf, offset)
    }

    /// Samples a bin; returns `(index, probability, u remapped to [0,1))`.
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let u = sanitise_u(u);
        let offset = self.find(u);
        let c0 = self.cdf_at(offset);
        let width = self.cdf_at(offset + 1) - c0;
        let ur = if width > 0.0 {
            ((u - c0) / width).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (offset, self.discrete_pdf(offset), ur)
    }

    /// Probability of bin `i` under `sample_discrete`.
    #[inline]
    pub fn discrete_pdf(&self, i: usize) -> f32 {
        self.bins[i].pdf / self.count() as f32
    }

    /// Density at `x` in `[0,1]` (values outside are clamped to the end bins).
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        self.bins[self.bin(x)].pdf
    }

    #[inline]
    fn bin(&self, x: f32) -> usize {
        let n = self.count();
        let i = (x * n as f32) as isize; // NaN -> 0, saturating
        i.clamp(0, n as isize - 1) as usize
    }
}

/// The bin choice of [`Distribution1D::sample_discrete`] and its
/// `func_int`, without the density and function arrays: only the prefix
/// sums (in f64), from which a CDF entry is computed when the search reads
/// it (`Distribution1D::new` stores the same entries). For
/// long functions sampled a few times (mlt's bootstrap weights, millions of
/// them, sampled once per chain): 8 bytes per bin instead of 12 (20 while
/// a `Distribution1D` is built), and no per-bin division.
#[derive(Clone, Debug)]
pub struct DiscreteCdf {
    /// `count + 1` sums of the sanitised values, `sums[0] == 0`.
    sums: Vec<f64>,
}

impl DiscreteCdf {
    pub fn new(f: &[f32]) -> Self {
        let mut sums = Vec::with_capacity(f.len().max(1) + 1);
        sums.push(0.0f64);
        if f.is_empty() {
            sums.push(0.0);
        }
        let mut acc = 0.0f64;
        for &v in f {
            acc += sanitise(v) as f64;
            sums.push(acc);
        }
        Self { sums }
    }

    fn count(&self) -> usize {
        self.sums.len() - 1
    }

    fn total(&self) -> f64 {
        self.sums[self.count()]
    }

    /// `Distribution1D::func_int` of the same function.
    pub fn func_int(&self) -> f32 {
        (self.total() / self.count() as f64) as f32
    }

    /// `Distribution1D`'s CDF entry `i` (0 at 0, 1 at `count`): the sums
    /// over their total, or `i / count` where the total is 0 or infinite.
    #[inline]
    fn cdf(&self, i: usize) -> f32 {
        let n = self.count();
        let total = self.total();
        if i == n {
            1.0
        } else if total > 0.0 && total.is_finite() {
            (self.sums[i] / total) as f32
        } else {
            i as f32 / n as f32
        }
    }

    /// The bin `Distribution1D::sample_discrete(u)` chooses.
    #[inline]
    pub fn sample_index(&self, u: f32) -> usize {
        find_interval_by(self.count() + 1, sanitise_u(u), |i| self.cdf(i))
    }
}

/// Piecewise-constant distribution over `[0,1)^2`: a marginal over rows (v)
/// and one conditional per row (u).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `f` is row-major: `nv` rows of `nu` values (`f.len()` must be `nu * nv`).
    pub fn new(f: &[f32], nu: usize, nv: usize) -> Self {
        assert_eq!(f.len(), nu * nv, "Distribution2D: f.len() != nu * nv");
        Self::from_rows(nu, nv, |v, row| {
            row.copy_from_slice(&f[v * nu..(v + 1) * nu])
        })
    }

    /// The distribution of `nv` rows of `nu` values, row `v` written by
    /// `fill(v, row)` (so that the whole function is never stored).
    pub fn from_rows(nu: usize, nv: usize, fill: impl Fn(usize, &mut [f32]) + Sync) -> Self {
        assert!(nu > 0 && nv > 0, "Distribution2D needs at least one bin");
        let row = |buf: &mut Vec<f32>, v: usize| {
            buf.resize(nu, 0.0);
            fill(v, buf);
            Distribution1D::new(buf)
        };
        // Big ones (an environment map's) row by row on all threads; the
        // rows are independent, so the result is the same.
        let conditional: Vec<Distribution1D> = if nu * nv >= PARALLEL_2D {
            (0..nv).into_par_iter().map_init(Vec::new, row).collect()
        } else {
            let mut buf = Vec::new();
            (0..nv).map(|v| row(&mut buf, v)).collect()
        };
        let marginal_func: Vec<f32> = conditional.iter().map(|d| d.func_int()).collect();
        let marginal = Distribution1D::new(&marginal_func);
        Self {
            conditional,
            marginal,
        }
    }

    /// Samples a point; returns `(p, pdf(p))`.
    #[inline]
    pub fn sample_continuous(&self, u: Vec2) -> (Vec2, f32) {
        self.sample_continuous_with(u, |_, _, _| {})
    }

    /// `sample_continuous`, calling `ahead(v, lo, hi)` once the row `v` is
    /// chosen, with the range of its bins the point will be in (`lo - 1
    /// ..= hi`), before the row's search reads them: so that the caller's
    /// hints about what it reads at the point overlap the search's misses.
    #[inline]
    pub fn sample_continuous_with(
        &self,
        u: Vec2,
        ahead: impl FnOnce(usize, usize, usize),
    ) -> (Vec2, f32) {
        // (The marginal, one entry per row, stays in the caches: no hints.)
        let (d1, pdf1, v) = self.marginal.sample_continuous_unhinted(u.y);
        let (d0, pdf0, _) =
            self.conditional[v].sample_continuous_with(u.x, |lo, hi| ahead(v, lo, hi));
        (Vec2::new(d0, d1), pdf0 * pdf1)
    }

    /// `sample_continuous` without the searches' hints (for callers that
    /// asked for the row's CDF entries already, as `prefetch_sample_bins`).
    #[inline]
    pub fn sample_continuous_unhinted(&self, u: Vec2) -> (Vec2, f32) {
        let (d1, pdf1, v) = self.marginal.sample_continuous_unhinted(u.y);
        let (d0, pdf0, _) = self.conditional[v].sample_continuous_unhinted(u.x);
        (Vec2::new(d0, d1), pdf0 * pdf1)
    }

    /// The number of columns and rows.
    #[inline]
    pub fn size(&self) -> (usize, usize) {
        (self.conditional[0].count(), self.conditional.len())
    }

    /// Density at `p` in `[0,1]^2`.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        let iv = self.marginal.bin(p.y);
        self.marginal.bins[iv].pdf * self.conditional[iv].pdf(p.x)
    }

    /// Asks for the cache line of `pdf(p)`'s density (a hint).
    #[inline]
    pub fn prefetch_pdf(&self, p: Vec2) {
        let iv = self.marginal.bin(p.y);
        let row = &self.conditional[iv];
        crate::accel::prefetch(row.bins.as_ptr().wrapping_add(row.bin(p.x)));
    }

    /// The first of two hints before `sample_continuous(u)`: asks for the
    /// guide table entries of the row that `u` chooses. Several samples'
    /// hints given together let their cache misses overlap.
    #[inline]
    pub fn prefetch_sample_row(&self, u: Vec2) {
        let v = self.marginal.find_unhinted(sanitise_u(u.y));
        self.conditional[v].guide.prefetch(sanitise_u(u.x));
    }

    /// The second hint (once the first's lines have arrived): asks for the
    /// CDF entries the row's search reads.
    #[inline]
    pub fn prefetch_sample_bins(&self, u: Vec2) {
        let row = &self.conditional[self.marginal.find_unhinted(sanitise_u(u.y))];
        let (lo, hi) = row.guide.cell(sanitise_u(u.x));
        row.prefetch_cell(lo, hi);
    }

    pub fn marginal(&self) -> &Distribution1D {
        &self.marginal
    }

    pub fn conditional(&self, v: usize) -> &Distribution1D {
        &self.conditional[v]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// The bins as `DiscreteCdf`'s stored prefix sums define them: the
    /// construction that sums twice instead of storing gives the same bits.
    #[test]
    fn bins_equal_the_stored_sums() {
        let mut rng = Pcg32::with_sequence(11);
        let specials = [0.0, -1.0, f32::NAN, f32::INFINITY, f32::MAX, 1e-30];
        for k in 0..400 {
            let n = [0usize, 1, 2, 3, 17, 1000][k % 6];
            let f: Vec<f32> = (0..n)
                .map(|_| match k % 5 {
                    0 => 0.0,
                    1 => specials[rng.uniform_u32() as usize % specials.len()],
                    _ if rng.uniform_f32() < 0.2 => 0.0,
                    _ => rng.uniform_f32() * 1e3,
                })
                .collect();
            let d = Distribution1D::new(&f);
            let func: Vec<f32> = if f.is_empty() {
                vec![0.0]
            } else {
                f.iter().map(|&v| sanitise(v)).collect()
            };
            let sums = DiscreteCdf::new(&func);
            let (total, m) = (sums.total(), func.len());
            let uniform = !(total > 0.0 && total.is_finite());
            assert_eq!(d.count(), m);
            assert_eq!(d.func_int().to_bits(), sums.func_int().to_bits());
            for i in 0..=m {
                let pdf = match func.get(i) {
                    None => 0.0,
                    Some(_) if uniform => 1.0,
                    Some(&v) => (v as f64 * (m as f64 / total)) as f32,
                };
                assert_eq!(
                    d.bins[i].cdf.to_bits(),
                    sums.cdf(i).to_bits(),
                    "{k} cdf {i}"
                );
                assert_eq!(d.bins[i].pdf.to_bits(), pdf.to_bits(), "{k} pdf {i}");
            }
        }
    }
}
