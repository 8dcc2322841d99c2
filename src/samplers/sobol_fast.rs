//! Speed only: a dimension of the Sobol' sequence from a table per four
//! bits of the index instead of one generator-matrix column per set bit.
//!
//! `sobol_sample` XORs the columns of the bits set in the index: about
//! eleven dependent steps for an image of 256² pixels at 64 samples, a
//! loop whose length is the index's bit count, so that its exit is a
//! mispredicted branch nearly every time. Here each four bits of the index
//! pick one entry of a 16-entry table (the XOR of the matching columns),
//! one cache line per four bits and dimension: as many steps as the
//! index has nibbles, the same for every sample of an image. XOR being
//! associative, the value is the column loop's bit for bit
//! (`tests::equals_the_column_loop`).

use super::sobolmatrices::{NUM_SOBOL_DIMENSIONS, SOBOL_MATRIX_SIZE};

/// Nibbles of an index that the matrices use (52 bits).
const NIBBLES: usize = SOBOL_MATRIX_SIZE.div_ceil(4);

/// Per dimension and nibble of the index, the 16 XORs of the nibble's
/// four columns: `t[dim * NIBBLES + k][n]` for nibble k with value n.
pub struct SobolNibbles {
    t: Vec<[u32; 16]>,
}

impl SobolNibbles {
    /// The tables of the generator matrices `m32` (`SOBOL_MATRIX_SIZE`
    /// columns per dimension).
    pub fn new(m32: &[u32]) -> SobolNibbles {
        debug_assert_eq!(m32.len(), NUM_SOBOL_DIMENSIONS * SOBOL_MATRIX_SIZE);
        let mut t = Vec::with_capacity(NUM_SOBOL_DIMENSIONS * NIBBLES);
        for cols in m32.chunks_exact(SOBOL_MATRIX_SIZE) {
            for k in 0..NIBBLES {
                let mut e = [0u32; 16];
                for (n, v) in e.iter_mut().enumerate() {
                    for b in 0..4 {
                        let c = 4 * k + b;
                        if (n >> b) & 1 == 1 && c < SOBOL_MATRIX_SIZE {
                            *v ^= cols[c];
                        }
                    }
                }
                t.push(e);
            }
        }
        SobolNibbles { t }
    }

    /// The XOR of the generator columns of dimension `dim` (below
    /// `NUM_SOBOL_DIMENSIONS`) for the low `SOBOL_MATRIX_SIZE` bits of
    /// `a`, XORed into `scramble`.
    #[inline]
    pub fn bits(&self, mut a: u64, dim: usize, scramble: u32) -> u32 {
        a &= (1 << SOBOL_MATRIX_SIZE) - 1;
        let t = &self.t[dim * NIBBLES..(dim + 1) * NIBBLES];
        let mut v = scramble;
        let mut k = 0;
        while a != 0 {
            v ^= t[k][(a & 15) as usize];
            a >>= 4;
            k += 1;
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::super::sobolmatrices::{sobol_matrices, sobol_sample_plain, to_unit};
    use super::*;
    use crate::sampling::rng::Pcg32;

    /// Every dimension, indices of every bit length up to 64 (bits past
    /// the 52nd ignored), zero, all ones and powers of two, with and
    /// without a scramble: the column loop's values bit for bit.
    #[test]
    fn equals_the_column_loop() {
        let m = sobol_matrices();
        let mut rng = Pcg32::with_sequence(3);
        let mut n = 0;
        for dim in 0..NUM_SOBOL_DIMENSIONS {
            let mut idx = vec![0u64, u64::MAX, (1 << 52) - 1, 1 << 51, 1 << 52];
            for len in [1, 4, 5, 16, 22, 23, 31, 40, 52, 60, 64] {
                let r = ((rng.uniform_u32() as u64) << 32) | rng.uniform_u32() as u64;
                idx.push(if len == 64 { r } else { r & ((1 << len) - 1) });
            }
            for a in idx {
                for scramble in [0, rng.uniform_u32()] {
                    let fast = to_unit(m.nibbles.bits(a, dim, scramble));
                    let plain = sobol_sample_plain(m, a, dim, scramble);
                    assert_eq!(fast.to_bits(), plain.to_bits(), "dim {dim} index {a:#x}");
                    n += 1;
                }
            }
        }
        assert_eq!(n, NUM_SOBOL_DIMENSIONS * 16 * 2);
    }
}
