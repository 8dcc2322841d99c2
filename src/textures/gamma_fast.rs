//! Speed only: [`super::inverse_gamma`] of the values 8-bit images give
//! (`k/255`; a 1024² texture is three million of them, and `powf` was 28%
//! of loading one) from a table of the formula's own results for the 256
//! codes, chosen by the value's bits, so that the result is the formula's
//! bit for bit (`tests::table_is_the_formula`).

use std::sync::OnceLock;

/// The 8-bit codes as the image readers make them
/// ([`crate::image::unorm8_table`]) and their linear values.
struct Srgb8Table {
    code: [f32; 256],
    linear: [f32; 256],
}

fn table() -> &'static Srgb8Table {
    static TABLE: OnceLock<Srgb8Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let code = crate::image::unorm8_table();
        Srgb8Table {
            code,
            linear: code.map(super::inverse_gamma_computed),
        }
    })
}

/// The linear value of `v` if its bits are those of an 8-bit code's.
#[inline]
pub(super) fn of_8bit_code(v: f32) -> Option<f32> {
    let k = (v * 255.0 + 0.5) as usize;
    let t = table();
    (k < 256 && t.code[k].to_bits() == v.to_bits()).then(|| t.linear[k])
}

#[cfg(test)]
mod tests {
    use super::super::{inverse_gamma, inverse_gamma_computed};
    use super::*;

    /// Every 8-bit code is found in the table; `inverse_gamma` gives the
    /// formula's bits for the codes and for every other value (their
    /// neighbours, -0, negatives, values past 1, NaN, random values),
    /// which the table does not claim.
    #[test]
    fn table_is_the_formula() {
        let mut values: Vec<f32> = vec![0.0, -0.0, -1.0, 1.0 + f32::EPSILON, 2.0, 1e30];
        values.extend([
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MIN_POSITIVE,
        ]);
        for (k, v) in crate::image::unorm8_table().into_iter().enumerate() {
            assert!(of_8bit_code(v).is_some(), "code {k}");
            assert!(of_8bit_code(v.next_up()).is_none(), "past code {k}");
            values.extend([v, v.next_up(), v.next_down(), -v, v * 0.5]);
        }
        let mut rng = crate::sampling::rng::Pcg32::with_sequence(3);
        values.extend((0..100_000).map(|_| rng.uniform_f32() * 1.2 - 0.1));
        for v in values {
            assert_eq!(
                inverse_gamma(v).to_bits(),
                inverse_gamma_computed(v).to_bits(),
                "{v:e}"
            );
        }
    }
}
