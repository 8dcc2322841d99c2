//! Image comparison metrics as defined for the project's references
//! (`scenes/references/README.md`), and a false-colour difference image.

use super::Image;
use glam::Vec3;

/// Offset in the denominators of the relative metrics.
pub const RELATIVE_EPSILON: f64 = 0.01;
/// Side of the blocks of the block error.
pub const BLOCK_SIZE: u32 = 8;

fn check_same_size(a: &Image, r: &Image) {
    assert!(
        a.width == r.width && a.height == r.height && a.data.len() == r.data.len(),
        "images differ in size: {}x{} vs {}x{}",
        a.width,
        a.height,
        r.width,
        r.height
    );
}

/// Mean over pixels and channels of `(a − r)² / (r² + 0.01)`.
pub fn relative_mse(a: &Image, r: &Image) -> f64 {
    check_same_size(a, r);
    if a.data.is_empty() {
        return 0.0;
    }
    let sum: f64 = a
        .data
        .iter()
        .zip(&r.data)
        .map(|(&a, &r)| {
            let (a, r) = (a as f64, r as f64);
            (a - r) * (a - r) / (r * r + RELATIVE_EPSILON)
        })
        .sum();
    sum / a.data.len() as f64
}

/// Root mean square error over pixels and channels.
pub fn rmse(a: &Image, r: &Image) -> f64 {
    check_same_size(a, r);
    if a.data.is_empty() {
        return 0.0;
    }
    let sum: f64 = a
        .data
        .iter()
        .zip(&r.data)
        .map(|(&a, &r)| (a as f64 - r as f64).powi(2))
        .sum();
    (sum / a.data.len() as f64).sqrt()
}

/// Per-channel means of 8×8 blocks (partial blocks at the right and bottom
/// edges average the pixels they have), row-major over blocks.
fn block_means(img: &Image) -> Vec<[f64; 3]> {
    let (w, h) = (img.width, img.height);
    let (bw, bh) = (w.div_ceil(BLOCK_SIZE), h.div_ceil(BLOCK_SIZE));
    let mut sums = vec![([0.0f64; 3], 0u32); (bw * bh) as usize];
    for y in 0..h {
        for x in 0..w {
            let b = ((y / BLOCK_SIZE) * bw + x / BLOCK_SIZE) as usize;
            let i = 3 * (y * w + x) as usize;
            for c in 0..3 {
                sums[b].0[c] += img.data[i + c] as f64;
            }
            sums[b].1 += 1;
        }
    }
    sums.into_iter()
        .map(|(s, n)| [s[0] / n as f64, s[1] / n as f64, s[2] / n as f64])
        .collect()
}

/// `sqrt(mean over 8×8 blocks and channels of (ā − r̄)² / (r̄² + 0.01))`,
/// with ā, r̄ the block means: sees bias that per-pixel noise hides.
pub fn block_error(a: &Image, r: &Image) -> f64 {
    check_same_size(a, r);
    let (ma, mr) = (block_means(a), block_means(r));
    if ma.is_empty() {
        return 0.0;
    }
    let mut sum = 0.0;
    for (ba, br) in ma.iter().zip(&mr) {
        for c in 0..3 {
            sum += (ba[c] - br[c]).powi(2) / (br[c] * br[c] + RELATIVE_EPSILON);
        }
    }
    (sum / (3 * ma.len()) as f64).sqrt()
}

/// Mean of each channel over all pixels.
pub fn mean_rgb(img: &Image) -> [f64; 3] {
    let mut s = [0.0f64; 3];
    for px in img.data.chunks_exact(3) {
        for c in 0..3 {
            s[c] += px[c] as f64;
        }
    }
    let n = (img.data.len() / 3).max(1) as f64;
    [s[0] / n, s[1] / n, s[2] / n]
}

/// All metrics at once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    pub relative_mse: f64,
    pub block_error: f64,
    pub rmse: f64,
    pub mean_a: [f64; 3],
    pub mean_r: [f64; 3],
}

pub fn compare(a: &Image, r: &Image) -> Comparison {
    Comparison {
        relative_mse: relative_mse(a, r),
        block_error: block_error(a, r),
        rmse: rmse(a, r),
        mean_a: mean_rgb(a),
        mean_r: mean_rgb(r),
    }
}

/// Heat map of the per-pixel relative difference
/// `sqrt(mean_c (a − r)² / (r² + 0.01))`, mapped through a black → blue →
/// green → yellow → red → white ramp where white is `max_error` or more
/// (linear RGB, write it as PNG to look at a failing test).
pub fn false_colour_difference_scaled(a: &Image, r: &Image, max_error: f32) -> Image {
    check_same_size(a, r);
    let mut out = Image::new(a.width, a.height);
    for (i, (pa, pr)) in a
        .data
        .chunks_exact(3)
        .zip(r.data.chunks_exact(3))
        .enumerate()
    {
        let mut e = 0.0f64;
        for c in 0..3 {
            let (x, y) = (pa[c] as f64, pr[c] as f64);
            e += (x - y).powi(2) / (y * y + RELATIVE_EPSILON);
        }
        let e = (e / 3.0).sqrt() as f32;
        let t = if e.is_finite() {
            (e / max_error.max(1e-12)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        out.data[3 * i..3 * i + 3].copy_from_slice(&ramp(t).to_array());
    }
    out
}

/// [`false_colour_difference_scaled`] with white at a relative error of 0.5.
pub fn false_colour_difference(a: &Image, r: &Image) -> Image {
    false_colour_difference_scaled(a, r, 0.5)
}

/// Writes the false-colour difference of `a` against `r` (e.g. as a PNG next
/// to a failing test's output).
pub fn write_false_colour(path: &std::path::Path, a: &Image, r: &Image) -> Result<(), String> {
    super::io::write_image(path, &false_colour_difference(a, r))
}

fn ramp(t: f32) -> Vec3 {
    const STOPS: [Vec3; 6] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let s = t * (STOPS.len() - 1) as f32;
    let i = (s as usize).min(STOPS.len() - 2);
    STOPS[i].lerp(STOPS[i + 1], s - i as f32)
}
