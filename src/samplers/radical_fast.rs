//! The unscrambled radical inverses of a run of consecutive indices at
//! once (speed only: bit for bit [`RadicalTable::radical_inverse`], as the
//! tests below check).
//!
//! sppm's photons draw dimension `d` of index `i`, then of `i + 1`, and so
//! on through a chunk of photons. Below a power of the table's chunk
//! `C = base^k`, consecutive indices `hi·C + lo` share their high digits
//! `hi`, so their reversals are `rev_k(lo)·base^n(hi) + rev(hi)`: one table
//! load, one multiply-add and the same conversion per value, with no chain
//! of dependent steps, where a lookup of each index on its own pays a
//! multiply-high and a load per chunk of digits.

use super::lowdiscrepancy::RadicalTable;
use crate::sampling::rng::ONE_MINUS_EPSILON;

/// Runs ending at or above this are looked up index by index (below it, a
/// reversal needs at most 46 bits: exact in f64 and without wrapping).
const FILL_LIMIT: u64 = 1 << 40;

impl RadicalTable {
    /// Whether [`RadicalTable::fill`] takes runs of indices in one pass
    /// (the bases with a table of digits: 3 to 64).
    pub fn fills(&self) -> bool {
        !self.entries.is_empty()
    }

    /// `out[i] = self.radical_inverse(first + i)` for every `i`, bit for
    /// bit.
    pub fn fill(&self, first: u64, out: &mut [f32]) {
        let end = first.checked_add(out.len() as u64);
        if !self.fills() || end.is_none_or(|e| e > FILL_LIMIT) {
            for (i, o) in out.iter_mut().enumerate() {
                *o = self.radical_inverse(first.wrapping_add(i as u64));
            }
            return;
        }
        let c = self.chunk;
        let mut i = 0usize;
        while i < out.len() {
            let a = first + i as u64;
            let (hi, lo) = (a / c, (a % c) as usize);
            let run = (c as usize - lo).min(out.len() - i);
            let seg = &mut out[i..i + run];
            let entries = &self.entries[lo..lo + run];
            if hi == 0 {
                // Below the chunk: the value's own significant digits.
                for (o, e) in seg.iter_mut().zip(entries) {
                    *o = ((e.1 as f64 * self.inv_powers[e.2 as usize]) as f32)
                        .min(ONE_MINUS_EPSILON);
                }
            } else {
                // All `k` low digits, shifted past the high ones.
                let (rev_hi, n_hi) = self.reversed_digits(hi);
                let base = self.base.base as u64;
                let shift = (0..n_hi).fold(1u64, |s, _| s * base);
                let scale = self.inv_powers[self.k + n_hi];
                // Every term below 2^53: the f64 sum is the integer's value.
                let (shift, rev_hi) = (shift as f64, rev_hi as f64);
                for (o, e) in seg.iter_mut().zip(entries) {
                    let reversed = e.0 as f64 * shift + rev_hi;
                    *o = ((reversed * scale) as f32).min(ONE_MINUS_EPSILON);
                }
            }
            i += run;
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::samplers::lowdiscrepancy::{radical_inverse, DigitBase, RadicalTable, PRIMES};
    use crate::sampling::rng::Pcg32;

    fn check(t: &RadicalTable, p: u32, first: u64, len: usize) {
        let mut out = vec![0f32; len];
        t.fill(first, &mut out);
        let b = DigitBase::new(p);
        for (i, v) in out.iter().enumerate() {
            let a = first.wrapping_add(i as u64);
            assert_eq!(
                v.to_bits(),
                radical_inverse(&b, a).to_bits(),
                "base {p} first {first} a {a}"
            );
        }
    }

    #[test]
    fn runs_are_bit_identical() {
        let mut r = Pcg32::with_sequence(5);
        for &p in PRIMES.iter().take(24).chain(&[7919]) {
            let t = RadicalTable::new(p);
            // From zero, across the first chunks.
            check(&t, p, 0, 20_000);
            // Runs across powers of the base (a new high digit) and the
            // chunk (a new high part), of lengths below and above it.
            let mut q = p as u64;
            while q < (1 << 42) {
                for len in [1, 3, 256, 5000] {
                    check(&t, p, q.saturating_sub(len as u64 / 2 + 1), len);
                }
                q *= p as u64;
            }
            for _ in 0..300 {
                let len = 1 + (r.uniform_u32() % 600) as usize;
                check(&t, p, r.uniform_u32() as u64, len);
                check(&t, p, (1 << 40) - (r.uniform_u32() % 700) as u64, len);
                let big = ((r.uniform_u32() as u64) << 32) | r.uniform_u32() as u64;
                check(&t, p, big, len.min(40));
            }
            check(&t, p, u64::MAX - 5, 10);
        }
    }
}
