//! Radical inverses and pbrt-v3's digit-permutation tables
//! (core/lowdiscrepancy.{h,cpp}), with integer digit extraction by
//! multiply-high instead of division.

use crate::sampling::rng::{Pcg32, ONE_MINUS_EPSILON};
use std::sync::{Arc, Mutex, OnceLock};

/// Number of primes in the table, as pbrt-v3's `PrimeTableSize`.
pub const PRIME_TABLE_SIZE: usize = 1000;

const fn compute_primes() -> [u32; PRIME_TABLE_SIZE] {
    let mut primes = [0u32; PRIME_TABLE_SIZE];
    let mut count = 0;
    let mut n = 2u32;
    while count < PRIME_TABLE_SIZE {
        let mut is_prime = true;
        let mut i = 0;
        while i < count {
            let p = primes[i];
            if p * p > n {
                break;
            }
            if n.is_multiple_of(p) {
                is_prime = false;
                break;
            }
            i += 1;
        }
        if is_prime {
            primes[count] = n;
            count += 1;
        }
        n += 1;
    }
    primes
}

/// The first 1000 primes (2 ..= 7919).
pub static PRIMES: [u32; PRIME_TABLE_SIZE] = compute_primes();

/// Radical inverse in base 2 by bit reversal: `a` mirrored about the binary point.
#[inline]
pub fn radical_inverse_base2(a: u64) -> f32 {
    let v = (a.reverse_bits() >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0);
    (v as f32).min(ONE_MINUS_EPSILON)
}

/// Per-dimension constants of the (scrambled) radical inverse.
#[derive(Clone, Copy, Debug)]
pub struct DigitBase {
    pub base: u32,
    /// `ceil(2^64 / base)`: `(n * magic) >> 64 == n / base` for every `n < 2^32`.
    magic: u64,
    inv_base: f64,
    /// `base²` and its magic number, to peel two digits per step.
    base2: u64,
    magic2: u64,
    inv_base2: f64,
}

impl DigitBase {
    /// `base` must be at least 2 and below 2^16 (so that `base²` < 2^32).
    pub const fn new(base: u32) -> Self {
        assert!(base >= 2 && base < 65536);
        let base2 = base as u64 * base as u64;
        Self {
            base,
            magic: u64::MAX / base as u64 + 1,
            inv_base: 1.0 / base as f64,
            base2,
            magic2: u64::MAX / base2 + 1,
            inv_base2: 1.0 / base2 as f64,
        }
    }

    /// `a / base`.
    #[inline(always)]
    pub fn div(&self, a: u64) -> u64 {
        self.div_rem(a).0
    }

    /// `(a / base², a % base²)`.
    #[inline(always)]
    fn div_rem2(&self, a: u64) -> (u64, u64) {
        let q = if a <= u32::MAX as u64 {
            ((a as u128 * self.magic2 as u128) >> 64) as u64
        } else {
            a / self.base2
        };
        (q, a - q * self.base2)
    }

    /// `(a / base, a % base)`.
    #[inline(always)]
    fn div_rem(&self, a: u64) -> (u64, u64) {
        let q = if a <= u32::MAX as u64 {
            ((a as u128 * self.magic as u128) >> 64) as u64
        } else {
            a / self.base as u64
        };
        (q, a - q * self.base as u64)
    }
}

/// Unscrambled radical inverse of `a` in `b.base`.
#[inline]
pub fn radical_inverse(b: &DigitBase, mut a: u64) -> f32 {
    let mut reversed: u64 = 0;
    let mut inv_base_n = 1.0f64;
    let base = b.base as u64;
    while a != 0 {
        let (next, digit) = b.div_rem(a);
        reversed = reversed.wrapping_mul(base).wrapping_add(digit);
        inv_base_n *= b.inv_base;
        a = next;
    }
    ((reversed as f64 * inv_base_n) as f32).min(ONE_MINUS_EPSILON)
}

/// Base-3 digits per table step of [`radical_inverse_base3`] (3^6 = 729).
const BASE3_CHUNK_DIGITS: u32 = 6;
const BASE3_CHUNK: u64 = 729;

/// For `v < 729`: its base-3 digits reversed as a number of exactly six
/// digits (`.0`), as a number of its own significant digits (`.1`), and how
/// many significant digits it has (`.2`).
static BASE3_CHUNKS: [(u16, u16, u8); BASE3_CHUNK as usize] = {
    let mut t = [(0u16, 0u16, 0u8); BASE3_CHUNK as usize];
    let mut v = 0;
    while v < BASE3_CHUNK as usize {
        let (mut a, mut rev, mut n) = (v, 0usize, 0u8);
        while a != 0 {
            rev = rev * 3 + a % 3;
            a /= 3;
            n += 1;
        }
        let mut full = rev;
        let mut k = n as u32;
        while k < BASE3_CHUNK_DIGITS {
            full *= 3;
            k += 1;
        }
        t[v] = (full as u16, rev as u16, n);
        v += 1;
    }
    t
};

/// `INV3_POWERS[n]`: 1/3 multiplied into 1.0 `n` times in f64, one step at
/// a time (the rounding of `radical_inverse`'s loop).
static INV3_POWERS: [f64; 48] = {
    let mut t = [1.0f64; 48];
    let mut i = 1;
    while i < 48 {
        t[i] = t[i - 1] * (1.0 / 3.0);
        i += 1;
    }
    t
};

/// `radical_inverse(&DigitBase::new(3), a)` bit for bit, six digits per
/// step from a table instead of one (the Halton sampler's second
/// dimension, drawn by every camera sample).
#[inline]
pub fn radical_inverse_base3(mut a: u64) -> f32 {
    let mut reversed: u64 = 0;
    let mut n = 0usize;
    while a >= BASE3_CHUNK {
        let next = a / BASE3_CHUNK;
        let chunk = BASE3_CHUNKS[(a - next * BASE3_CHUNK) as usize];
        reversed = reversed
            .wrapping_mul(BASE3_CHUNK)
            .wrapping_add(chunk.0 as u64);
        n += BASE3_CHUNK_DIGITS as usize;
        a = next;
    }
    let (_, rev, digits) = BASE3_CHUNKS[a as usize];
    reversed = reversed
        .wrapping_mul(3u64.pow(digits as u32))
        .wrapping_add(rev as u64);
    n += digits as usize;
    ((reversed as f64 * INV3_POWERS[n]) as f32).min(ONE_MINUS_EPSILON)
}

/// Largest chunk of digits [`RadicalTable`] looks up at once.
const RADICAL_CHUNK_MAX: u64 = 4096;

/// The unscrambled radical inverse in one base, several digits per step
/// from a table (`radical_inverse` bit for bit): a chunk of `k` digits,
/// `base^k ≤ 4096`, costs one multiply-high and one load where the plain
/// loop pays `k` dependent multiply-highs. Base 2 reverses the bits (below
/// 2^53, where that is exact); bases above 64 (one digit per chunk) use the
/// plain loop.
pub struct RadicalTable {
    pub(super) base: DigitBase,
    /// `base^k`, the chunk, and its magic number (as [`DigitBase`]'s).
    pub(super) chunk: u64,
    chunk_magic: u64,
    pub(super) k: usize,
    /// For `v < chunk`: its `k` digits reversed (`.0`), its significant
    /// digits reversed (`.1`), and how many those are (`.2`). Empty where
    /// the table is not used (base 2 below 2^53, whose bits are reversed,
    /// and bases above 64).
    pub(super) entries: Box<[(u16, u16, u16)]>,
    /// `base^n` for `n ≤ k`.
    pow: [u64; 13],
    /// 1/base multiplied into 1.0 `n` times in f64, one step at a time (the
    /// rounding of `radical_inverse`'s loop).
    pub(super) inv_powers: [f64; 65],
}

impl RadicalTable {
    pub fn new(base: u32) -> RadicalTable {
        let b = DigitBase::new(base);
        let (mut chunk, mut k) = (1u64, 0usize);
        while chunk * base as u64 <= RADICAL_CHUNK_MAX {
            chunk *= base as u64;
            k += 1;
        }
        let mut pow = [1u64; 13];
        for n in 1..=k {
            pow[n] = pow[n - 1] * base as u64;
        }
        let mut inv_powers = [1.0f64; 65];
        for n in 1..65 {
            inv_powers[n] = inv_powers[n - 1] * b.inv_base;
        }
        let entries = if k < 2 {
            Box::default()
        } else {
            (0..chunk)
                .map(|v| {
                    let (mut a, mut rev, mut n) = (v, 0u64, 0usize);
                    while a != 0 {
                        rev = rev * base as u64 + a % base as u64;
                        a /= base as u64;
                        n += 1;
                    }
                    ((rev * pow[k - n]) as u16, rev as u16, n as u16)
                })
                .collect()
        };
        RadicalTable {
            base: b,
            chunk,
            // (Unused where the chunk is a single digit or less.)
            chunk_magic: (u64::MAX / chunk).wrapping_add(1),
            k,
            entries,
            pow,
            inv_powers,
        }
    }

    /// `radical_inverse(&DigitBase::new(base), a)`, bit for bit.
    #[inline]
    pub fn radical_inverse(&self, a: u64) -> f32 {
        if self.base.base == 2 && a < 1 << 53 {
            return radical_inverse_base2(a);
        }
        if self.entries.is_empty() {
            return radical_inverse(&self.base, a);
        }
        let (reversed, n) = self.reversed_digits(a);
        ((reversed as f64 * self.inv_powers[n]) as f32).min(ONE_MINUS_EPSILON)
    }

    /// The significant digits of `a` reversed (wrapping) and how many they
    /// are, for a base with a table.
    #[inline(always)]
    pub(super) fn reversed_digits(&self, mut a: u64) -> (u64, usize) {
        let mut reversed: u64 = 0;
        let mut n = 0usize;
        while a >= self.chunk {
            let next = if a <= u32::MAX as u64 {
                ((a as u128 * self.chunk_magic as u128) >> 64) as u64
            } else {
                a / self.chunk
            };
            let e = self.entries[(a - next * self.chunk) as usize];
            reversed = reversed.wrapping_mul(self.chunk).wrapping_add(e.0 as u64);
            n += self.k;
            a = next;
        }
        let e = self.entries[a as usize];
        reversed = reversed
            .wrapping_mul(self.pow[e.2 as usize])
            .wrapping_add(e.1 as u64);
        n += e.2 as usize;
        (reversed, n)
    }
}

/// Radical inverse with every digit (including the infinitely many leading
/// zeros) mapped through `perm` (pbrt-v3's `ScrambledRadicalInverse`).
#[inline]
pub fn scrambled_radical_inverse(b: &DigitBase, perm: &[u16], tail: f64, mut a: u64) -> f32 {
    let base = b.base as u64;
    debug_assert_eq!(perm.len(), b.base as usize);
    let mut reversed: u64 = 0;
    let mut inv_base_n = 1.0f64;
    // Two digits per step: the dependency chain is one multiply-high per pair.
    while a >= b.base2 {
        let (next, pair) = b.div_rem2(a);
        let (hi, lo) = b.div_rem(pair);
        let digits = perm[lo as usize] as u64 * base + perm[hi as usize] as u64;
        reversed = reversed.wrapping_mul(b.base2).wrapping_add(digits);
        inv_base_n *= b.inv_base2;
        a = next;
    }
    if a >= base {
        let (hi, lo) = b.div_rem(a);
        let digits = perm[lo as usize] as u64 * base + perm[hi as usize] as u64;
        reversed = reversed.wrapping_mul(b.base2).wrapping_add(digits);
        inv_base_n *= b.inv_base2;
    } else if a != 0 {
        reversed = reversed
            .wrapping_mul(base)
            .wrapping_add(perm[a as usize] as u64);
        inv_base_n *= b.inv_base;
    }
    // The tail of permuted zero digits sums to perm[0] / (base - 1)
    // (`tail`, see `scramble_tail`).
    ((inv_base_n * (reversed as f64 + tail)) as f32).min(ONE_MINUS_EPSILON)
}

/// `scrambled_radical_inverse` with a table of digit pairs: entry
/// `hi * base + lo` (< `base²`) is `perm[lo] * base + perm[hi]`, the pair
/// reversed and permuted, and entry `base² + d` is `perm[d]`; so a pair
/// costs one load. Bit-identical to `scrambled_radical_inverse`.
#[inline(always)]
pub fn scrambled_radical_inverse_pairs(b: &DigitBase, table: &[u16], tail: f64, mut a: u64) -> f32 {
    let base = b.base as u64;
    let base2 = b.base2;
    debug_assert_eq!(table.len() as u64, base2 + base);
    let mut reversed: u64 = 0;
    let mut inv_base_n = 1.0f64;
    // Indices past 2^32 (not met in practice) divide until the rest fits
    // the multiply-high below (`DigitBase::div_rem2` in two loops, so that
    // the hot one has no branch on the index's size: 0.8% of cornell-direct's
    // instructions).
    while a > u32::MAX as u64 {
        let next = a / base2;
        reversed = reversed
            .wrapping_mul(base2)
            .wrapping_add(table[(a - next * base2) as usize] as u64);
        inv_base_n *= b.inv_base2;
        a = next;
    }
    while a >= base2 {
        let next = ((a as u128 * b.magic2 as u128) >> 64) as u64;
        reversed = reversed
            .wrapping_mul(base2)
            .wrapping_add(table[(a - next * base2) as usize] as u64);
        inv_base_n *= b.inv_base2;
        a = next;
    }
    if a >= base {
        reversed = reversed
            .wrapping_mul(base2)
            .wrapping_add(table[a as usize] as u64);
        inv_base_n *= b.inv_base2;
    } else if a != 0 {
        reversed = reversed
            .wrapping_mul(base)
            .wrapping_add(table[(base2 + a) as usize] as u64);
        inv_base_n *= b.inv_base;
    }
    ((inv_base_n * (reversed as f64 + tail)) as f32).min(ONE_MINUS_EPSILON)
}

/// The value of infinitely many permuted zero digits, `perm[0] / (base - 1)`
/// (the `tail` of `scrambled_radical_inverse`).
pub fn scramble_tail(perm: &[u16]) -> f64 {
    perm[0] as f64 / (perm.len() - 1) as f64
}

/// Inverse of the radical inverse on the first `n_digits` digits
/// (pbrt-v3's `InverseRadicalInverse<base>`).
#[inline]
pub fn inverse_radical_inverse(base: u64, mut inverse: u64, n_digits: u32) -> u64 {
    let mut index = 0;
    for _ in 0..n_digits {
        let digit = inverse % base;
        inverse /= base;
        index = index * base + digit;
    }
    index
}

/// Bases up to this one also get a table of permuted digit pairs (`base²`
/// entries: 16,129 for 127, all bases together 144,000 entries).
pub const PAIR_TABLE_MAX_BASE: u32 = 127;

/// Everything one scrambled dimension needs, in one place.
#[derive(Clone, Copy, Debug)]
struct ScrambledDim {
    b: DigitBase,
    tail: f64,
    /// Start of the permutation in `perms`.
    perm: u32,
    /// Start of the pair table in `pairs`, or `NO_PAIRS`.
    pairs: u32,
}

const NO_PAIRS: u32 = u32::MAX;

/// Digit permutations for every prime base, concatenated (pbrt-v3's
/// `ComputeRadicalInversePermutations`), with per-dimension bases, and
/// tables of permuted digit pairs (then the permutation again) for the
/// small bases.
#[derive(Debug)]
pub struct PermutationTables {
    perms: Vec<u16>,
    pairs: Vec<u16>,
    dims: Vec<ScrambledDim>,
    /// Read by the AVX2 block only (builds without AVX2 take the scalar loop).
    #[cfg_attr(
        not(all(target_arch = "x86_64", target_feature = "avx2")),
        allow(dead_code)
    )]
    lanes: BlockLanes,
    late: OnceLock<LateTables>,
    /// The generator as the first `EAGER_PRIMES` permutations left it.
    late_rng: Pcg32,
}

/// Permutations generated up front: the bases of the dimensions the Halton
/// blocks compute and more (a path of default depth reads about 70). The
/// other 872 (3.6 million entries, 7 MiB, 16 ms of shuffling) come when a
/// dimension past 127 is first read.
const EAGER_PRIMES: usize = 128;
// The block constants and gathers read the eager tables only.
const _: () = assert!(EAGER_PRIMES >= BLOCK_DIM_END);

/// The permutations of the bases past `EAGER_PRIMES` (offsets in `perms`).
#[derive(Debug)]
struct LateTables {
    perms: Vec<u16>,
    dims: Vec<ScrambledDim>,
}

/// Appends pbrt-v3's permutation of the digits of base `p` (its
/// `Shuffle(p, count, 1, rng)` of the identity) to `perms`.
fn push_permutation(p: u32, rng: &mut Pcg32, perms: &mut Vec<u16>) -> ScrambledDim {
    let off = perms.len();
    perms.extend(0..p as u16);
    let slice = &mut perms[off..];
    for i in 0..p as usize {
        let other = i + rng.uniform_u32_below(p - i as u32) as usize;
        slice.swap(i, other);
    }
    ScrambledDim {
        b: DigitBase::new(p),
        tail: scramble_tail(slice),
        perm: off as u32,
        pairs: NO_PAIRS,
    }
}

/// Dimensions `2..BLOCK_DIM_END` (bases 5 ..= 503) can be computed
/// `BLOCK_LANES` at a time by `scrambled_block`: a path of `path`'s default
/// depth reads about 70 dimensions, eight per bounce. Past base 127 a block
/// costs one pass of two digit pairs where one dimension at a time costs
/// four digit steps (cornell-path: 1.1% fewer instructions than with
/// blocks up to base 127 only, 2% less time).
pub const BLOCK_DIM_END: usize = 96;
/// Dimensions per `scrambled_block` call: 8 lanes, two AVX2 vectors of f64.
pub const BLOCK_LANES: usize = 8;
/// Blocks below this dimension (bases up to 61) read the pair tables;
/// later ones the permutations.
const PAIR_BLOCK_DIM_END: usize = 18;

/// Per-dimension constants of the block dimensions as structure of
/// arrays (indexed by dimension, padded by `BLOCK_LANES` past
/// `BLOCK_DIM_END` with harmless values), so that a block of consecutive
/// dimensions loads each constant as one vector.
#[derive(Debug)]
#[repr(C, align(64))]
struct BlockLanes {
    base: [f64; LANES_LEN],
    base2: [f64; LANES_LEN],
    inv_base: [f64; LANES_LEN],
    inv_base2: [f64; LANES_LEN],
    tail: [f64; LANES_LEN],
    /// Start of the dimension's pair table in `pairs`.
    pairs: [i32; LANES_LEN],
    /// Start of the dimension's permutation in `perms`.
    perm: [i32; LANES_LEN],
}

/// A lane set's constants for `scrambled_lanes_avx2`: base, base²,
/// their reciprocals, the zero-digit tail (four lanes each in `.0`, four
/// in `.1`) and the offset of the pair table or permutation.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
struct LaneConsts {
    b: (std::arch::x86_64::__m256d, std::arch::x86_64::__m256d),
    b2: (std::arch::x86_64::__m256d, std::arch::x86_64::__m256d),
    ib: (std::arch::x86_64::__m256d, std::arch::x86_64::__m256d),
    ib2: (std::arch::x86_64::__m256d, std::arch::x86_64::__m256d),
    tail: (std::arch::x86_64::__m256d, std::arch::x86_64::__m256d),
    off: (std::arch::x86_64::__m128i, std::arch::x86_64::__m128i),
}

/// Entries of each `BlockLanes` array.
const LANES_LEN: usize = BLOCK_DIM_END + BLOCK_LANES;

impl BlockLanes {
    /// The constants in arrays of their own inside the tables (not
    /// separate allocations: where the allocator put those, the loads of a
    /// block's constants could stall, 12% of the block's time).
    fn new(dims: &[ScrambledDim]) -> Self {
        // Dimensions 0 and 1 and the padding reuse dimension 2's
        // constants; their lanes are computed and ignored.
        let dim = |d: usize| {
            let s = &dims[if (2..BLOCK_DIM_END).contains(&d) {
                d
            } else {
                2
            }];
            debug_assert!(d >= PAIR_BLOCK_DIM_END || s.pairs != NO_PAIRS);
            s
        };
        BlockLanes {
            base: std::array::from_fn(|d| dim(d).b.base as f64),
            base2: std::array::from_fn(|d| dim(d).b.base2 as f64),
            inv_base: std::array::from_fn(|d| dim(d).b.inv_base),
            inv_base2: std::array::from_fn(|d| dim(d).b.inv_base2),
            tail: std::array::from_fn(|d| dim(d).tail),
            pairs: std::array::from_fn(|d| dim(d).pairs as i32),
            perm: std::array::from_fn(|d| dim(d).perm as i32),
        }
    }
}

impl PermutationTables {
    /// Tables generated from `rng` exactly as pbrt-v3 does (it passes a
    /// default-constructed `RNG`): the first `EAGER_PRIMES` bases now, the
    /// rest (99% of the entries, read only by dimensions past 127) on first
    /// use, from the generator's state where the first ones left it.
    pub fn generate(rng: &mut Pcg32) -> Self {
        let mut perms = Vec::new();
        let mut pairs = Vec::new();
        let mut dims = Vec::with_capacity(EAGER_PRIMES);
        for &p in &PRIMES[..EAGER_PRIMES] {
            let mut d = push_permutation(p, rng, &mut perms);
            if p <= PAIR_TABLE_MAX_BASE {
                let perm = &perms[d.perm as usize..];
                d.pairs = pairs.len() as u32;
                for hi in 0..p as usize {
                    for lo in 0..p as usize {
                        pairs.push(perm[lo] * p as u16 + perm[hi]);
                    }
                }
                pairs.extend_from_slice(perm);
            }
            dims.push(d);
        }
        // The AVX2 gather reads 32 bits at a 16-bit entry: one entry of
        // padding keeps the last read inside the table.
        pairs.push(0);
        let lanes = BlockLanes::new(&dims);
        Self {
            perms,
            pairs,
            dims,
            lanes,
            late: OnceLock::new(),
            late_rng: *rng,
        }
    }

    /// The permutations of the bases past `EAGER_PRIMES`.
    #[cold]
    fn late(&self) -> &LateTables {
        self.late.get_or_init(|| {
            let mut rng = self.late_rng;
            let mut perms = Vec::new();
            let dims = PRIMES[EAGER_PRIMES..]
                .iter()
                .map(|&p| push_permutation(p, &mut rng, &mut perms))
                .collect();
            LateTables { perms, dims }
        })
    }

    /// Base, permutation and tail of prime dimension `dim`, and the table
    /// its permutation is in.
    #[inline(always)]
    fn dim(&self, dim: usize) -> (&ScrambledDim, &[u16]) {
        if dim < EAGER_PRIMES {
            (&self.dims[dim], &self.perms)
        } else {
            let late = self.late();
            (&late.dims[dim - EAGER_PRIMES], &late.perms)
        }
    }

    /// Shared tables for a seed: seed 0 gives pbrt-v3's own permutations
    /// (default `RNG`); other seeds use the PCG32 stream `seed`.
    pub fn shared(seed: u64) -> Arc<PermutationTables> {
        static DEFAULT: OnceLock<Arc<PermutationTables>> = OnceLock::new();
        static OTHERS: Mutex<Vec<(u64, Arc<PermutationTables>)>> = Mutex::new(Vec::new());
        if seed == 0 {
            return DEFAULT
                .get_or_init(|| Arc::new(Self::generate(&mut Pcg32::new())))
                .clone();
        }
        let mut others = OTHERS.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, t)) = others.iter().find(|(s, _)| *s == seed) {
            return t.clone();
        }
        let t = Arc::new(Self::generate(&mut Pcg32::with_sequence(seed)));
        if others.len() >= 8 {
            others.remove(0);
        }
        others.push((seed, t.clone()));
        t
    }

    /// Base, permutation and zero-digit tail of prime dimension `dim`
    /// (< PRIME_TABLE_SIZE): what `scrambled` is checked against.
    #[cfg(test)]
    pub fn dimension(&self, dim: usize) -> (&DigitBase, &[u16], f64) {
        let (d, perms) = self.dim(dim);
        let off = d.perm as usize;
        (&d.b, &perms[off..off + d.b.base as usize], d.tail)
    }

    /// The scrambled radical inverse of `a` in prime dimension `dim`
    /// (< PRIME_TABLE_SIZE): `scrambled_radical_inverse` with the
    /// dimension's tables, bit for bit.
    #[inline(always)]
    pub fn scrambled(&self, dim: usize, a: u64) -> f32 {
        let (d, perms) = self.dim(dim);
        if d.pairs != NO_PAIRS {
            let n = (d.b.base2 + d.b.base as u64) as usize;
            let table = &self.pairs[d.pairs as usize..d.pairs as usize + n];
            scrambled_radical_inverse_pairs(&d.b, table, d.tail, a)
        } else {
            let perm = &perms[d.perm as usize..d.perm as usize + d.b.base as usize];
            scrambled_radical_inverse(&d.b, perm, d.tail, a)
        }
    }
}

impl PermutationTables {
    /// `scrambled(first + k, a)` for `k < BLOCK_LANES` into `out[k]`, bit
    /// for bit, with the dimensions in SIMD lanes; `first` in
    /// `2..BLOCK_DIM_END` and `a <= u32::MAX`. Lanes at or past
    /// `BLOCK_DIM_END` hold unspecified values.
    #[inline]
    pub fn scrambled_block(&self, first: usize, a: u64, out: &mut [f32; BLOCK_LANES]) {
        assert!((2..BLOCK_DIM_END).contains(&first) && a <= u32::MAX as u64);
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        // SAFETY: AVX2 is enabled at compile time; the constant loads stay
        // inside `lanes` (padded by BLOCK_LANES past BLOCK_DIM_END) and
        // every gather index is an entry of the pair table or a digit of
        // the permutation of a dimension below BLOCK_DIM_END (the pair
        // tables are padded for the 32-bit read; the permutations of these
        // bases, up to 503, start `perms`, whose later ones keep the reads
        // inside it).
        unsafe {
            if first + BLOCK_LANES <= PAIR_BLOCK_DIM_END {
                self.scrambled_block_avx2::<true>(first, a as u32, out)
            } else {
                self.scrambled_block_avx2::<false>(first, a as u32, out)
            }
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        for (k, v) in out.iter_mut().enumerate() {
            *v = self.scrambled((first + k).min(BLOCK_DIM_END - 1), a);
        }
    }

    /// `scrambled(dims[k / 4], a[k])` for `k < BLOCK_LANES` into `out[k]`,
    /// bit for bit, with the indices in SIMD lanes (four entries of a
    /// sample array, both of its dimensions); `dims` in `2..BLOCK_DIM_END`.
    #[inline]
    pub fn scrambled_indices(
        &self,
        dims: [usize; 2],
        a: &[u32; BLOCK_LANES],
        out: &mut [f32; BLOCK_LANES],
    ) {
        assert!(dims.iter().all(|d| (2..BLOCK_DIM_END).contains(d)));
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        // SAFETY: AVX2 is enabled at compile time; `dims` are block
        // dimensions, whose constants are inside `lanes` and whose gathers
        // stay inside their pair tables or permutations (as the block's).
        unsafe {
            if dims[0].max(dims[1]) < PAIR_BLOCK_DIM_END {
                self.scrambled_indices_avx2::<true>(dims, a, out)
            } else {
                self.scrambled_indices_avx2::<false>(dims, a, out)
            }
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        for (k, (v, &a)) in out.iter_mut().zip(a).enumerate() {
            *v = self.scrambled(dims[k / 4], a as u64);
        }
    }

    /// `scrambled_radical_inverse_pairs` in eight lanes: the same steps
    /// per lane (two digits while `a >= base²`, then one or two), the
    /// reversed digits held exactly in f64 (below 2^41), quotients by
    /// correctly rounded division (exact when floored, for `a < 2^53`).
    /// A pair of digits is one load from the pair tables (`PAIRS`) or two
    /// from the permutations: the pair tables of bases past 61 (250 KiB)
    /// miss the first- and second-level caches, the permutations (3 KiB up
    /// to base 127) do not, and the pair tables below (41 KiB) mostly hit.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    #[inline]
    unsafe fn scrambled_block_avx2<const PAIRS: bool>(
        &self,
        first: usize,
        a: u32,
        out: &mut [f32; BLOCK_LANES],
    ) {
        use std::arch::x86_64::*;
        let l = &self.lanes;
        let ld = |v: &[f64; LANES_LEN], k: usize| _mm256_loadu_pd(v.as_ptr().add(first + k));
        let offsets = if PAIRS { &l.pairs } else { &l.perm };
        let c = LaneConsts {
            b: (ld(&l.base, 0), ld(&l.base, 4)),
            b2: (ld(&l.base2, 0), ld(&l.base2, 4)),
            ib: (ld(&l.inv_base, 0), ld(&l.inv_base, 4)),
            ib2: (ld(&l.inv_base2, 0), ld(&l.inv_base2, 4)),
            tail: (ld(&l.tail, 0), ld(&l.tail, 4)),
            off: (
                _mm_loadu_si128(offsets.as_ptr().add(first) as *const __m128i),
                _mm_loadu_si128(offsets.as_ptr().add(first + 4) as *const __m128i),
            ),
        };
        let a = _mm256_set1_pd(a as f64);
        self.scrambled_lanes_avx2::<PAIRS>(&c, (a, a), out)
    }

    /// `scrambled(dims[k / 4], a[k])` for the eight indices `a` into
    /// `out[k]`, bit for bit (the block's lanes with one dimension's
    /// constants in each half and an index of their own); `dims` in
    /// `2..BLOCK_DIM_END`.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    #[inline]
    unsafe fn scrambled_indices_avx2<const PAIRS: bool>(
        &self,
        [lo, hi]: [usize; 2],
        a: &[u32; BLOCK_LANES],
        out: &mut [f32; BLOCK_LANES],
    ) {
        use std::arch::x86_64::*;
        let l = &self.lanes;
        let sp = |v: &[f64; LANES_LEN]| (_mm256_set1_pd(v[lo]), _mm256_set1_pd(v[hi]));
        let offsets = if PAIRS { &l.pairs } else { &l.perm };
        let c = LaneConsts {
            b: sp(&l.base),
            b2: sp(&l.base2),
            ib: sp(&l.inv_base),
            ib2: sp(&l.inv_base2),
            tail: sp(&l.tail),
            off: (_mm_set1_epi32(offsets[lo]), _mm_set1_epi32(offsets[hi])),
        };
        let a_lo = _mm256_cvtepi32_pd(_mm_loadu_si128(a.as_ptr() as *const __m128i));
        let a_hi = _mm256_cvtepi32_pd(_mm_loadu_si128(a.as_ptr().add(4) as *const __m128i));
        // The indices are unsigned: those past i32::MAX read as negative.
        let wrap = |x: __m256d| {
            let neg = _mm256_cmp_pd::<_CMP_LT_OQ>(x, _mm256_setzero_pd());
            _mm256_add_pd(x, _mm256_and_pd(neg, _mm256_set1_pd(4_294_967_296.0)))
        };
        self.scrambled_lanes_avx2::<PAIRS>(&c, (wrap(a_lo), wrap(a_hi)), out)
    }

    /// The eight lanes of `scrambled_block_avx2` and
    /// `scrambled_indices_avx2`: lane `k` (of `lo` for k < 4, else `hi`)
    /// is the scrambled radical inverse of index `a` with the base,
    /// reciprocals, tail and table offset in the lanes of `c`.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    #[inline(always)]
    unsafe fn scrambled_lanes_avx2<const PAIRS: bool>(
        &self,
        c: &LaneConsts,
        (a_lo, a_hi): (std::arch::x86_64::__m256d, std::arch::x86_64::__m256d),
        out: &mut [f32; BLOCK_LANES],
    ) {
        use std::arch::x86_64::*;
        let (b_lo, b_hi) = c.b;
        let (b2_lo, b2_hi) = c.b2;
        let (ib_lo, ib_hi) = c.ib;
        let (ib2_lo, ib2_hi) = c.ib2;
        let (off_lo, off_hi) = c.off;
        let table = if PAIRS {
            self.pairs.as_ptr() as *const i32
        } else {
            self.perms.as_ptr() as *const i32
        };
        let low16 = _mm_set1_epi32(0xffff);
        // Entry `i` of a dimension's pair table or permutation, for 4 lanes.
        let gather = |i: __m256d, off: __m128i| {
            let idx = _mm_add_epi32(_mm256_cvttpd_epi32(i), off);
            _mm256_cvtepi32_pd(_mm_and_si128(_mm_i32gather_epi32::<2>(table, idx), low16))
        };
        // (floor(a / b), a mod b) for integers a < 2^32, b < 2^16 held in
        // f64, from `inv` = 1 / b rounded.
        let divmod = |a: __m256d, b: __m256d, inv: __m256d| {
            let q = _mm256_floor_pd(_mm256_mul_pd(a, inv));
            let r = _mm256_sub_pd(a, _mm256_mul_pd(q, b));
            let zero = _mm256_setzero_pd();
            let one = _mm256_set1_pd(1.0);
            let low = _mm256_cmp_pd::<_CMP_LT_OQ>(r, zero);
            let q = _mm256_sub_pd(q, _mm256_and_pd(low, one));
            let r = _mm256_add_pd(r, _mm256_and_pd(low, b));
            let high = _mm256_cmp_pd::<_CMP_GE_OQ>(r, b);
            (
                _mm256_add_pd(q, _mm256_and_pd(high, one)),
                _mm256_sub_pd(r, _mm256_and_pd(high, b)),
            )
        };
        // The pair of digits `r` = hi · base + lo (< base²) reversed and
        // permuted, perm[lo] · base + perm[hi] (the pair table's entry
        // `r`), from the permutations.
        let pair = |r: __m256d, b: __m256d, inv: __m256d, off: __m128i| {
            let (hi, lo) = divmod(r, b, inv);
            let p_lo = gather(lo, off);
            (_mm256_add_pd(_mm256_mul_pd(p_lo, b), gather(hi, off)), p_lo)
        };
        // Appends digits `d` (a number below `mul`, whose reciprocal is
        // `inv_mul`) to the reversed digits and the scale, in the lanes of
        // `mask`.
        let push = |rev: __m256d,
                    inv: __m256d,
                    d: __m256d,
                    mul: __m256d,
                    inv_mul: __m256d,
                    mask: __m256d| {
            (
                _mm256_blendv_pd(rev, _mm256_add_pd(_mm256_mul_pd(rev, mul), d), mask),
                _mm256_blendv_pd(inv, _mm256_mul_pd(inv, inv_mul), mask),
            )
        };
        let (mut a_lo, mut a_hi) = (a_lo, a_hi);
        let mut rev_lo = _mm256_setzero_pd();
        let mut rev_hi = rev_lo;
        let mut inv_lo = _mm256_set1_pd(1.0);
        let mut inv_hi = inv_lo;
        loop {
            let m_lo = _mm256_cmp_pd::<_CMP_GE_OQ>(a_lo, b2_lo);
            let m_hi = _mm256_cmp_pd::<_CMP_GE_OQ>(a_hi, b2_hi);
            if _mm256_movemask_pd(_mm256_or_pd(m_lo, m_hi)) == 0 {
                break;
            }
            // a / base² by the reciprocal: the estimate is off by at most
            // one (a < 2^32, so every product here is exact), which the
            // remainder's sign and size correct.
            let (q_lo, r_lo) = divmod(a_lo, b2_lo, ib2_lo);
            let (q_hi, r_hi) = divmod(a_hi, b2_hi, ib2_hi);
            let (d_lo, d_hi) = if PAIRS {
                (gather(r_lo, off_lo), gather(r_hi, off_hi))
            } else {
                (
                    pair(r_lo, b_lo, ib_lo, off_lo).0,
                    pair(r_hi, b_hi, ib_hi, off_hi).0,
                )
            };
            (rev_lo, inv_lo) = push(rev_lo, inv_lo, d_lo, b2_lo, ib2_lo, m_lo);
            (rev_hi, inv_hi) = push(rev_hi, inv_hi, d_hi, b2_hi, ib2_hi, m_hi);
            a_lo = _mm256_blendv_pd(a_lo, q_lo, m_lo);
            a_hi = _mm256_blendv_pd(a_hi, q_hi, m_hi);
        }
        // The last one or two digits: the pair `a` when `a >= base`, else
        // the digit perm[a] when `a != 0` (pair-table entry `base² + a`;
        // lo = a, hi = 0 from the permutations).
        let zero = _mm256_setzero_pd();
        let two_lo = _mm256_cmp_pd::<_CMP_GE_OQ>(a_lo, b_lo);
        let two_hi = _mm256_cmp_pd::<_CMP_GE_OQ>(a_hi, b_hi);
        let nz_lo = _mm256_cmp_pd::<_CMP_GT_OQ>(a_lo, zero);
        let nz_hi = _mm256_cmp_pd::<_CMP_GT_OQ>(a_hi, zero);
        let (d_lo, d_hi) = if PAIRS {
            let i_lo = _mm256_blendv_pd(_mm256_add_pd(a_lo, b2_lo), a_lo, two_lo);
            let i_hi = _mm256_blendv_pd(_mm256_add_pd(a_hi, b2_hi), a_hi, two_hi);
            (gather(i_lo, off_lo), gather(i_hi, off_hi))
        } else {
            let (p2_lo, p1_lo) = pair(a_lo, b_lo, ib_lo, off_lo);
            let (p2_hi, p1_hi) = pair(a_hi, b_hi, ib_hi, off_hi);
            (
                _mm256_blendv_pd(p1_lo, p2_lo, two_lo),
                _mm256_blendv_pd(p1_hi, p2_hi, two_hi),
            )
        };
        let mul_lo = _mm256_blendv_pd(b_lo, b2_lo, two_lo);
        let mul_hi = _mm256_blendv_pd(b_hi, b2_hi, two_hi);
        let im_lo = _mm256_blendv_pd(ib_lo, ib2_lo, two_lo);
        let im_hi = _mm256_blendv_pd(ib_hi, ib2_hi, two_hi);
        (rev_lo, inv_lo) = push(rev_lo, inv_lo, d_lo, mul_lo, im_lo, nz_lo);
        (rev_hi, inv_hi) = push(rev_hi, inv_hi, d_hi, mul_hi, im_hi, nz_hi);
        let v_lo = _mm256_mul_pd(inv_lo, _mm256_add_pd(rev_lo, c.tail.0));
        let v_hi = _mm256_mul_pd(inv_hi, _mm256_add_pd(rev_hi, c.tail.1));
        let cap = _mm_set1_ps(ONE_MINUS_EPSILON);
        let f_lo = _mm_min_ps(_mm256_cvtpd_ps(v_lo), cap);
        let f_hi = _mm_min_ps(_mm256_cvtpd_ps(v_hi), cap);
        _mm_storeu_ps(out.as_mut_ptr(), f_lo);
        _mm_storeu_ps(out.as_mut_ptr().add(4), f_hi);
    }
}

/// pbrt-v3's `multiplicativeInverse(a, n)` via the extended Euclid algorithm.
pub fn multiplicative_inverse(a: i64, n: i64) -> u64 {
    fn extended_gcd(a: i64, b: i64) -> (i64, i64) {
        if b == 0 {
            return (1, 0);
        }
        let d = a / b;
        let (xp, yp) = extended_gcd(b, a % b);
        (yp, xp - d * yp)
    }
    let (x, _) = extended_gcd(a, n);
    x.rem_euclid(n) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primes_table() {
        assert_eq!(&PRIMES[..6], &[2, 3, 5, 7, 11, 13]);
        assert_eq!(PRIMES[PRIME_TABLE_SIZE - 1], 7919);
    }

    #[test]
    fn magic_division_is_exact() {
        let mut r = Pcg32::with_sequence(5);
        for &p in PRIMES.iter().step_by(7) {
            let b = DigitBase::new(p);
            for k in 0..2000u64 {
                let a = if k < 1000 {
                    u32::MAX as u64 - k
                } else {
                    r.uniform_u32() as u64
                };
                assert_eq!(b.div_rem(a), (a / p as u64, a % p as u64));
            }
            let a = u64::MAX - 3;
            assert_eq!(b.div_rem(a), (a / p as u64, a % p as u64));
        }
    }

    /// Digit-by-digit reference (pbrt-v3's loop).
    fn scrambled_reference(base: u64, perm: &[u16], mut a: u64) -> f64 {
        let (mut reversed, mut inv_n) = (0u64, 1.0f64);
        while a != 0 {
            reversed = reversed * base + perm[(a % base) as usize] as u64;
            inv_n /= base as f64;
            a /= base;
        }
        inv_n * (reversed as f64 + perm[0] as f64 / (base - 1) as f64)
    }

    #[test]
    fn scrambled_matches_digit_by_digit_reference() {
        let t = PermutationTables::shared(0);
        let mut r = Pcg32::with_sequence(11);
        for dim in [0usize, 1, 2, 3, 7, 50, 300, 999] {
            let (b, perm, tail) = t.dimension(dim);
            for k in 0..3000u64 {
                let a = match k % 3 {
                    0 => k,
                    1 => r.uniform_u32() as u64,
                    _ => ((r.uniform_u32() as u64) << 8) ^ r.uniform_u32() as u64,
                };
                let fast = scrambled_radical_inverse(b, perm, tail, a);
                let slow =
                    (scrambled_reference(b.base as u64, perm, a) as f32).min(ONE_MINUS_EPSILON);
                assert!(
                    (fast - slow).abs() <= 1e-7,
                    "dim {dim} a {a}: {fast} vs {slow}"
                );
            }
        }
    }

    #[test]
    fn pair_tables_are_bit_identical() {
        let t = PermutationTables::shared(0);
        let mut r = Pcg32::with_sequence(12);
        for dim in 0..40usize {
            let (b, perm, tail) = t.dimension(dim);
            for k in 0..4000u64 {
                let a = match k % 4 {
                    0 => k,
                    1 => r.uniform_u32() as u64,
                    2 => ((r.uniform_u32() as u64) << 32) | r.uniform_u32() as u64,
                    _ => u64::MAX - k,
                };
                assert_eq!(
                    t.scrambled(dim, a).to_bits(),
                    scrambled_radical_inverse(b, perm, tail, a).to_bits(),
                    "dim {dim} a {a}"
                );
            }
        }
    }

    #[test]
    fn radical_tables_are_bit_identical() {
        let mut r = Pcg32::with_sequence(11);
        for &p in PRIMES
            .iter()
            .take(80)
            .chain(&PRIMES[PRIME_TABLE_SIZE - 3..])
        {
            let b = DigitBase::new(p);
            let t = RadicalTable::new(p);
            let check = |a: u64| {
                assert_eq!(
                    t.radical_inverse(a).to_bits(),
                    radical_inverse(&b, a).to_bits(),
                    "base {p} a {a}"
                );
            };
            for a in 0..5_000u64 {
                check(a);
            }
            for _ in 0..5_000 {
                check(r.uniform_u32() as u64);
                check(((r.uniform_u32() as u64) << 32) | r.uniform_u32() as u64);
            }
            // Around powers of the base and the chunk, and the extremes.
            let mut q = 1u64;
            while let Some(n) = q.checked_mul(p as u64) {
                for a in [q - 1, q, q + 1, n - 1] {
                    check(a);
                }
                q = n;
            }
            for a in [u32::MAX as u64, u32::MAX as u64 + 1, u64::MAX - 1, u64::MAX] {
                check(a);
            }
        }
    }

    #[test]
    fn base3_by_chunks_is_bit_identical() {
        let b3 = DigitBase::new(3);
        let mut r = Pcg32::with_sequence(5);
        let check = |a: u64| {
            assert_eq!(
                radical_inverse_base3(a).to_bits(),
                radical_inverse(&b3, a).to_bits(),
                "a = {a}"
            );
        };
        for a in 0..100_000u64 {
            check(a);
        }
        let mut p = 1u64;
        while let Some(q) = p.checked_mul(3) {
            for a in [p - 1, p, p + 1, q - 1] {
                check(a);
            }
            p = q;
        }
        for _ in 0..100_000 {
            let a = (r.uniform_u32() as u64) << 32 | r.uniform_u32() as u64;
            check(a);
            check(a >> 20);
            check(a >> 40);
        }
        check(u64::MAX);
    }

    #[test]
    fn lanes_of_indices_are_bit_identical() {
        for seed in [0u64, 9] {
            let t = PermutationTables::shared(seed);
            let mut r = Pcg32::with_sequence(17);
            let mut out = [0f32; BLOCK_LANES];
            for dim in 2..BLOCK_DIM_END {
                let dims = [dim, (dim * 7 + 3) % (BLOCK_DIM_END - 2) + 2];
                for k in 0..400u32 {
                    // Small, random, near the top of u32 (past i32::MAX)
                    // and arithmetic progressions (a sample array's).
                    let a: [u32; BLOCK_LANES] = std::array::from_fn(|j| match k % 4 {
                        0 => k * 8 + j as u32,
                        1 => r.uniform_u32(),
                        2 => u32::MAX - k - j as u32,
                        _ => (k * 1_000_003).wrapping_add(j as u32 * 373_248),
                    });
                    t.scrambled_indices(dims, &a, &mut out);
                    for (j, &v) in out.iter().enumerate() {
                        let d = dims[j / 4];
                        assert_eq!(
                            v.to_bits(),
                            t.scrambled(d, a[j] as u64).to_bits(),
                            "dim {d} a {}",
                            a[j]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn blocks_are_bit_identical() {
        for seed in [0u64, 9] {
            let t = PermutationTables::shared(seed);
            let mut r = Pcg32::with_sequence(13);
            let mut out = [0f32; BLOCK_LANES];
            for first in 2..BLOCK_DIM_END {
                for k in 0..3000u64 {
                    let a = match k % 3 {
                        0 => k,
                        1 => r.uniform_u32() as u64,
                        _ => u32::MAX as u64 - k,
                    };
                    t.scrambled_block(first, a, &mut out);
                    for (j, &v) in out.iter().enumerate() {
                        if first + j < BLOCK_DIM_END {
                            assert_eq!(
                                v.to_bits(),
                                t.scrambled(first + j, a).to_bits(),
                                "dim {} a {a}",
                                first + j
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn radical_inverses() {
        assert_eq!(radical_inverse_base2(1), 0.5);
        assert_eq!(radical_inverse_base2(3), 0.75);
        assert_eq!(radical_inverse_base2(6), 0.375);
        let b3 = DigitBase::new(3);
        assert!((radical_inverse(&b3, 1) - 1.0 / 3.0).abs() < 1e-7);
        assert!((radical_inverse(&b3, 5) - 7.0 / 9.0).abs() < 1e-7); // 5 = 12_3 -> 0.21_3
        let b2 = DigitBase::new(2);
        for a in 0..1000 {
            assert_eq!(radical_inverse(&b2, a), radical_inverse_base2(a));
        }
        // Identity permutation: scrambled == plain.
        let id: Vec<u16> = (0..7).collect();
        let b7 = DigitBase::new(7);
        for a in 0..500 {
            assert!(
                (scrambled_radical_inverse(&b7, &id, scramble_tail(&id), a)
                    - radical_inverse(&b7, a))
                .abs()
                    < 1e-7
            );
        }
        assert_eq!(inverse_radical_inverse(3, 5, 2), 7); // digits 12 -> 21
        assert_eq!(multiplicative_inverse(3, 7), 5);
        assert_eq!(multiplicative_inverse(128, 243) * 128 % 243, 1);
    }

    #[test]
    fn permutations_are_permutations() {
        let t = PermutationTables::shared(0);
        for dim in [0, 1, 2, 10, 999] {
            let (b, p, _) = t.dimension(dim);
            let mut s: Vec<u16> = p.to_vec();
            s.sort();
            assert_eq!(s, (0..b.base as u16).collect::<Vec<_>>());
        }
        assert!(Arc::ptr_eq(&t, &PermutationTables::shared(0)));
        let t7 = PermutationTables::shared(7);
        assert_ne!(t7.dimension(5).1, t.dimension(5).1);
    }

    /// The permutations made on first use continue pbrt-v3's one stream of
    /// shuffles: every dimension's is the one of shuffling all 1000 bases
    /// in order from the default generator, and its tail follows from it.
    #[test]
    fn late_permutations_continue_the_stream() {
        let t = PermutationTables::generate(&mut Pcg32::new());
        let mut rng = Pcg32::new();
        for (dim, &p) in PRIMES.iter().enumerate() {
            let mut want: Vec<u16> = (0..p as u16).collect();
            for i in 0..p as usize {
                let other = i + rng.uniform_u32_below(p - i as u32) as usize;
                want.swap(i, other);
            }
            let (b, got, tail) = t.dimension(dim);
            assert_eq!(b.base, p);
            assert_eq!(got, &want[..], "dimension {dim}");
            assert_eq!(tail.to_bits(), scramble_tail(&want).to_bits());
        }
    }
}
