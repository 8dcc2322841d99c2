//! Speed only: pbrt-v3's `RNG::UniformUInt32(b)` ([`Pcg32::uniform_u32_below`])
//! for the many draws below small bounds that shuffles make, with both of
//! its remainders (the rejection threshold and the result) taken by
//! multiplication (Lemire, Kaser and Kurz, "Faster remainder by direct
//! computation", 2019) from constants made once per bound, in place of two
//! integer divisions per draw. The draws and the RNG's state afterwards are
//! the plain method's, bit for bit (`tests::equals_plain`).

use super::rng::Pcg32;

/// `a % d` for any `a` and `d >= 1` from `m = ⌊(2^64 − 1) / d⌋ + 1`
/// (wrapping: 0 for `d = 1`).
#[inline(always)]
fn fastmod(a: u32, m: u64, d: u32) -> u32 {
    ((m.wrapping_mul(a as u64) as u128 * d as u128) >> 64) as u32
}

/// The constants of every bound from 1 to `max`.
#[derive(Clone, Debug, Default)]
pub struct BoundedDraws {
    /// `(m, threshold)` of bound `b` at index `b` (index 0 unused).
    consts: Vec<(u64, u32)>,
}

impl BoundedDraws {
    /// Constants for the bounds `1..=max`.
    pub fn new(max: u32) -> Self {
        let consts = (0..=max.max(1))
            .map(|b| {
                if b == 0 {
                    return (0, 0);
                }
                let m = (u64::MAX / b as u64).wrapping_add(1);
                (m, fastmod(b.wrapping_neg(), m, b))
            })
            .collect();
        Self { consts }
    }

    /// Largest bound covered.
    #[inline]
    pub fn max(&self) -> u32 {
        self.consts.len() as u32 - 1
    }

    /// Covers the bounds up to `max` too.
    pub fn cover(&mut self, max: u32) {
        if max > self.max() {
            *self = Self::new(max);
        }
    }

    /// `rng.uniform_u32_below(b)` for `1 <= b <= max()` (larger bounds take
    /// the plain method).
    #[inline]
    pub fn below(&self, rng: &mut Pcg32, b: u32) -> u32 {
        let Some(&(m, threshold)) = self.consts.get(b as usize) else {
            return rng.uniform_u32_below(b);
        };
        loop {
            let r = rng.uniform_u32();
            if r >= threshold {
                return fastmod(r, m, b);
            }
        }
    }
}

/// Draws computed side by side by [`BoundedDraws::skip_runs`] (the 64-bit
/// state arithmetic vectorised by the compiler): one minimum, one branch
/// and one step of the state per 32 draws.
const LANES: usize = 32;

/// The states `k = 0..=LANES` steps after a state `s`, as `a[k]·s + c[k]`
/// (mod 2^64) on one stream.
#[derive(Clone, Copy, Debug)]
pub struct Jumps {
    a: [u64; LANES + 1],
    c: [u64; LANES + 1],
}

impl Jumps {
    /// The jumps of `rng`'s stream.
    pub fn of(rng: &Pcg32) -> Self {
        let inc = rng.parts().1;
        let (mut a, mut c) = ([1u64; LANES + 1], [0u64; LANES + 1]);
        for k in 1..=LANES {
            a[k] = a[k - 1].wrapping_mul(Pcg32::MULT);
            c[k] = c[k - 1].wrapping_mul(Pcg32::MULT).wrapping_add(inc);
        }
        Self { a, c }
    }
}

/// A fixed number of steps of one stream as one affine map of the state,
/// `a·s + c` (mod 2^64): [`Pcg32::advance`] by that number, with its
/// constants ([`Pcg32::jump`]) made once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stride {
    a: u64,
    c: u64,
}

impl Stride {
    /// `delta` steps of `rng`'s stream.
    pub fn new(rng: &Pcg32, delta: u64) -> Self {
        let (a, c) = rng.jump(delta);
        Self { a, c }
    }

    /// Steps `rng` (on the stream the stride was made for).
    #[inline(always)]
    pub fn apply(&self, rng: &mut Pcg32) {
        let s = rng.parts().0;
        rng.set_state(self.a.wrapping_mul(s).wrapping_add(self.c));
    }
}

impl BoundedDraws {
    /// Steps `rng` (whose stream `jumps` describes) past the draws of
    /// `below(rng, count - i)` for `i` in `0..count` (a shuffle of `count`
    /// values) without making them.
    #[inline]
    pub fn skip(&self, rng: &mut Pcg32, jumps: &Jumps, count: usize) {
        self.skip_runs(rng, jumps, 1, count);
    }

    /// Steps `rng` (whose stream `jumps` describes) past the draws of
    /// `runs` shuffles of `per_run` values each, one after the other (draw
    /// `j` below `per_run - j % per_run`), without making them: [`LANES`]
    /// draws at a time, computed side by side from the state, are one step
    /// each when none of them is rejected, which holds when none is below
    /// `per_run` (every threshold is below its bound, at most `per_run`);
    /// a block where one is goes draw by draw.
    pub fn skip_runs(&self, rng: &mut Pcg32, jumps: &Jumps, runs: usize, per_run: usize) {
        let count = runs * per_run;
        let mut j = 0;
        while j < count {
            let m = (count - j).min(LANES);
            let s = rng.parts().0;
            let mut least = u32::MAX;
            for k in 0..LANES {
                let sk = jumps.a[k].wrapping_mul(s).wrapping_add(jumps.c[k]);
                let o = Pcg32::output(sk);
                least = least.min(if k < m { o } else { u32::MAX });
            }
            if least as usize >= per_run {
                rng.set_state(jumps.a[m].wrapping_mul(s).wrapping_add(jumps.c[m]));
            } else {
                for k in j..j + m {
                    self.below(rng, (per_run - k % per_run) as u32);
                }
            }
            j += m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fastmod_is_the_remainder() {
        let ds = [
            1u32,
            2,
            3,
            5,
            7,
            10,
            63,
            64,
            65,
            1000,
            4095,
            4096,
            65537,
            u32::MAX - 1,
            u32::MAX,
        ];
        let mut rng = Pcg32::new();
        for &d in &ds {
            let m = (u64::MAX / d as u64).wrapping_add(1);
            let mut aa = vec![
                0u32,
                1,
                d - 1,
                d,
                d.wrapping_add(1),
                u32::MAX,
                u32::MAX - 1,
                d.wrapping_neg(),
            ];
            aa.extend((0..2000).map(|_| rng.uniform_u32()));
            for a in aa {
                assert_eq!(fastmod(a, m, d), a % d, "{a} % {d}");
            }
        }
    }

    #[test]
    fn equals_plain() {
        let draws = BoundedDraws::new(300);
        assert_eq!(draws.max(), 300);
        let mut fast = Pcg32::new();
        fast.set_sequence(17);
        let mut plain = fast;
        // Every covered bound, and bounds past the table.
        for round in 0..40u32 {
            for b in 1..=310u32 {
                let b = if round % 7 == 3 { b * 1_000_003 } else { b };
                assert_eq!(
                    draws.below(&mut fast, b),
                    plain.uniform_u32_below(b),
                    "bound {b}"
                );
            }
        }
        assert_eq!(fast.uniform_u32(), plain.uniform_u32());
    }

    #[test]
    fn stride_is_advance() {
        for seq in [0u64, 1, 17, 1 << 40, u64::MAX >> 1] {
            let mut r = Pcg32::with_sequence(seq);
            r.uniform_u32();
            for delta in [0u64, 1, 2, 3, 7, 64, 65, 66, 1000, 1 << 33] {
                let mut a = r;
                let mut b = r;
                Stride::new(&r, delta).apply(&mut a);
                b.advance(delta as i64);
                assert_eq!(a, b, "sequence {seq} delta {delta}");
            }
            // A stride made on another stream moves this one elsewhere.
            let other = Pcg32::with_sequence(seq ^ 1);
            let mut a = r;
            Stride::new(&other, 5).apply(&mut a);
            let mut b = r;
            b.advance(5);
            assert_ne!(a, b);
        }
    }

    #[test]
    fn skip_equals_plain_draws() {
        let draws = BoundedDraws::new(4096);
        for seq in 0..200u64 {
            let mut fast = Pcg32::with_sequence(seq);
            let jumps = Jumps::of(&fast);
            let mut plain = fast;
            for count in [1usize, 2, 7, 8, 9, 16, 63, 64, 65, 1000, 4096] {
                draws.skip(&mut fast, &jumps, count);
                for i in 0..count {
                    plain.uniform_u32_below((count - i) as u32);
                }
                assert_eq!(fast, plain, "sequence {seq} count {count}");
            }
        }
        // State 0 draws 0 first: rejected below 9 (2^32 mod 9 = 4), taken
        // below 16 (no threshold) yet under the block test's bound.
        for count in [9usize, 16, 24, 100] {
            let mut fast = Pcg32::with_sequence(3);
            fast.set_state(0);
            let jumps = Jumps::of(&fast);
            let mut plain = fast;
            draws.skip(&mut fast, &jumps, count);
            for i in 0..count {
                plain.uniform_u32_below((count - i) as u32);
            }
            assert_eq!(fast, plain, "from state 0, count {count}");
        }
    }

    /// `runs` shuffles of `per_run` values, draw by draw.
    fn plain_runs(rng: &mut Pcg32, runs: usize, per_run: usize) {
        for _ in 0..runs {
            for i in 0..per_run {
                rng.uniform_u32_below((per_run - i) as u32);
            }
        }
    }

    #[test]
    fn skip_runs_equals_plain_draws() {
        let draws = BoundedDraws::new(64);
        for seq in 0..100u64 {
            let mut fast = Pcg32::with_sequence(seq);
            let jumps = Jumps::of(&fast);
            let mut plain = fast;
            for runs in [1usize, 2, 3, 64] {
                for per_run in [1usize, 2, 3, 9, 16, 31, 32, 33, 64] {
                    draws.skip_runs(&mut fast, &jumps, runs, per_run);
                    plain_runs(&mut plain, runs, per_run);
                    assert_eq!(fast, plain, "sequence {seq}, {runs} runs of {per_run}");
                }
            }
        }
        // Draw `k` made from state 0 (output 0) or 3·2^27 (output 3), so
        // that it is rejected (its bound, `per_run - k % per_run`, has a
        // threshold above the output: 2^32 mod 7 = 4) in the middle of a
        // later block, or taken (a power of two, or a threshold below it).
        for (state, k, per_run) in [
            (0u64, 40usize, 9usize),
            (0, 70, 9),
            (0, 33, 7),
            (0, 5, 6),
            (0, 95, 32),
            (0, 100, 33),
            (3 << 27, 35, 7),
            (3 << 27, 36, 7),
            (3 << 27, 64, 64),
        ] {
            let mut fast = Pcg32::with_sequence(11);
            fast.set_state(state);
            fast.advance(-(k as i64));
            let jumps = Jumps::of(&fast);
            let mut plain = fast;
            let runs = k / per_run + 2;
            draws.skip_runs(&mut fast, &jumps, runs, per_run);
            plain_runs(&mut plain, runs, per_run);
            assert_eq!(fast, plain, "state {state} at draw {k}, runs of {per_run}");
        }
    }
}
