//! Sobol' generator matrices made from Joe and Kuo's published direction
//! numbers (`data/new-joe-kuo-6.1024`: the first 1023 lines of
//! new-joe-kuo-6.21201, S. Joe and F. Y. Kuo, "Constructing Sobol sequences
//! with better two-dimensional projections", SIAM J. Sci. Comput. 30,
//! 2635–2654, 2008; provenance in `data/README.md`), in the layout pbrt-v3's
//! core/sobolmatrices.{h,cpp} use: 1024 dimensions (the first the van der
//! Corput sequence), 52 columns each, a column's top 32 bits as a `u32`;
//! and the matrices of `SobolIntervalToIndex` (Grünschloß, Raab and
//! Keller's enumeration of the first two dimensions in an elementary
//! interval) with their inverses, for every resolution `2^m`, m ≤ 26.

use std::sync::OnceLock;

/// Dimensions pbrt-v3's Sobol' sampler has (`NumSobolDimensions`).
pub const NUM_SOBOL_DIMENSIONS: usize = 1024;
/// Columns per dimension (`SobolMatrixSize`): index bits taken.
pub const SOBOL_MATRIX_SIZE: usize = 52;
/// The largest `log2` of the resolution `SobolIntervalToIndex` supports.
pub const MAX_LOG2_RESOLUTION: u32 = 26;

const DIRECTION_NUMBERS: &str = include_str!("data/new-joe-kuo-6.1024");

/// The generator matrices and the interval-enumeration matrices.
pub struct SobolMatrices {
    /// Column `j` of dimension `d` is `m32[d * SOBOL_MATRIX_SIZE + j]`: bit
    /// 31 is the first digit after the binary point.
    pub m32: Vec<u32>,
    /// `m32` as tables per four bits of the index (speed only).
    pub nibbles: super::sobol_fast::SobolNibbles,
    /// `vdc[m - 1][c]`: the first `m` digits of dimensions 0 and 1 (packed
    /// `x << m | y`) that index bit `2m + c` contributes (pbrt-v3's
    /// `VdCSobolMatrices`; zero where `2m + c` is past the 52 columns).
    pub vdc: Vec<[u64; SOBOL_MATRIX_SIZE]>,
    /// `vdc_inv[m - 1][c]`: the low `2m` index bits giving packed digit `c`
    /// alone (pbrt-v3's `VdCSobolMatricesInv`).
    pub vdc_inv: Vec<[u64; SOBOL_MATRIX_SIZE]>,
}

impl std::fmt::Debug for SobolMatrices {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SobolMatrices")
    }
}

/// The matrices, made on first use.
pub fn sobol_matrices() -> &'static SobolMatrices {
    static M: OnceLock<SobolMatrices> = OnceLock::new();
    M.get_or_init(build)
}

/// The 52-bit columns of every dimension: column `j` (index bit `j`) is
/// direction number `m_{j+1} / 2^{j+1}` with 52 bits after the point.
fn columns_52() -> Vec<[u64; SOBOL_MATRIX_SIZE]> {
    let l = SOBOL_MATRIX_SIZE;
    let mut dims = Vec::with_capacity(NUM_SOBOL_DIMENSIONS);
    let mut first = [0u64; SOBOL_MATRIX_SIZE];
    for (j, c) in first.iter_mut().enumerate() {
        *c = 1 << (l - 1 - j);
    }
    dims.push(first);
    for line in DIRECTION_NUMBERS.lines().skip(1) {
        if dims.len() == NUM_SOBOL_DIMENSIONS {
            break;
        }
        let f: Vec<u64> = line
            .split_whitespace()
            .map(|t| t.parse().expect("direction numbers: a number"))
            .collect();
        let (s, a) = (f[1] as usize, f[2]);
        let mut m: Vec<u64> = f[3..3 + s].to_vec();
        // m_k = 2 a_1 m_{k-1} ^ 4 a_2 m_{k-2} ^ ... ^ 2^s m_{k-s} ^ m_{k-s}
        // (a's bits from the highest: a_1 is bit s-2).
        for k in s..l {
            let mut v = m[k - s] ^ (m[k - s] << s);
            for i in 1..s {
                if (a >> (s - 1 - i)) & 1 == 1 {
                    v ^= m[k - i] << i;
                }
            }
            m.push(v);
        }
        let mut cols = [0u64; SOBOL_MATRIX_SIZE];
        for (j, c) in cols.iter_mut().enumerate() {
            *c = m[j] << (l - 1 - j);
        }
        dims.push(cols);
    }
    assert_eq!(
        dims.len(),
        NUM_SOBOL_DIMENSIONS,
        "direction numbers: too few lines"
    );
    dims
}

fn build() -> SobolMatrices {
    let dims = columns_52();
    let m32: Vec<u32> = dims
        .iter()
        .flat_map(|d| d.iter().map(|&c| (c >> (SOBOL_MATRIX_SIZE - 32)) as u32))
        .collect();
    let (mut vdc, mut vdc_inv) = (Vec::new(), Vec::new());
    for m in 1..=MAX_LOG2_RESOLUTION as usize {
        // Index bit j -> the first m digits of dimensions 0 and 1, packed.
        let packed = |j: usize| -> u64 {
            let top = |c: u64| c >> (SOBOL_MATRIX_SIZE - m);
            (top(dims[0][j]) << m) | top(dims[1][j])
        };
        let mut v = [0u64; SOBOL_MATRIX_SIZE];
        for (c, e) in v.iter_mut().enumerate().take(SOBOL_MATRIX_SIZE - 2 * m) {
            *e = packed(2 * m + c);
        }
        vdc.push(v);
        vdc_inv.push(invert((0..2 * m).map(packed).collect()));
    }
    let nibbles = super::sobol_fast::SobolNibbles::new(&m32);
    SobolMatrices {
        m32,
        nibbles,
        vdc,
        vdc_inv,
    }
}

/// The inverse of the `n × n` GF(2) matrix whose column `j` is `cols[j]`,
/// as its columns (Gauss–Jordan elimination: each pivot row keeps the
/// combination of input columns that makes it).
fn invert(cols: Vec<u64>) -> [u64; SOBOL_MATRIX_SIZE] {
    let n = cols.len();
    // basis[b]: (image with highest bit b, the input bits making it).
    let mut basis: Vec<Option<(u64, u64)>> = vec![None; n];
    for (k, &c) in cols.iter().enumerate() {
        let (mut img, mut pre) = (c, 1u64 << k);
        for b in (0..n).rev() {
            if let Some((bi, bp)) = basis[b] {
                if (img >> b) & 1 == 1 {
                    img ^= bi;
                    pre ^= bp;
                }
            }
        }
        assert!(img != 0, "interval matrix is singular");
        let hb = 63 - img.leading_zeros() as usize;
        for e in basis.iter_mut().flatten() {
            if (e.0 >> hb) & 1 == 1 {
                e.0 ^= img;
                e.1 ^= pre;
            }
        }
        basis[hb] = Some((img, pre));
    }
    let mut inv = [0u64; SOBOL_MATRIX_SIZE];
    for (c, e) in inv.iter_mut().enumerate().take(n) {
        let (img, pre) = basis[c].expect("full rank");
        debug_assert_eq!(img, 1 << c);
        *e = pre;
    }
    inv
}

/// pbrt-v3's `SobolIntervalToIndex`: the index of the `frame`-th sample of
/// the Sobol' sequence whose first two dimensions, scaled by `2^m`, fall in
/// pixel `p` (`0 ≤ p < 2^m`).
#[inline]
pub fn sobol_interval_to_index(t: &SobolMatrices, m: u32, mut frame: u64, p: (u32, u32)) -> u64 {
    if m == 0 {
        return 0;
    }
    let (vdc, inv) = (&t.vdc[m as usize - 1], &t.vdc_inv[m as usize - 1]);
    let mut index = frame << (2 * m);
    let mut delta = 0u64;
    let mut c = 0;
    while frame != 0 {
        if frame & 1 == 1 {
            delta ^= vdc.get(c).copied().unwrap_or(0);
        }
        frame >>= 1;
        c += 1;
    }
    let mut b = (((p.0 as u64) << m) | p.1 as u64) ^ delta;
    let mut c = 0;
    while b != 0 {
        if b & 1 == 1 {
            index ^= inv[c];
        }
        b >>= 1;
        c += 1;
    }
    index
}

/// pbrt-v3's `SobolSampleFloat`: dimension `dim` (< 1024) of sample `a`,
/// XOR-scrambled by `scramble` (the columns of `a`'s set bits XORed,
/// through the tables of `sobol_fast`).
#[inline]
pub fn sobol_sample(t: &SobolMatrices, a: u64, dim: usize, scramble: u32) -> f32 {
    to_unit(t.nibbles.bits(a, dim, scramble))
}

/// pbrt-v3's `SobolSampleFloat`: dimension `dim` (< 1024) of sample `a`,
/// XOR-scrambled by `scramble`.
#[cfg(test)]
pub fn sobol_sample_plain(t: &SobolMatrices, mut a: u64, dim: usize, scramble: u32) -> f32 {
    let mut v = scramble;
    let cols = &t.m32[dim * SOBOL_MATRIX_SIZE..(dim + 1) * SOBOL_MATRIX_SIZE];
    // One step per set bit (the same XORs as pbrt-v3's loop over all bits).
    a &= (1 << SOBOL_MATRIX_SIZE) - 1;
    while a != 0 {
        v ^= cols[a.trailing_zeros() as usize];
        a &= a - 1;
    }
    to_unit(v)
}

/// `v / 2^32` as pbrt-v3 computes it (an `f32` product), below 1.
#[inline]
pub fn to_unit(v: u32) -> f32 {
    (v as f32 * (1.0 / 4_294_967_296.0)).min(crate::sampling::rng::ONE_MINUS_EPSILON)
}
