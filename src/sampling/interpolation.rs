//! Spline and Fourier-series tools for tabulated BSDFs, with pbrt-v3's
//! semantics (`core/interpolation.cpp`): Catmull-Rom weights over a node
//! array, sampling a 2D Catmull-Rom tabulated function along its second
//! dimension, evaluating a cosine series, and sampling one by its azimuth.
//!
//! The Newton–bisection loops stop on pbrt-v3's tolerances; they also stop
//! after a bounded number of steps, which pbrt-v3 does not, so that a table
//! with pathological values cannot hang a render (well-formed tables converge
//! in a handful of steps).

use std::f32::consts::PI as PI_F32;

/// pbrt-v3's `Pi` and `Inv2Pi` are `Float` (f32) constants, even where they
/// enter its double-precision sums; the same roundings are kept here.
const PI: f64 = PI_F32 as f64;
const INV_2PI: f64 = (std::f32::consts::FRAC_1_PI * 0.5) as f64;

/// Steps after which the root finders give up (bisection alone reaches
/// their 1e-6 interval in about 20).
const MAX_STEPS: usize = 100;

/// pbrt-v3's `FindInterval`: the largest `i` in `0..=size-2` with `pred(i)`
/// true, assuming `pred` is true then false along the range (0 if none).
#[inline]
pub fn find_interval(size: usize, pred: impl Fn(usize) -> bool) -> usize {
    let (mut first, mut len) = (0usize, size);
    while len > 0 {
        let half = len >> 1;
        let middle = first + half;
        if pred(middle) {
            first = middle + 1;
            len -= half + 1;
        } else {
            len = half;
        }
    }
    first.saturating_sub(1).min(size.saturating_sub(2))
}

/// Catmull-Rom spline weights of `x` over `nodes` (at least 2,
/// non-decreasing, the last two distinct; an empty interval is never chosen):
/// the value at `x` is `Σ weights[i] · values[offset + i]`. `None` if `x` is
/// outside the nodes (or NaN). A weight is non-zero only where
/// `offset + i` is a valid node index (`offset` is -1 in the first interval).
#[inline]
pub fn catmull_rom_weights(nodes: &[f32], x: f32) -> Option<(isize, [f32; 4])> {
    let size = nodes.len();
    if !(x >= nodes[0] && x <= nodes[size - 1]) {
        return None;
    }
    let idx = find_interval(size, |i| nodes[i] <= x);
    let (x0, x1) = (nodes[idx], nodes[idx + 1]);
    let t = (x - x0) / (x1 - x0);
    let (t2, t3) = (t * t, t * t * t);
    let mut w = [0.0f32; 4];
    w[1] = 2.0 * t3 - 3.0 * t2 + 1.0;
    w[2] = -2.0 * t3 + 3.0 * t2;
    // The end intervals have no outer neighbour: their tangents are one-sided.
    if idx > 0 {
        let w0 = (t3 - 2.0 * t2 + t) * (x1 - x0) / (x1 - nodes[idx - 1]);
        w[0] = -w0;
        w[2] += w0;
    } else {
        let w0 = t3 - 2.0 * t2 + t;
        w[0] = 0.0;
        w[1] -= w0;
        w[2] += w0;
    }
    if idx + 2 < size {
        let w3 = (t3 - t2) * (x1 - x0) / (nodes[idx + 2] - x0);
        w[1] -= w3;
        w[3] = w3;
    } else {
        let w3 = t3 - t2;
        w[1] -= w3;
        w[2] += w3;
        w[3] = 0.0;
    }
    Some((idx as isize - 1, w))
}

/// The finite-difference tangents pbrt-v3 gives the Catmull-Rom segment
/// `i` of `values` over `x` (one-sided at the ends), scaled to the
/// segment's width.
#[inline]
fn segment_tangents(x: &[f32], values: &[f32], i: usize) -> (f32, f32) {
    let n = x.len();
    let (x0, x1) = (x[i], x[i + 1]);
    let (f0, f1) = (values[i], values[i + 1]);
    let width = x1 - x0;
    let d0 = if i > 0 {
        width * (f1 - values[i - 1]) / (x1 - x[i - 1])
    } else {
        f1 - f0
    };
    let d1 = if i + 2 < n {
        width * (values[i + 2] - f0) / (x[i + 2] - x0)
    } else {
        f1 - f0
    };
    (d0, d1)
}

/// pbrt-v3's `IntegrateCatmullRom`: the integral of the Catmull-Rom spline
/// through `values` at the nodes `x` (at least 2, increasing), filling
/// `cdf` (as long as `x`) with the running integral at each node.
pub fn integrate_catmull_rom(x: &[f32], values: &[f32], cdf: &mut [f32]) -> f32 {
    let mut sum = 0.0f32;
    cdf[0] = 0.0;
    for i in 0..x.len() - 1 {
        let (f0, f1) = (values[i], values[i + 1]);
        let width = x[i + 1] - x[i];
        let (d0, d1) = segment_tangents(x, values, i);
        sum += ((d0 - d1) * (1.0 / 12.0) + (f0 + f1) * 0.5) * width;
        cdf[i + 1] = sum;
    }
    sum
}

/// pbrt-v3's `InvertCatmullRom`: the `x` at which the Catmull-Rom spline
/// through the increasing `values` at the nodes `x` equals `u`; the first
/// or last node when `u` is outside the values (or NaN).
pub fn invert_catmull_rom(x: &[f32], values: &[f32], u: f32) -> f32 {
    let n = x.len();
    if u.is_nan() || u <= values[0] {
        return x[0];
    } else if u >= values[n - 1] {
        return x[n - 1];
    }
    let i = find_interval(n, |i| values[i] <= u);
    let (x0, x1) = (x[i], x[i + 1]);
    let (f0, f1) = (values[i], values[i + 1]);
    let (d0, d1) = segment_tangents(x, values, i);
    let (mut a, mut b, mut t) = (0.0f32, 1.0f32, 0.5f32);
    let mut steps = 0;
    loop {
        if !(t > a && t < b) {
            t = 0.5 * (a + b);
        }
        let (t2, t3) = (t * t, t * t * t);
        let big_f = (2.0 * t3 - 3.0 * t2 + 1.0) * f0
            + (-2.0 * t3 + 3.0 * t2) * f1
            + (t3 - 2.0 * t2 + t) * d0
            + (t3 - t2) * d1;
        let f = (6.0 * t2 - 6.0 * t) * f0
            + (-6.0 * t2 + 6.0 * t) * f1
            + (3.0 * t2 - 4.0 * t + 1.0) * d0
            + (3.0 * t2 - 2.0 * t) * d1;
        steps += 1;
        if (big_f - u).abs() < 1e-6 || b - a < 1e-6 || steps >= MAX_STEPS {
            break;
        }
        if big_f - u < 0.0 {
            a = t;
        } else {
            b = t;
        }
        t -= (big_f - u) / f;
    }
    x0 + t * (x1 - x0)
}

/// A sample of [`sample_catmull_rom_2d`].
#[derive(Clone, Copy, Debug)]
pub struct SplineSample {
    pub x: f32,
    /// The interpolated function at `x`.
    pub value: f32,
    /// `value` over the interpolated integral.
    pub pdf: f32,
}

/// pbrt-v3's `SampleCatmullRom2D`: samples the second dimension of a
/// function tabulated on `nodes1 × nodes2` (`values` and its running
/// integrals `cdf` along the second dimension, row-major), interpolated at
/// `alpha` along the first. `None` if `alpha` is outside `nodes1`.
pub fn sample_catmull_rom_2d(
    nodes1: &[f32],
    nodes2: &[f32],
    values: &[f32],
    cdf: &[f32],
    alpha: f32,
    u: f32,
) -> Option<SplineSample> {
    let size2 = nodes2.len();
    let (offset, weights) = catmull_rom_weights(nodes1, alpha)?;
    let interpolate = |array: &[f32], idx: usize| {
        let mut value = 0.0f32;
        for (i, &w) in weights.iter().enumerate() {
            if w != 0.0 {
                value += array[(offset + i as isize) as usize * size2 + idx] * w;
            }
        }
        value
    };
    let maximum = interpolate(cdf, size2 - 1);
    let u = u * maximum;
    let idx = find_interval(size2, |i| interpolate(cdf, i) <= u);
    let (f0, f1) = (interpolate(values, idx), interpolate(values, idx + 1));
    let (x0, x1) = (nodes2[idx], nodes2[idx + 1]);
    let width = x1 - x0;
    let u = (u - interpolate(cdf, idx)) / width;
    // Tangents by finite differences of the interpolant.
    let d0 = if idx > 0 {
        width * (f1 - interpolate(values, idx - 1)) / (x1 - nodes2[idx - 1])
    } else {
        f1 - f0
    };
    let d1 = if idx + 2 < size2 {
        width * (interpolate(values, idx + 2) - f0) / (nodes2[idx + 2] - x0)
    } else {
        f1 - f0
    };
    // Invert the segment's integral, starting from the linear interpolant's
    // inverse, by Newton steps kept inside a shrinking bracket.
    let mut t = if f0 != f1 {
        (f0 - (f0 * f0 + 2.0 * u * (f1 - f0)).max(0.0).sqrt()) / (f0 - f1)
    } else {
        u / f0
    };
    let (mut a, mut b) = (0.0f32, 1.0f32);
    let mut fhat;
    let mut steps = 0;
    loop {
        if !(t >= a && t <= b) {
            t = 0.5 * (a + b);
        }
        let big_f = t
            * (f0
                + t * (0.5 * d0
                    + t * ((1.0 / 3.0) * (-2.0 * d0 - d1) + f1 - f0
                        + t * (0.25 * (d0 + d1) + 0.5 * (f0 - f1)))));
        fhat = f0
            + t * (d0 + t * (-2.0 * d0 - d1 + 3.0 * (f1 - f0) + t * (d0 + d1 + 2.0 * (f0 - f1))));
        steps += 1;
        if (big_f - u).abs() < 1e-6 || b - a < 1e-6 || steps >= MAX_STEPS {
            break;
        }
        if big_f - u < 0.0 {
            a = t;
        } else {
            b = t;
        }
        t -= (big_f - u) / fhat;
    }
    Some(SplineSample {
        x: x0 + width * t,
        value: fhat,
        pdf: fhat / maximum,
    })
}

/// pbrt-v3's `Fourier`: `Σ a[k] cos(kφ)` given cos φ, summed in f64 with the
/// Chebyshev recurrence for cos(kφ).
#[inline]
pub fn fourier(a: &[f32], cos_phi: f64) -> f32 {
    let mut value = 0.0f64;
    let (mut cos_prev, mut cos_k) = (cos_phi, 1.0f64);
    for &ak in a {
        value += ak as f64 * cos_k;
        let cos_next = 2.0 * cos_phi * cos_k - cos_prev;
        cos_prev = cos_k;
        cos_k = cos_next;
    }
    value as f32
}

/// A sample of [`sample_fourier`].
#[derive(Clone, Copy, Debug)]
pub struct FourierSample {
    /// The series at `phi`.
    pub value: f32,
    /// Density of `phi` on [0, 2π).
    pub pdf: f32,
    pub phi: f32,
}

/// pbrt-v3's `SampleFourier`: samples φ ∈ [0, 2π) proportionally to the
/// cosine series `ak` (even in φ: `u` picks a half, then φ on [0, π] inverts
/// the integral by Newton–bisection in f64). `recip[k]` is 1/k. An empty
/// series gives a zero density.
pub fn sample_fourier(ak: &[f32], recip: &[f32], u: f32) -> FourierSample {
    let a0_f32 = ak.first().copied().unwrap_or(0.0);
    let a0 = a0_f32 as f64;
    let flip = u >= 0.5;
    let u = if flip { 1.0 - 2.0 * (u - 0.5) } else { u * 2.0 };
    let (mut a, mut b, mut phi) = (0.0f64, PI, 0.5 * PI);
    let mut f;
    let mut steps = 0;
    loop {
        let cos_phi = phi.cos();
        let sin_phi = (1.0 - cos_phi * cos_phi).max(0.0).sqrt();
        let (mut cos_prev, mut cos_cur) = (cos_phi, 1.0f64);
        let (mut sin_prev, mut sin_cur) = (-sin_phi, 0.0f64);
        // F(φ) = ∫₀^φ series, and its derivative f(φ) = the series.
        let mut big_f = a0 * phi;
        f = a0;
        for k in 1..ak.len() {
            let sin_next = 2.0 * cos_phi * sin_cur - sin_prev;
            let cos_next = 2.0 * cos_phi * cos_cur - cos_prev;
            sin_prev = sin_cur;
            sin_cur = sin_next;
            cos_prev = cos_cur;
            cos_cur = cos_next;
            big_f += (ak[k] * recip[k]) as f64 * sin_next;
            f += ak[k] as f64 * cos_next;
        }
        big_f -= (u * a0_f32 * PI_F32) as f64;
        if big_f > 0.0 {
            b = phi;
        } else {
            a = phi;
        }
        steps += 1;
        if big_f.abs() < 1e-6 || b - a < 1e-6 || steps >= MAX_STEPS {
            break;
        }
        phi -= big_f / f;
        if !(phi > a && phi < b) {
            phi = 0.5 * (a + b);
        }
    }
    if flip {
        phi = (2.0 * PI_F32) as f64 - phi;
    }
    FourierSample {
        value: f as f32,
        pdf: (INV_2PI * f / a0) as f32,
        phi: phi as f32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn find_interval_clamps_to_the_nodes() {
        let nodes = [0.0f32, 1.0, 2.0, 3.0];
        assert_eq!(find_interval(4, |i| nodes[i] <= -1.0), 0);
        assert_eq!(find_interval(4, |i| nodes[i] <= 0.5), 0);
        assert_eq!(find_interval(4, |i| nodes[i] <= 1.0), 1);
        assert_eq!(find_interval(4, |i| nodes[i] <= 2.5), 2);
        assert_eq!(find_interval(4, |i| nodes[i] <= 9.0), 2);
    }

    /// The weights sum to one and reproduce any linear function exactly
    /// (Catmull-Rom with finite-difference tangents is exact on lines),
    /// on uneven nodes, in end and inner intervals.
    #[test]
    fn catmull_rom_weights_reproduce_lines() {
        let nodes = [-1.0f32, -0.7, -0.1, 0.0, 0.35, 0.9, 1.0];
        let line = |x: f32| 0.3 - 2.0 * x;
        for i in 0..=200 {
            let x = -1.0 + 2.0 * i as f32 / 200.0;
            let (offset, w) = catmull_rom_weights(&nodes, x).unwrap();
            let mut sum = 0.0;
            let mut v = 0.0;
            for (k, &wk) in w.iter().enumerate() {
                if wk != 0.0 {
                    let n = (offset + k as isize) as usize;
                    v += wk * line(nodes[n]);
                }
                sum += wk;
            }
            assert!((sum - 1.0).abs() < 1e-5, "x {x}: Σw = {sum}");
            assert!((v - line(x)).abs() < 1e-5, "x {x}: {v} vs {}", line(x));
        }
        assert!(catmull_rom_weights(&nodes, 1.01).is_none());
        assert!(catmull_rom_weights(&nodes, f32::NAN).is_none());
    }

    #[test]
    fn fourier_matches_the_cosine_sum() {
        let a = [0.5f32, -0.25, 0.125, 0.3];
        for phi in [0.0f64, 0.4, 1.3, 2.9] {
            let direct: f64 = a
                .iter()
                .enumerate()
                .map(|(k, &ak)| ak as f64 * (k as f64 * phi).cos())
                .sum();
            assert!((fourier(&a, phi.cos()) as f64 - direct).abs() < 1e-6);
        }
    }

    /// φ sampled from a positive series: its CDF at the samples is uniform
    /// (the sample's integral equals u), and the pdf is the normalised series.
    #[test]
    fn sample_fourier_inverts_the_integral() {
        let ak = [1.0f32, 0.6, 0.2, -0.1];
        let recip: Vec<f32> = (0..4).map(|i| 1.0 / i as f32).collect();
        let integral = |phi: f64| {
            ak[0] as f64 * phi
                + (1..4)
                    .map(|k| ak[k] as f64 / k as f64 * (k as f64 * phi).sin())
                    .sum::<f64>()
        };
        for i in 0..50 {
            let u = (i as f32 + 0.5) / 50.0;
            let s = sample_fourier(&ak, &recip, u);
            let cdf = integral(s.phi as f64) / (2.0 * PI * ak[0] as f64);
            assert!((cdf - u as f64).abs() < 1e-5, "u {u}: cdf {cdf}");
            let series = fourier(&ak, (s.phi as f64).cos());
            assert!((s.value - series).abs() < 1e-5);
            assert!((s.pdf as f64 - series as f64 / (2.0 * PI)).abs() < 1e-5);
        }
        let empty = sample_fourier(&[], &[], 0.3);
        assert!(empty.pdf.is_nan() || empty.pdf <= 0.0);
    }

    /// On a separable table f(α, x) = g(x) the 2D sampler inverts g's
    /// spline integral: the sample's CDF (by fine quadrature of the spline)
    /// equals u, and the pdf integrates to one.
    #[test]
    fn sample_catmull_rom_2d_inverts_the_cdf() {
        let nodes = [0.0f32, 0.2, 0.5, 0.6, 1.0];
        let g = [0.2f32, 1.0, 0.7, 0.9, 0.1];
        let n = nodes.len();
        // The spline's integral per segment (pbrt-v3's IntegrateCatmullRom).
        let mut cdf_row = vec![0.0f32; n];
        for i in 0..n - 1 {
            let (x0, x1) = (nodes[i], nodes[i + 1]);
            let w = x1 - x0;
            let d0 = if i > 0 {
                w * (g[i + 1] - g[i - 1]) / (x1 - nodes[i - 1])
            } else {
                g[i + 1] - g[i]
            };
            let d1 = if i + 2 < n {
                w * (g[i + 2] - g[i]) / (nodes[i + 2] - x0)
            } else {
                g[i + 1] - g[i]
            };
            cdf_row[i + 1] = cdf_row[i] + ((d0 - d1) / 12.0 + (g[i] + g[i + 1]) * 0.5) * w;
        }
        let values: Vec<f32> = (0..n).flat_map(|_| g).collect();
        let cdf: Vec<f32> = (0..n).flat_map(|_| cdf_row.clone()).collect();
        let spline = |x: f32| {
            let (o, w) = catmull_rom_weights(&nodes, x).unwrap();
            (0..4)
                .filter(|&k| w[k] != 0.0)
                .map(|k| w[k] * g[(o + k as isize) as usize])
                .sum::<f32>()
        };
        let total = cdf_row[n - 1];
        for i in 0..40 {
            let u = (i as f32 + 0.5) / 40.0;
            let s = sample_catmull_rom_2d(&nodes, &nodes, &values, &cdf, 0.37, u).unwrap();
            let steps = 4000;
            let h = s.x / steps as f32;
            let area: f32 = (0..steps).map(|j| spline((j as f32 + 0.5) * h) * h).sum();
            assert!((area / total - u).abs() < 1e-3, "u {u}: {}", area / total);
            assert!((s.value - spline(s.x)).abs() < 1e-3);
            assert!((s.pdf - s.value / total).abs() < 1e-5);
        }
        assert!(sample_catmull_rom_2d(&nodes, &nodes, &values, &cdf, 1.5, 0.5).is_none());
    }
    #[test]
    fn integrate_catmull_rom_is_exact_for_lines_and_fills_the_cdf() {
        let x = [0.0f32, 0.5, 1.5, 2.0, 4.0];
        let values: Vec<f32> = x.iter().map(|&x| 3.0 * x + 1.0).collect();
        let mut cdf = [0.0f32; 5];
        let total = integrate_catmull_rom(&x, &values, &mut cdf);
        assert!((total - (1.5 * 16.0 + 4.0)).abs() < 1e-4, "{total}");
        for (xi, c) in x.iter().zip(cdf) {
            assert!((c - (1.5 * xi * xi + xi)).abs() < 1e-4, "{xi}: {c}");
        }
    }

    #[test]
    fn invert_catmull_rom_round_trips() {
        let x: Vec<f32> = (0..20).map(|i| i as f32 / 19.0).collect();
        let values: Vec<f32> = x.iter().map(|&x| x * x * (3.0 - x) + 0.1 * x).collect();
        for k in 1..100 {
            let xt = k as f32 / 100.0;
            // The spline's value at xt, through its weights.
            let (offset, w) = catmull_rom_weights(&x, xt).unwrap();
            let mut u = 0.0;
            for (i, wi) in w.iter().enumerate() {
                if *wi != 0.0 {
                    u += wi * values[(offset + i as isize) as usize];
                }
            }
            let back = invert_catmull_rom(&x, &values, u);
            assert!((back - xt).abs() < 1e-4, "{xt} -> {u} -> {back}");
        }
        assert_eq!(invert_catmull_rom(&x, &values, -1.0), 0.0);
        assert_eq!(invert_catmull_rom(&x, &values, 10.0), 1.0);
        assert_eq!(invert_catmull_rom(&x, &values, f32::NAN), 0.0);
    }
}
