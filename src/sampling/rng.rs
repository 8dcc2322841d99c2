//! PCG32, bit-compatible with pbrt-v3's `RNG` (core/rng.h), plus a few
//! integer hashes used to seed independent streams without shared state.

/// `0x1.fffffep-1`: the largest `f32` below 1.
pub const ONE_MINUS_EPSILON: f32 = f32::from_bits(0x3f7f_ffff);

const PCG32_DEFAULT_STATE: u64 = 0x853c_49e6_748f_ea9b;
const PCG32_DEFAULT_STREAM: u64 = 0xda3e_39cb_94b9_5bdb;
const PCG32_MULT: u64 = 0x5851_f42d_4c95_7f2d;

/// Permuted congruential generator (O'Neill's PCG32), as pbrt-v3's `RNG`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

impl Default for Pcg32 {
    fn default() -> Self {
        Self::new()
    }
}

impl Pcg32 {
    /// pbrt-v3's default-constructed `RNG`.
    pub const fn new() -> Self {
        Self {
            state: PCG32_DEFAULT_STATE,
            inc: PCG32_DEFAULT_STREAM,
        }
    }

    /// pbrt-v3's `RNG(uint64_t sequenceIndex)`.
    pub fn with_sequence(initseq: u64) -> Self {
        let mut r = Self::new();
        r.set_sequence(initseq);
        r
    }

    /// pbrt-v3's `RNG::SetSequence`.
    #[inline]
    pub fn set_sequence(&mut self, initseq: u64) {
        self.seed(PCG32_DEFAULT_STATE, initseq);
    }

    /// The reference `pcg32_srandom_r(initstate, initseq)`.
    #[inline]
    pub fn seed(&mut self, initstate: u64, initseq: u64) {
        self.state = 0;
        self.inc = (initseq << 1) | 1;
        self.uniform_u32();
        self.state = self.state.wrapping_add(initstate);
        self.uniform_u32();
    }

    #[inline]
    pub fn uniform_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(PCG32_MULT).wrapping_add(self.inc);
        Self::output(old)
    }

    /// The value drawn from `state` (PCG's XSH RR output).
    #[inline(always)]
    pub(crate) fn output(state: u64) -> u32 {
        let xorshifted = (((state >> 18) ^ state) >> 27) as u32;
        let rot = (state >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// The state and increment.
    #[inline(always)]
    pub(crate) fn parts(&self) -> (u64, u64) {
        (self.state, self.inc)
    }

    /// Moves to `state` on the same stream.
    #[inline(always)]
    pub(crate) fn set_state(&mut self, state: u64) {
        self.state = state;
    }

    /// The multiplier of one step.
    pub(crate) const MULT: u64 = PCG32_MULT;

    /// Uniform in `[0, b)` without modulo bias (pbrt-v3's `UniformUInt32(b)`).
    #[inline]
    pub fn uniform_u32_below(&mut self, b: u32) -> u32 {
        debug_assert!(b > 0);
        let threshold = b.wrapping_neg() % b;
        loop {
            let r = self.uniform_u32();
            if r >= threshold {
                return r % b;
            }
        }
    }

    /// Uniform in `[0, 1)`.
    #[inline]
    pub fn uniform_f32(&mut self) -> f32 {
        (self.uniform_u32() as f32 * (1.0 / 4_294_967_296.0)).min(ONE_MINUS_EPSILON)
    }

    /// pbrt-v3's `RNG::Advance`: skip `delta` (two's complement) steps in O(log n).
    pub fn advance(&mut self, delta: i64) {
        let (acc_mult, acc_plus) = self.jump(delta as u64);
        self.state = acc_mult.wrapping_mul(self.state).wrapping_add(acc_plus);
    }

    /// `delta` steps of this stream as the affine map of the state they
    /// are, `(a, c)` with `s ↦ a·s + c` (mod 2^64).
    pub(crate) fn jump(&self, mut delta: u64) -> (u64, u64) {
        let mut cur_mult = PCG32_MULT;
        let mut cur_plus = self.inc;
        let mut acc_mult: u64 = 1;
        let mut acc_plus: u64 = 0;
        while delta > 0 {
            if delta & 1 != 0 {
                acc_mult = acc_mult.wrapping_mul(cur_mult);
                acc_plus = acc_plus.wrapping_mul(cur_mult).wrapping_add(cur_plus);
            }
            cur_plus = cur_mult.wrapping_add(1).wrapping_mul(cur_plus);
            cur_mult = cur_mult.wrapping_mul(cur_mult);
            delta /= 2;
        }
        (acc_mult, acc_plus)
    }
}

/// A strong 64-bit finaliser (splitmix64 / Stafford's mix 13).
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hash of several 64-bit words, order dependent.
#[inline]
pub fn hash_words(words: &[u64]) -> u64 {
    let mut h: u64 = 0x9e37_79b9_7f4a_7c15;
    for &w in words {
        h = mix64(h ^ mix64(w.wrapping_add(0x632b_e59b_d9b4_e019)));
    }
    h
}

/// A uniform `f32` in `[0, 1)` from the top 24 bits of a hash.
#[inline]
pub fn hash_to_unit(h: u64) -> f32 {
    ((h >> 40) as f32 * (1.0 / 16_777_216.0)).min(ONE_MINUS_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advance_matches_stepping() {
        let mut a = Pcg32::with_sequence(42);
        let mut b = a;
        for _ in 0..1000 {
            a.uniform_u32();
        }
        b.advance(1000);
        assert_eq!(a, b);
        b.advance(-1000);
        let c = Pcg32::with_sequence(42);
        assert_eq!(b, c);
    }

    #[test]
    fn reference_outputs() {
        // pcg32-demo's output for pcg32_srandom_r(42, 54).
        let mut r = Pcg32::new();
        r.seed(42, 54);
        let v: Vec<u32> = (0..6).map(|_| r.uniform_u32()).collect();
        assert_eq!(
            v,
            [0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e]
        );
    }

    #[test]
    fn floats_in_unit_interval() {
        let mut r = Pcg32::with_sequence(7);
        for _ in 0..100_000 {
            let u = r.uniform_f32();
            assert!((0.0..1.0).contains(&u));
        }
        let mut r = Pcg32::with_sequence(7);
        for b in 1..200 {
            assert!(r.uniform_u32_below(b) < b);
        }
    }
}
