//! Walker's alias method over the bins of a piecewise-constant
//! distribution: the same density as [`Distribution1D`] and
//! [`Distribution2D`], sampled in constant time (one table entry per
//! dimension) instead of by a binary search of the CDF.
//!
//! The mapping from sample values to points differs from the CDF
//! inversion: `u` picks an entry uniformly and the rest of `u` decides
//! between the entry's own bin and its alias, so neighbouring values of
//! `u` may land in distant bins. The density is unchanged (so `pdf` is the
//! distribution's own), but the stratification of low-discrepancy samples
//! carries over only within an entry. Tables are built with Vose's
//! worklists in f64.

use super::distribution::{Distribution1D, Distribution2D};
use super::rng::ONE_MINUS_EPSILON;
use glam::Vec2;
use rayon::prelude::*;

/// One entry: its own bin is kept when the entry's fraction is below `q`,
/// else `alias` is taken; with both bins' densities, so that a sample
/// reads one entry and nothing else.
#[derive(Clone, Copy, Debug)]
struct Entry {
    q: f32,
    alias: u32,
    pdf: f32,
    alias_pdf: f32,
}

/// An alias table over `n` bins with the probabilities of a
/// [`Distribution1D`]'s bins.
#[derive(Clone, Debug)]
pub struct AliasTable {
    entries: Vec<Entry>,
}

impl AliasTable {
    /// The table of `d`'s bin probabilities (uniform for an all-zero
    /// function, as `d` samples it).
    pub fn new(d: &Distribution1D) -> AliasTable {
        let n = d.count();
        // Bin probabilities times n (mean 1), from the densities.
        let mut scaled: Vec<f64> = (0..n)
            .map(|i| d.discrete_pdf(i) as f64 * n as f64)
            .collect();
        let sum: f64 = scaled.iter().sum();
        if !(sum > 0.0 && sum.is_finite()) {
            scaled.iter_mut().for_each(|s| *s = 1.0);
        } else {
            let k = n as f64 / sum;
            scaled.iter_mut().for_each(|s| *s *= k);
        }
        let pdf = |i: u32| d.pdf((i as f32 + 0.5) / n as f32);
        let mut entries = vec![
            Entry {
                q: 1.0,
                alias: 0,
                pdf: 0.0,
                alias_pdf: 0.0
            };
            n
        ];
        let (mut small, mut large): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
        for (i, &s) in scaled.iter().enumerate() {
            if s < 1.0 {
                small.push(i as u32);
            } else {
                large.push(i as u32);
            }
        }
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            entries[s as usize] = Entry {
                q: scaled[s as usize] as f32,
                alias: l,
                pdf: pdf(s),
                alias_pdf: pdf(l),
            };
            scaled[l as usize] -= 1.0 - scaled[s as usize];
            if scaled[l as usize] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left holds (up to rounding) probability 1/n: its own bin.
        for i in small.into_iter().chain(large) {
            entries[i as usize] = Entry {
                q: 1.0,
                alias: i,
                pdf: pdf(i),
                alias_pdf: pdf(i),
            };
        }
        AliasTable { entries }
    }

    /// Number of bins.
    #[inline]
    pub fn count(&self) -> usize {
        self.entries.len()
    }

    /// A point in `[0, 1)`, its density and its bin: the entry `⌊u n⌋`,
    /// then its own bin or its alias by the fraction left, rescaled to the
    /// position inside the bin.
    #[inline]
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let n = self.entries.len();
        let s = super::distribution::sanitise_u(u) * n as f32;
        let i = (s as usize).min(n - 1);
        let f = (s - i as f32).clamp(0.0, ONE_MINUS_EPSILON);
        let e = self.entries[i];
        let (bin, du, pdf) = if f < e.q {
            (i, f / e.q, e.pdf)
        } else {
            (e.alias as usize, (f - e.q) / (1.0 - e.q), e.alias_pdf)
        };
        let du = du.clamp(0.0, ONE_MINUS_EPSILON);
        (super::distribution::point_in_bin(bin, du, n), pdf, bin)
    }
}

/// Alias tables for a [`Distribution2D`]: one over its rows, one per row.
#[derive(Clone, Debug)]
pub struct Alias2D {
    marginal: AliasTable,
    conditional: Vec<AliasTable>,
}

impl Alias2D {
    pub fn new(d: &Distribution2D) -> Alias2D {
        let marginal = AliasTable::new(d.marginal());
        let conditional = (0..marginal.count())
            .into_par_iter()
            .map(|v| AliasTable::new(d.conditional(v)))
            .collect();
        Alias2D {
            marginal,
            conditional,
        }
    }

    /// A point of `[0, 1)²` and its density (that of the distribution the
    /// tables were built from).
    #[inline]
    pub fn sample_continuous(&self, u: Vec2) -> (Vec2, f32) {
        let (y, pdf_y, v) = self.marginal.sample_continuous(u.y);
        let (x, pdf_x, _) = self.conditional[v].sample_continuous(u.x);
        (Vec2::new(x, y), pdf_x * pdf_y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// The table's bin frequencies equal the distribution's probabilities,
    /// exactly when `u` sweeps a fine grid: each entry gives its own bin the
    /// fraction `q` of its 1/n and its alias the rest.
    #[test]
    fn bin_frequencies_match_the_distribution() {
        for f in [
            vec![1.0, 2.0, 3.0, 4.0],
            vec![0.0, 5.0, 0.0, 0.0, 1.0, 0.5, 9.0],
            vec![0.0; 5],
            vec![1e-30, 1.0, 1e30],
            vec![3.0],
        ] {
            let d = Distribution1D::new(&f);
            let a = AliasTable::new(&d);
            let m = 1 << 20;
            let mut counts = vec![0u64; d.count()];
            for k in 0..m {
                let u = (k as f32 + 0.5) / m as f32;
                let (x, pdf, bin) = a.sample_continuous(u);
                assert!((0.0..1.0).contains(&x), "{x}");
                assert_eq!(pdf, d.pdf(x));
                assert_eq!(((x * d.count() as f32) as usize).min(d.count() - 1), bin);
                counts[bin] += 1;
            }
            for (i, &c) in counts.iter().enumerate() {
                let p = d.discrete_pdf(i) as f64;
                let got = c as f64 / m as f64;
                assert!((got - p).abs() < 1e-4, "{f:?} bin {i}: {got} against {p}");
            }
        }
    }

    /// Inside a bin the points are uniform: the mean position of the
    /// samples that land in each bin is its centre.
    #[test]
    fn points_are_uniform_within_bins() {
        let d = Distribution1D::new(&[0.5, 3.0, 1.0, 0.2, 2.0, 0.0, 1.5]);
        let a = AliasTable::new(&d);
        let n = d.count();
        let mut sum = vec![0.0f64; n];
        let mut cnt = vec![0u64; n];
        let mut rng = Pcg32::with_sequence(3);
        for _ in 0..400_000 {
            let (x, _, bin) = a.sample_continuous(rng.uniform_f32());
            sum[bin] += x as f64;
            cnt[bin] += 1;
        }
        for i in 0..n {
            if cnt[i] > 0 {
                let centre = (i as f64 + 0.5) / n as f64;
                assert!((sum[i] / cnt[i] as f64 - centre).abs() < 2e-3, "bin {i}");
            }
        }
        assert_eq!(cnt[5], 0);
    }

    /// 2D: the tables pick rows and columns with the distribution's
    /// probabilities (cell frequencies against pdf × cell area).
    #[test]
    fn cells_match_the_2d_distribution() {
        let (nu, nv) = (6, 4);
        let f: Vec<f32> = (0..nu * nv)
            .map(|i| ((i * 7) % 5) as f32 + if i == 9 { 20.0 } else { 0.0 })
            .collect();
        let d = Distribution2D::new(&f, nu, nv);
        let a = Alias2D::new(&d);
        let mut counts = vec![0u64; nu * nv];
        let m = 1024;
        for y in 0..m {
            for x in 0..m {
                let u = Vec2::new((x as f32 + 0.5) / m as f32, (y as f32 + 0.5) / m as f32);
                let (p, pdf) = a.sample_continuous(u);
                assert_eq!(pdf, d.pdf(p));
                let (i, j) = ((p.x * nu as f32) as usize, (p.y * nv as f32) as usize);
                counts[j * nu + i] += 1;
            }
        }
        for j in 0..nv {
            for i in 0..nu {
                let c = Vec2::new((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
                let want = d.pdf(c) as f64 / (nu * nv) as f64;
                let got = counts[j * nu + i] as f64 / (m * m) as f64;
                assert!(
                    (got - want).abs() < 1e-3,
                    "cell ({i}, {j}): {got} against {want}"
                );
            }
        }
    }
}
