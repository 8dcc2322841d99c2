//! Pearson chi-square goodness-of-fit tests for sampling routines, in the
//! style of Mitsuba's `ChiSquare`: draw many samples, histogram them over a
//! grid, integrate the claimed pdf over each cell numerically (adaptive
//! Simpson) to get expected counts, pool cells with low expected counts, and
//! turn the statistic into a p-value.
//!
//! Reusable for any routine that maps `[0,1)^2` to directions (BSDFs, lights):
//!
//! ```
//! use pbrs::sampling::{chi2, warps};
//! let r = chi2::chi2_sphere(
//!     |u| Some(warps::cosine_sample_hemisphere(u)),
//!     |w| if w.z > 0.0 { warps::cosine_hemisphere_pdf(w.z) } else { 0.0 },
//!     &chi2::Chi2Config { sample_count: 100_000, ..Default::default() },
//! );
//! assert!(r.passed(chi2::sidak_significance(0.01, 1)), "{r}");
//! ```

use super::rng::Pcg32;
use crate::image::Image;
use glam::{Vec2, Vec3};
use std::f64::consts::PI;
use std::fmt;

/// Grid and sample budget.
#[derive(Clone, Debug)]
pub struct Chi2Config {
    /// Cells along θ ∈ [0, π] (sphere) or along x (square).
    pub theta_res: usize,
    /// Cells along φ ∈ [0, 2π) (sphere) or along y (square).
    pub phi_res: usize,
    pub sample_count: usize,
    /// Cells expecting fewer samples than this are pooled.
    pub min_expected: f64,
    /// Seed of the PCG32 stream that drives `sample`.
    pub seed: u64,
    /// How each cell's expected count is integrated: `None`, adaptive
    /// Simpson to `cell_tolerance` (analytic densities); `Some(n)`,
    /// composite Simpson with `n` intervals per axis (rounded up to even),
    /// for tabulated densities, whose f32 rounding and spline knots keep the
    /// adaptive rule from converging before its depth limit.
    pub simpson_intervals: Option<usize>,
    /// Absolute error allowed in each cell's integrated probability; `None`:
    /// 1e-9 × the cell's area. Peaked densities (glossy lobes) need a
    /// looser bound to integrate in reasonable time: an error well below
    /// `sqrt(p / sample_count)` for a cell of probability `p` does not move
    /// the statistic.
    pub cell_tolerance: Option<f64>,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Self {
            theta_res: 10,
            phi_res: 20,
            sample_count: 1_000_000,
            min_expected: 5.0,
            seed: 0,
            simpson_intervals: None,
            cell_tolerance: None,
        }
    }
}

/// Outcome of one test.
#[derive(Clone, Debug)]
pub struct Chi2Result {
    pub statistic: f64,
    pub dof: usize,
    /// Probability of a statistic at least this large if the pdf were right.
    pub p_value: f64,
    /// Cells merged into the pooled cell.
    pub pooled_cells: usize,
    /// Integral of the pdf over the whole domain (should be ≈ 1, or the
    /// probability that `sample` succeeds).
    pub pdf_integral: f64,
    /// Samples that were NaN, off the unit sphere or outside the square.
    pub invalid_samples: usize,
    /// Samples that `sample` rejected (returned `None`).
    pub rejected_samples: usize,
    /// Samples in cells whose expected count is 0.
    pub unexpected_samples: usize,
    /// Observed and expected counts per cell, row-major (θ outer, φ inner).
    pub observed: Vec<f64>,
    pub expected: Vec<f64>,
    /// Grid shape: `rows` (θ or x) × `cols` (φ or y).
    pub rows: usize,
    pub cols: usize,
    pub sample_count: usize,
}

impl Chi2Result {
    /// Observed and expected counts as grey images (`cols` wide, `rows`
    /// high), to write out with `image::io::write_image` when a test fails.
    pub fn histogram_images(&self) -> (Image, Image) {
        let to_image = |v: &[f64]| Image {
            width: self.cols as u32,
            height: self.rows as u32,
            data: v.iter().flat_map(|&c| [c as f32; 3]).collect(),
        };
        (to_image(&self.observed), to_image(&self.expected))
    }

    /// True if the test does not reject the pdf at `significance`.
    pub fn passed(&self, significance: f64) -> bool {
        self.invalid_samples == 0
            && (self.unexpected_samples as f64) <= 1e-5 * self.sample_count as f64
            && self.p_value >= significance
    }
}

impl fmt::Display for Chi2Result {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "chi2 = {:.3}, dof = {}, p = {:.3e}, pooled {} cells, pdf integral {:.6}, \
             invalid {}, rejected {}, unexpected {}",
            self.statistic,
            self.dof,
            self.p_value,
            self.pooled_cells,
            self.pdf_integral,
            self.invalid_samples,
            self.rejected_samples,
            self.unexpected_samples
        )
    }
}

/// Šidák-corrected per-test significance so that `n_tests` tests together
/// reject a correct implementation with probability `alpha`.
pub fn sidak_significance(alpha: f64, n_tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / n_tests.max(1) as f64)
}

/// Chi-square test of a sampler of directions on the unit sphere against its
/// solid-angle `pdf`. Cells are `theta_res × phi_res` in spherical coordinates
/// (θ from +z, φ = atan2(y, x)).
pub fn chi2_sphere(
    mut sample: impl FnMut(Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
    cfg: &Chi2Config,
) -> Chi2Result {
    let (nt, np) = (cfg.theta_res.max(1), cfg.phi_res.max(1));
    let mut observed = vec![0.0f64; nt * np];
    let mut invalid = 0;
    let mut rejected = 0;
    let mut rng = Pcg32::with_sequence(cfg.seed);
    for _ in 0..cfg.sample_count {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let Some(w) = sample(u) else {
            rejected += 1;
            continue;
        };
        if !w.is_finite() || (w.length() - 1.0).abs() > 1e-3 {
            invalid += 1;
            continue;
        }
        let w = w.as_dvec3().normalize();
        let theta = w.z.clamp(-1.0, 1.0).acos();
        let mut phi = w.y.atan2(w.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let it = ((theta / PI * nt as f64) as usize).min(nt - 1);
        let ip = ((phi / (2.0 * PI) * np as f64) as usize).min(np - 1);
        observed[it * np + ip] += 1.0;
    }
    let f = |theta: f64, phi: f64| {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let w = Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32);
        pdf(w) as f64 * st
    };
    let mut expected = vec![0.0f64; nt * np];
    for it in 0..nt {
        let t0 = PI * it as f64 / nt as f64;
        let t1 = PI * (it + 1) as f64 / nt as f64;
        for ip in 0..np {
            let p0 = 2.0 * PI * ip as f64 / np as f64;
            let p1 = 2.0 * PI * (ip + 1) as f64 / np as f64;
            expected[it * np + ip] = integrate_cell(&f, t0, t1, p0, p1, cfg);
        }
    }
    finish(observed, expected, invalid, rejected, (nt, np), cfg)
}

/// Chi-square test of a sampler of points in `[0,1]^2` against its area
/// density `pdf` (e.g. barycentrics, or a disk mapped to the square).
/// Cells are `theta_res` (x) × `phi_res` (y).
pub fn chi2_square(
    mut sample: impl FnMut(Vec2) -> Option<Vec2>,
    pdf: impl Fn(Vec2) -> f32,
    cfg: &Chi2Config,
) -> Chi2Result {
    let (nx, ny) = (cfg.theta_res.max(1), cfg.phi_res.max(1));
    let mut observed = vec![0.0f64; nx * ny];
    let mut invalid = 0;
    let mut rejected = 0;
    let mut rng = Pcg32::with_sequence(cfg.seed);
    for _ in 0..cfg.sample_count {
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let Some(p) = sample(u) else {
            rejected += 1;
            continue;
        };
        if !p.is_finite() || p.x < 0.0 || p.y < 0.0 || p.x > 1.0 || p.y > 1.0 {
            invalid += 1;
            continue;
        }
        let ix = ((p.x * nx as f32) as usize).min(nx - 1);
        let iy = ((p.y * ny as f32) as usize).min(ny - 1);
        observed[ix * ny + iy] += 1.0;
    }
    let f = |x: f64, y: f64| pdf(Vec2::new(x as f32, y as f32)) as f64;
    let mut expected = vec![0.0f64; nx * ny];
    for ix in 0..nx {
        let x0 = ix as f64 / nx as f64;
        let x1 = (ix + 1) as f64 / nx as f64;
        for iy in 0..ny {
            let y0 = iy as f64 / ny as f64;
            let y1 = (iy + 1) as f64 / ny as f64;
            expected[ix * ny + iy] = integrate_cell(&f, x0, x1, y0, y1, cfg);
        }
    }
    finish(observed, expected, invalid, rejected, (nx, ny), cfg)
}

fn finish(
    observed: Vec<f64>,
    mut expected: Vec<f64>,
    invalid: usize,
    rejected: usize,
    (rows, cols): (usize, usize),
    cfg: &Chi2Config,
) -> Chi2Result {
    let pdf_integral: f64 = expected.iter().sum();
    let n = cfg.sample_count as f64;
    for e in &mut expected {
        *e *= n;
    }
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut stat, mut dof, mut unexpected) = (0.0f64, 0usize, 0usize);
    let (mut pooled_obs, mut pooled_exp, mut pooled_cells) = (0.0f64, 0.0f64, 0usize);
    for &i in &order {
        let (o, e) = (observed[i], expected[i]);
        if e <= 0.0 {
            unexpected += o as usize;
        } else if e < cfg.min_expected || (pooled_exp > 0.0 && pooled_exp < cfg.min_expected) {
            pooled_obs += o;
            pooled_exp += e;
            pooled_cells += 1;
        } else {
            stat += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_exp > 0.0 {
        stat += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
        dof += 1;
    }
    let dof = dof.saturating_sub(1);
    let p_value = if dof == 0 {
        1.0
    } else {
        chi2_survival(stat, dof as f64)
    };
    Chi2Result {
        statistic: stat,
        dof,
        p_value,
        pooled_cells,
        pdf_integral,
        invalid_samples: invalid,
        rejected_samples: rejected,
        unexpected_samples: unexpected,
        observed,
        expected,
        rows,
        cols,
        sample_count: cfg.sample_count,
    }
}

/// ∫∫ f(x, y) dy dx over a cell, by the rule `cfg` asks for.
fn integrate_cell(
    f: &impl Fn(f64, f64) -> f64,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    cfg: &Chi2Config,
) -> f64 {
    match cfg.simpson_intervals {
        None => integrate_2d(f, x0, x1, y0, y1, cfg.cell_tolerance),
        Some(n) => simpson_2d(f, x0, x1, y0, y1, n),
    }
}

/// Composite Simpson over a rectangle with `n` (made even) intervals per axis.
fn simpson_2d(f: &impl Fn(f64, f64) -> f64, x0: f64, x1: f64, y0: f64, y1: f64, n: usize) -> f64 {
    let n = (n.max(2) + 1) & !1;
    let weight = |i: usize| match i {
        0 => 1.0,
        i if i == n => 1.0,
        i if i % 2 == 1 => 4.0,
        _ => 2.0,
    };
    let (hx, hy) = ((x1 - x0) / n as f64, (y1 - y0) / n as f64);
    let mut sum = 0.0;
    for i in 0..=n {
        let x = x0 + hx * i as f64;
        for j in 0..=n {
            sum += weight(i) * weight(j) * f(x, y0 + hy * j as f64);
        }
    }
    sum * hx * hy / 9.0
}

/// ∫∫ f(x, y) dy dx over a rectangle: adaptive Simpson in both directions,
/// each started from 4 panels so narrow features are not missed, to the
/// absolute error `tolerance` (default 1e-9 × area).
fn integrate_2d(
    f: &impl Fn(f64, f64) -> f64,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    tolerance: Option<f64>,
) -> f64 {
    let area = (x1 - x0) * (y1 - y0);
    let tol = tolerance.unwrap_or(1e-9 * area.max(1e-12));
    // The inner integrals' errors add up over the outer interval.
    let eps = tol / (x1 - x0);
    let inner = |x: f64| integrate_1d(&|y| f(x, y), y0, y1, eps, 14);
    integrate_1d(&inner, x0, x1, tol, 14)
}

fn integrate_1d(f: &impl Fn(f64) -> f64, a: f64, b: f64, eps: f64, depth: u32) -> f64 {
    const PANELS: usize = 4;
    let h = (b - a) / PANELS as f64;
    let mut sum = 0.0;
    for k in 0..PANELS {
        let (l, r) = (a + h * k as f64, a + h * (k + 1) as f64);
        let m = 0.5 * (l + r);
        let (fl, fm, fr) = (f(l), f(m), f(r));
        let whole = (r - l) / 6.0 * (fl + 4.0 * fm + fr);
        sum += simpson_rec(f, l, r, fl, fm, fr, whole, eps / PANELS as f64, depth);
    }
    sum
}

#[allow(clippy::too_many_arguments)]
fn simpson_rec(
    f: &impl Fn(f64) -> f64,
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
    eps: f64,
    depth: u32,
) -> f64 {
    let m = 0.5 * (a + b);
    let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
    let (flm, frm) = (f(lm), f(rm));
    let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    let delta = left + right - whole;
    if depth == 0 || delta.abs() <= 15.0 * eps {
        return left + right + delta / 15.0;
    }
    simpson_rec(f, a, m, fa, flm, fm, left, 0.5 * eps, depth - 1)
        + simpson_rec(f, m, b, fm, frm, fb, right, 0.5 * eps, depth - 1)
}

/// `P(X >= x)` for X ~ χ²(k): the regularised upper incomplete gamma Q(k/2, x/2).
pub fn chi2_survival(x: f64, k: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    gamma_q(0.5 * k, 0.5 * x)
}

fn ln_gamma(x: f64) -> f64 {
    // Lanczos approximation (g = 7, n = 9), accurate to ~1e-15 for x > 0.
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, &c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised upper incomplete gamma function Q(a, x) (series or continued
/// fraction, as in Numerical Recipes).
fn gamma_q(a: f64, x: f64) -> f64 {
    if x < a + 1.0 {
        // Series for P, Q = 1 - P.
        let mut sum = 1.0 / a;
        let mut term = sum;
        let mut ap = a;
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        let p = sum * (-x + a * x.ln() - ln_gamma(a)).exp();
        (1.0 - p).clamp(0.0, 1.0)
    } else {
        // Lentz's continued fraction.
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        ((-x + a * x.ln() - ln_gamma(a)).exp() * h).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn survival_function_matches_tables() {
        // Critical values of χ² at 0.05 and 0.01 from standard tables.
        assert!((chi2_survival(3.841, 1.0) - 0.05).abs() < 1e-4);
        assert!((chi2_survival(18.307, 10.0) - 0.05).abs() < 1e-4);
        assert!((chi2_survival(23.209, 10.0) - 0.01).abs() < 1e-4);
        assert!((chi2_survival(135.807, 100.0) - 0.01).abs() < 1e-4);
        assert!((chi2_survival(2.0, 2.0) - (-1.0f64).exp()).abs() < 1e-12);
        assert!((ln_gamma(5.0) - 24.0f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn integrator_handles_discontinuities() {
        // Indicator of the triangle x + y < 1 over the unit square: 1/2.
        let f = |x: f64, y: f64| if x + y < 1.0 { 1.0 } else { 0.0 };
        let v = integrate_2d(&f, 0.0, 1.0, 0.0, 1.0, None);
        assert!((v - 0.5).abs() < 1e-5, "{v}");
        let g = |t: f64, _p: f64| t.sin();
        let v = integrate_2d(&g, 0.0, PI, 0.0, 2.0 * PI, None);
        assert!((v - 4.0 * PI).abs() < 1e-9, "{v}");
    }

    #[test]
    fn composite_simpson_is_exact_on_cubics() {
        let f = |x: f64, y: f64| x * x * x - 2.0 * x * y + y * y + 1.0;
        // ∫₀¹∫₀² = 1/4·2 − 2·(1/2)·2 + 8/3 + 2
        let exact = 0.5 - 2.0 + 8.0 / 3.0 + 2.0;
        for n in [2, 3, 8] {
            let v = simpson_2d(&f, 0.0, 1.0, 0.0, 2.0, n);
            assert!((v - exact).abs() < 1e-12, "n {n}: {v} vs {exact}");
        }
        let g = |t: f64, _p: f64| t.sin();
        let v = simpson_2d(&g, 0.0, PI, 0.0, 2.0 * PI, 16);
        assert!((v - 4.0 * PI).abs() < 1e-3, "{v}");
    }
}
