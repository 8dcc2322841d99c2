//! The golden-image verdict shared by the project's own golden test
//! (`tests/golden.rs`) and `pbrs test`: a render matches its golden when its
//! relative MSE, its 8×8 block error and the relative difference of its
//! per-channel means are within bounds, and it has no non-finite pixel.
//!
//! Bounds come either from a stated reference noise (pbrt-v3's own render at
//! equal spp, for the project's scenes) or from [`Noise`], the noise of one
//! render measured against a second render with another seed, so that the
//! tolerance is a multiple of the expected noise, not a number per scene.

use super::compare::{compare, Comparison, BLOCK_SIZE};
use super::Image;

/// Acceptance bounds for a render compared with a golden.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub max_relative_mse: f64,
    pub max_block_error: f64,
    /// Largest relative difference of the per-channel image means.
    pub max_mean_difference: f64,
}

/// The metrics of a render against its golden, and the bounds they met or not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    pub comparison: Comparison,
    /// Largest relative difference of the per-channel means.
    pub mean_difference: f64,
    /// Pixels of the render with a NaN or infinite channel.
    pub nonfinite: usize,
    pub bounds: Bounds,
}

impl Verdict {
    pub fn passed(&self) -> bool {
        self.failures().is_empty()
    }

    /// What is out of bounds, one phrase each (empty when it passed).
    pub fn failures(&self) -> Vec<String> {
        let (c, b) = (&self.comparison, &self.bounds);
        let mut out = Vec::new();
        if self.nonfinite > 0 {
            out.push(format!("{} non-finite pixels", self.nonfinite));
        }
        if !within(c.relative_mse, b.max_relative_mse) {
            out.push(format!(
                "relative MSE {:.4e} > {:.4e}",
                c.relative_mse, b.max_relative_mse
            ));
        }
        if !within(c.block_error, b.max_block_error) {
            out.push(format!(
                "block error {:.4e} > {:.4e}",
                c.block_error, b.max_block_error
            ));
        }
        if !within(self.mean_difference, b.max_mean_difference) {
            out.push(format!(
                "mean difference {:.3e} > {:.3e}",
                self.mean_difference, b.max_mean_difference
            ));
        }
        out
    }

    /// One line of figures, for logs and failure messages.
    pub fn summary(&self) -> String {
        let (c, b) = (&self.comparison, &self.bounds);
        format!(
            "relative MSE {:.5} (max {:.5}), block error {:.5} (max {:.5}), mean difference {:.4} (max {:.4}), non-finite pixels {}; means {:?} vs {:?}",
            c.relative_mse,
            b.max_relative_mse,
            c.block_error,
            b.max_block_error,
            self.mean_difference,
            b.max_mean_difference,
            self.nonfinite,
            c.mean_a,
            c.mean_r
        )
    }
}

/// `x ≤ max`; a NaN figure is out of bounds.
fn within(x: f64, max: f64) -> bool {
    x <= max
}

/// Largest relative difference of the per-channel means of a comparison.
pub fn mean_difference(c: &Comparison) -> f64 {
    (0..3)
        .map(|i| ((c.mean_a[i] - c.mean_r[i]) / c.mean_r[i].abs().max(1e-6)).abs())
        .fold(0.0f64, f64::max)
}

/// Pixels with a NaN or infinite channel.
pub fn nonfinite_pixels(img: &Image) -> usize {
    img.data
        .chunks_exact(3)
        .filter(|p| p.iter().any(|v| !v.is_finite()))
        .count()
}

/// Judges `img` against `golden` (images of the same size).
pub fn judge(img: &Image, golden: &Image, bounds: Bounds) -> Verdict {
    let comparison = compare(img, golden);
    Verdict {
        mean_difference: mean_difference(&comparison),
        comparison,
        nonfinite: nonfinite_pixels(img),
        bounds,
    }
}

/// The noise of one render, measured from two renders with different seeds
/// (`a`, `b`): for independent noise E[relMSE(a, b)] is twice one render's
/// relative MSE against the converged image, and likewise for the squared
/// block error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Noise {
    /// One render's expected relative MSE against the converged image.
    pub relative_mse: f64,
    /// One render's expected block error (root mean square over blocks).
    pub block_error: f64,
    /// One render's standard deviation of each channel's image mean,
    /// relative to the mean: from the spread of the 8×8 block means'
    /// differences, divided by √(number of blocks).
    pub mean_sigma: [f64; 3],
}

impl Noise {
    pub fn measure(a: &Image, b: &Image) -> Noise {
        let c = compare(a, b);
        Noise {
            relative_mse: c.relative_mse / 2.0,
            block_error: c.block_error / 2f64.sqrt(),
            mean_sigma: mean_sigma(a, b),
        }
    }

    /// Bounds for a render with a fresh seed against a golden that is the
    /// mean of `golden_renders` renders like it (so the golden's own noise
    /// is 1/`golden_renders` of a render's): relative MSE and block error
    /// within `tolerance` times their expected value, the means within
    /// `mean_tolerance` standard deviations.
    pub fn bounds(&self, golden_renders: f64, tolerance: f64, mean_tolerance: f64) -> Bounds {
        let share = 1.0 + 1.0 / golden_renders;
        // Floors keep a noise-free scene (two identical renders) usable:
        // then only rounding-level differences pass.
        let sigma = self.mean_sigma.iter().fold(0.0f64, |m, &s| m.max(s));
        Bounds {
            max_relative_mse: tolerance * (self.relative_mse * share).max(1e-12),
            max_block_error: tolerance * (self.block_error * share.sqrt()).max(1e-6),
            max_mean_difference: mean_tolerance * (sigma * share.sqrt()).max(1e-6),
        }
    }
}

/// Per-channel standard deviation of one render's image mean relative to the
/// mean, estimated from the block means of `a − b` (see [`Noise`]).
fn mean_sigma(a: &Image, b: &Image) -> [f64; 3] {
    let (w, h) = (a.width, a.height);
    let (bw, bh) = (w.div_ceil(BLOCK_SIZE), h.div_ceil(BLOCK_SIZE));
    let nb = (bw * bh) as usize;
    let mut sums = vec![([0.0f64; 3], 0u32); nb];
    for y in 0..h {
        for x in 0..w {
            let k = ((y / BLOCK_SIZE) * bw + x / BLOCK_SIZE) as usize;
            let i = 3 * (y * w + x) as usize;
            for c in 0..3 {
                sums[k].0[c] += a.data[i + c] as f64 - b.data[i + c] as f64;
            }
            sums[k].1 += 1;
        }
    }
    let ma = compare(a, b);
    let mut out = [0.0; 3];
    if nb < 2 {
        return out;
    }
    for (c, o) in out.iter_mut().enumerate() {
        let d: Vec<f64> = sums.iter().map(|(s, n)| s[c] / *n as f64).collect();
        let m = d.iter().sum::<f64>() / nb as f64;
        let var = d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (nb - 1) as f64;
        // Var(mean(a) − mean(b)) = var / nb, twice one render's variance.
        let mean = 0.5 * (ma.mean_a[c] + ma.mean_r[c]);
        *o = (var / nb as f64 / 2.0).sqrt() / mean.abs().max(1e-6);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noisy(seed: u64, scale: f32) -> Image {
        let mut img = Image::new(32, 32);
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        for v in &mut img.data {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            *v = scale * (0.5 + 0.1 * ((s >> 40) as f32 / (1u64 << 24) as f32 - 0.5));
        }
        img
    }

    #[test]
    fn noise_passes_and_bias_fails() {
        let (a, b) = (noisy(1, 1.0), noisy(2, 1.0));
        let golden = Image {
            data: a
                .data
                .iter()
                .zip(&b.data)
                .map(|(x, y)| 0.5 * (x + y))
                .collect(),
            ..a.clone()
        };
        let bounds = Noise::measure(&a, &b).bounds(2.0, 2.0, 5.0);
        assert!(judge(&noisy(3, 1.0), &golden, bounds).passed());
        let v = judge(&noisy(3, 1.03), &golden, bounds);
        assert!(!v.passed());
        assert!(v.failures().iter().any(|f| f.contains("mean")), "{v:?}");
        let mut nan = noisy(3, 1.0);
        nan.data[5] = f32::NAN;
        let v = judge(&nan, &golden, bounds);
        assert_eq!(v.nonfinite, 1);
        assert!(!v.passed());
    }
}
